"""Fuzz test of the FOLD reader through the CLI (issue 17): a few hundred seeded mutants of
valid FOLD files run through ``rigidfold analyze``, ``develop`` and ``optimize`` in this
process. Every case must end with exit code 0, 1 or 2 (2: one line ``rigidfold: error: ...``
on stderr), raise nothing else (no traceback, no warning: warnings are errors in the test
suite), and write nothing outside its ``--out`` folder (the input file included).

No case can hang: a mutant is at most twice its base's size plus a few kB
(:func:`check_size`), and the bases are small patterns (at most 121 vertices), whose
analysis, development and optimisation take well under a second each. The mutator is this
file's own (seeded ``random.Random``), so a failure names the base, the mutant's number and
the mutations that made it, and reruns the same.
"""

from __future__ import annotations

import copy
import json
import math
import random
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from conftest import folded_grid, main_code
from fuzzing import byte_damage
from rigidfold.generate.specs import parse_pattern
from rigidfold.io import write_fold
from rigidfold.mesh import CreasePattern

DATA = Path(__file__).parent / "data"
MUTANTS_PER_BASE = 50  # 8 bases: 400 mutants, about 500 commands
JUNK = [
    None,
    True,
    False,
    0,
    -1,
    1.5,
    -0.0,
    2**64,
    10**400,
    1e308,
    -1e308,
    1e-320,
    math.nan,
    math.inf,
    -math.inf,
    "",
    "1",
    "x",
    "\u00e9\u0000",
    [],
    {},
    [[]],
    [None],
    [["a", 1]],
    {"a": [1, {"b": None}]},
    [[1, 2, 3, 4, 5]],
]
NUMBER_JUNK = [math.nan, math.inf, -math.inf, 1e308, -1e308, 10**30, 2**63, "1", None, True, []]
INDEX_JUNK = [-1, 10**6, 2**63, 1.0, 1.5, "0", None, True, math.nan, [0]]


# ------------------------------------------------------------------------------- the bases
def quad_pattern() -> dict:
    """A 4 x 3 vertex Miura-like crease pattern with quad faces and M/V/B assignments."""
    xs, ys = [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0]
    coords = [[x + 0.2 * (j % 2), y] for j, y in enumerate(ys) for x in xs]
    faces = [[j * 4 + i, j * 4 + i + 1, (j + 1) * 4 + i + 1, (j + 1) * 4 + i] for j in range(2)
             for i in range(3)]  # fmt: skip
    edges, letters = [], []
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            if [b, a] not in edges and [a, b] not in edges:
                edges.append([a, b])
    for a, b in edges:
        shared = sum({a, b} <= set(f) for f in faces)
        letters.append("B" if shared == 1 else ("M" if (a + b) % 2 else "V"))
    return {
        "file_spec": 1.1,
        "file_creator": "test",
        "frame_classes": ["creasePattern"],
        "frame_unit": "cm",
        "vertices_coords": coords,
        "faces_vertices": faces,
        "edges_vertices": edges,
        "edges_assignment": letters,
        "edges_foldAngle": [0 if a == "B" else (-90 if a == "M" else 90) for a in letters],
    }


@pytest.fixture(scope="module")
def bases(tmp_path_factory) -> dict[str, str]:
    """name -> text of each valid FOLD file mutated: files of other tools (tests/data) and
    files written by rigidfold (a folded grid, pattern 1 in plan, a quad pattern, a design
    with its development frame written by ``rigidfold develop``)."""
    folder = tmp_path_factory.mktemp("bases")
    texts = {
        name: (DATA / "fold_examples" / f"{name}.fold").read_text()
        for name in ("simple", "squaretwist", "diagonal-cp")
    }
    texts["dome_sym_dof1"] = (DATA / "dome_sym_dof1.fold").read_text()
    write_fold(folder / "grid.fold", folded_grid(4), metadata={"note": [1, {"a": 2}]})
    one = parse_pattern("1")
    flat = CreasePattern.from_faces(np.column_stack([one.xy, np.zeros(len(one.xy))]), one.faces)
    write_fold(folder / "pattern1.fold", flat, frame_class="creasePattern")
    (folder / "quads.fold").write_text(json.dumps(quad_pattern()))
    assert main_code(["develop", str(folder / "grid.fold"), "--out", str(folder / "dev")]) == 0
    for name in ("grid", "pattern1", "quads"):
        texts[name] = (folder / f"{name}.fold").read_text()
    texts["developed"] = (folder / "dev" / "grid.fold").read_text()
    for name, text in texts.items():  # each base is read and analysed as it is
        (folder / f"check-{name}.fold").write_text(text)
        assert main_code(["analyze", str(folder / f"check-{name}.fold")]) == 0, name
    return texts


# ----------------------------------------------------------------------------- the mutator
def nodes(doc, path=()):
    """Every (path, value) in a JSON document, depth first (path: keys and indices)."""
    yield path, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from nodes(v, (*path, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from nodes(v, (*path, i))


def put(doc, path, value):
    """``doc`` with the value at ``path`` replaced (the root itself when path is empty)."""
    if not path:
        return value
    parent = doc
    for step in path[:-1]:
        parent = parent[step]
    parent[path[-1]] = value
    return doc


def table(doc, rng: random.Random) -> str | None:
    """The name of one list-valued FOLD table of the document (None when it has none)."""
    names = (
        [k for k, v in doc.items() if isinstance(v, list) and v] if isinstance(doc, dict) else []
    )
    return rng.choice(sorted(names)) if names else None


def replace_any(doc, rng):
    path, _ = rng.choice(list(nodes(doc)))
    value = copy.deepcopy(rng.choice(JUNK))
    return put(doc, path, value), f"{list(path)} = {value!r:.40}"


def delete_key(doc, rng):
    dicts = [(p, v) for p, v in nodes(doc) if isinstance(v, dict) and v]
    if not dicts:
        return doc, "no key to delete"
    path, d = rng.choice(dicts)
    key = rng.choice(sorted(d, key=str))
    del d[key]
    return doc, f"del {[*path, key]}"


def is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def bad_leaf(doc, rng, wanted: Callable, junk: list):
    """One number of the document for which ``wanted(path, value)`` holds, set to junk."""
    leaves = [p for p, v in nodes(doc) if is_number(v) and wanted(p, v)]
    if not leaves:
        return doc, "no such number"
    path, value = rng.choice(leaves), rng.choice(junk)
    return put(doc, path, copy.deepcopy(value)), f"{list(path)} = {value!r}"


def bad_number(doc, rng):
    """A coordinate set to NaN, inf, a huge number, a string, ..."""
    return bad_leaf(doc, rng, lambda p, v: "vertices_coords" in p, NUMBER_JUNK)


def bad_index(doc, rng):
    """A vertex index of a face or an edge set out of range, fractional, a string, ..."""
    return bad_leaf(
        doc,
        rng,
        lambda p, v: isinstance(v, int) and len(p) >= 3 and str(p[-3]).endswith("_vertices"),
        INDEX_JUNK,
    )


def reshape_table(doc, rng):
    """Shuffle, duplicate, drop, reverse, truncate or empty rows of one table."""
    name = table(doc, rng)
    if name is None:
        return doc, "no table"
    rows = doc[name]
    how = rng.choice(["shuffle", "duplicate", "drop", "reverse row", "truncate row", "empty",
                      "rotate row", "repeat in row", "append junk row"])  # fmt: skip
    k = rng.randrange(len(rows))
    if how == "shuffle":
        rng.shuffle(rows)
    elif how == "duplicate":
        rows.insert(k, copy.deepcopy(rows[k]))
    elif how == "drop":
        del rows[k]
    elif how == "empty":
        doc[name] = []
    elif how == "append junk row":
        rows.append(copy.deepcopy(rng.choice(JUNK)))
    elif isinstance(rows[k], list) and rows[k]:
        row = rows[k]
        if how == "reverse row":
            row.reverse()
        elif how == "truncate row":
            del row[rng.randrange(len(row)) :]
        elif how == "rotate row":
            row.append(row.pop(0))
        else:
            row.insert(rng.randrange(len(row) + 1), row[rng.randrange(len(row))])
    return doc, f"{how} {name}[{k}]"


def geometry(doc, rng):
    """Whole-shape changes: scale, flatten, collapse or swap vertices, mixed dimensions."""
    coords = doc.get("vertices_coords") if isinstance(doc, dict) else None
    if not (isinstance(coords, list) and coords and all(isinstance(c, list) for c in coords)):
        return doc, "no coordinates"
    numeric = all(
        isinstance(x, (int, float)) and not isinstance(x, bool) for c in coords for x in c
    )
    how = rng.choice(
        ["scale", "shift", "jitter", "flatten", "collapse", "swap", "mixed dims", "extra dim"]
    )
    i, j = rng.randrange(len(coords)), rng.randrange(len(coords))
    if how == "scale" and numeric:
        factor = rng.choice([1e-300, 1e-12, 1e-6, 1e5, 1e290, -1.0])
        doc["vertices_coords"] = [[x * factor for x in c] for c in coords]
        return doc, f"scale coordinates by {factor:g}"
    if how == "shift" and numeric:
        offset = rng.choice([1e5, 9.9e5, -3e3])
        doc["vertices_coords"] = [[x + offset for x in c] for c in coords]
        return doc, f"shift coordinates by {offset:g}"
    if how == "jitter" and numeric:
        size = rng.choice([1e-13, 1e-6, 0.1, 1.0])
        coords[i] = [x + rng.uniform(-size, size) for x in coords[i]]
        return doc, f"jitter vertex {i} by {size:g}"
    if how == "flatten" and numeric:
        doc["vertices_coords"] = [[*c[:-1], 0.0] if len(c) == 3 else [c[0], 0.0] for c in coords]
    elif how == "collapse":
        coords[i] = copy.deepcopy(coords[j])
    elif how == "swap":
        coords[i], coords[j] = coords[j], coords[i]
    elif how == "mixed dims":
        coords[i] = coords[i][:2] if len(coords[i]) == 3 else [*coords[i], 0.5]
    else:
        coords[i] = [*coords[i], 1.0]
    return doc, f"{how} vertices {i}, {j}"


def frames(doc, rng):
    """Junk in the FOLD frame keys: units, classes, file_frames, inheritance."""
    if not isinstance(doc, dict):
        return doc, "no frames"
    key, value = rng.choice(
        [
            ("frame_unit", rng.choice(["furlong", "MM", 5, None, "mm", "nm", "km"])),
            ("frame_classes", rng.choice(["foldedForm", [1], ["creasePattern", None]])),
            ("file_frames", rng.choice([{}, [1], [{}], [{"frame_inherit": True}]])),
            ("file_frames", [{"frame_inherit": True, "frame_parent": rng.choice([1, -1, 9, "0"])}]),
            (
                "file_frames",
                [
                    {"frame_inherit": True, "frame_parent": 2},
                    {"frame_inherit": True, "frame_parent": 1},
                ],
            ),
            ("edges_rigidfold:fixed", rng.choice([[True], "yes", [1, 0], [None] * 3])),
            ("rigidfold:junk", "[" * 40 + "]" * 40),
            ("edges_assignment", rng.choice([["Z"], "MV", [None], ["C"] * 3, ["J", "J"]])),
            ("edges_foldAngle", rng.choice([[math.nan], ["90"], 5, [1e308] * 4])),
        ]
    )
    doc[key] = copy.deepcopy(value)
    return doc, f"{key} = {value!r:.40}"


def nest(doc, rng):
    """A value nested deep (within or beyond Settings.limits.max_json_depth)."""
    depth = rng.choice([20, 99, 150, 400])
    value: object = 1
    for _ in range(depth):
        value = [value]
    path, _ = rng.choice([(p, v) for p, v in nodes(doc) if len(p) <= 2])
    return put(doc, path, value), f"{list(path)} nested {depth} deep"


MUTATIONS: list[Callable] = [
    replace_any,
    delete_key,
    bad_number,
    bad_number,
    bad_index,
    bad_index,
    reshape_table,
    reshape_table,
    geometry,
    geometry,
    frames,
    nest,
]


def text_damage(text: str, rng: random.Random) -> tuple[bytes, str]:
    """Damage to the file's bytes: cut short, a byte changed, not UTF-8, a BOM, empty, a
    key given twice."""
    kinds = ("cut", "byte", "latin-1", "bom", "empty", "duplicate key")
    data, what = byte_damage(text.encode(), rng, kinds)
    if what == "duplicate key":
        return data.replace(b"{", b'{"vertices_coords": 7, ', 1), "a duplicated key first"
    return data, what


def mutant(text: str, rng: random.Random) -> tuple[bytes, list[str]]:
    """Bytes of one mutant of a FOLD file's text, and what was done to it."""
    if rng.random() < 0.1:
        data, what = text_damage(text, rng)
        return data, [what]
    doc = json.loads(text)
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        doc, what = rng.choice(MUTATIONS)(doc, rng)
        done.append(what)
    if rng.random() < 0.05:
        doc, done = rng.choice([[doc], 3, "x", None]), [*done, "top level not an object"]
    return json.dumps(doc, allow_nan=True).encode(), done


def check_size(data: bytes, base: str) -> None:
    """The bound on every case's work: a mutant is at most twice its base plus 4 kB."""
    assert len(data) <= 2 * len(base.encode()) + 4096


# ------------------------------------------------------------------------------ the runner
def snapshot(root: Path) -> dict[str, tuple[int, int, bytes]]:
    """Every file under ``root``: relative path -> (size, mtime_ns, first bytes)."""
    out = {}
    for path in root.rglob("*"):
        if path.is_file() or path.is_symlink():
            st = path.lstat()
            head = path.read_bytes()[:64] if path.is_file() else b"link"
            out[str(path.relative_to(root))] = (st.st_size, st.st_mtime_ns, head)
    return out


def commands(k: int, case: Path, out: Path, small: bool) -> list[list[str]]:
    """The commands run on mutant number k: analyze always, develop on every third, optimize
    on every eighth of a small base; sometimes read y-up; develop into the input's folder."""
    up = ["--up", "y"] if k % 7 == 3 else []
    runs = [["analyze", str(case), *up, *(["--json"] if k % 2 else [])]]
    if k % 3 == 0:
        target = case.parent if k % 12 == 0 else out
        runs.append(["develop", str(case), "--out", str(target), *up])
    if small and k % 8 == 1:
        panels = ["--rigid-panels"] if k % 16 == 1 else []
        runs.append(
            ["optimize", "--surface", "dome", "--pattern", str(case), "--out", str(out), *panels]
        )
    return runs


SMALL = {"simple", "squaretwist", "diagonal-cp", "grid", "quads"}


@pytest.mark.parametrize(
    "name",
    ["simple", "squaretwist", "diagonal-cp", "dome_sym_dof1", "grid", "pattern1", "quads",
     "developed"],
)  # fmt: skip
def test_mutated_fold_files_end_in_an_exit_code_and_write_only_under_out(
    name, bases, tmp_path, monkeypatch, capsys
):
    base = bases[name]
    rng = random.Random(f"fuzz-{name}")
    work = tmp_path / "cwd"  # stray relative writes would land here
    work.mkdir()
    monkeypatch.chdir(work)
    codes = []
    for k in range(MUTANTS_PER_BASE):
        data, done = mutant(base, rng)
        check_size(data, base)
        case_dir = tmp_path / f"case{k}"
        case_dir.mkdir()
        case = case_dir / f"{name}.fold"
        case.write_bytes(data)
        out = tmp_path / f"out{k}"
        for argv in commands(k, case, out, name in SMALL):
            label = f"{name} mutant {k} ({'; '.join(done)}): rigidfold {' '.join(argv)}"
            target = Path(argv[argv.index("--out") + 1]) if "--out" in argv else None
            before = snapshot(tmp_path)
            try:
                code = main_code(argv)
            except BaseException as exc:  # any escape is a failure, named with its case
                pytest.fail(f"{label}: {type(exc).__name__}: {exc}")
            stdout, stderr = capsys.readouterr()
            assert code in (0, 1, 2), f"{label}: exit code {code}"
            assert "Traceback" not in stdout + stderr, label
            if code == 2:
                lines = stderr.strip().splitlines()
                assert len(lines) == 1 and lines[0].startswith("rigidfold: error: "), (
                    f"{label}: {stderr!r}"
                )
            else:  # nothing on stderr (a solver's warning, a NaN met on the way) but notes
                lines = stderr.strip().splitlines()
                assert all(x.startswith("rigidfold: note: ") for x in lines), f"{label}: {stderr!r}"
            after = snapshot(tmp_path)
            changed = {p for p in before.keys() | after.keys() if before.get(p) != after.get(p)}
            outside = [
                p
                for p in changed
                if target is None or not (tmp_path / p).is_relative_to(target)
                or (tmp_path / p) == case
            ]  # fmt: skip
            assert not outside, f"{label}: wrote {sorted(outside)}"
            assert case.read_bytes() == data, f"{label}: the input changed"
            codes.append(code)
        shutil.rmtree(case_dir)
        shutil.rmtree(out, ignore_errors=True)
    # the mutants reach past the first checks: some are still read, some refused
    assert codes.count(2) >= 5 and codes.count(0) >= 1, codes
