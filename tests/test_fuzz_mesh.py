"""Fuzz test of the mesh inputs (issue 30): seeded mutants of a target surface given as a
triangle mesh (``--surface mesh:FILE``, OBJ, STL binary and ASCII, PLY binary and ASCII, OFF)
and of a footprint file (``--pattern mesh:FILE``), run through ``rigidfold optimize`` in this
process on a small case (a 3 x 3 grid on the mesh; the built-in dome on the footprint). Every
case must end with exit code 0, 1 or 2 (2: one line ``rigidfold: error: ...``), raise nothing
else (no traceback, no warning), write nothing outside its ``--out`` folder, leave its input
as it was, and end within :data:`test_fuzz_svg.SECONDS`.

The mutations: numbers made NaN, infinite, huge, tiny or negative; lines deleted, repeated,
swapped or junk; vertices repeated or collapsed; degenerate faces and faces of many or
missing vertices; counts in the headers that lie (PLY, OFF, a binary STL's triangle count);
the file cut short, a byte changed, bytes not UTF-8. A mutant is at most twice its base
plus a few kilobytes. The mutator is this file's own (seeded ``random.Random``).
"""

from __future__ import annotations

import random
import re
import shutil
import struct
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from conftest import dome_mesh, main_code
from fuzzing import byte_damage
from test_fuzz_svg import run_command

NUMBERS = ["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e400", "1e-300", "0", "-0", "",
           "-1", "x", "99999999999999999999", "3.5", "1e5", "-7", "1,5", "0x1f"]  # fmt: skip
FLOATS = [float("nan"), float("inf"), -float("inf"), 3.4e38, -3.4e38, 1e-45, 0.0, 1e5, -1.0]
_NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
FOOTPRINT = "# a house\n0,0\n3,0\n3 2\n1.5,3\n0,2\n0,0\n"
"""A footprint file: a comment, pairs with a comma or a space, the outline closed again."""


@pytest.fixture(scope="module")
def bases(tmp_path_factory) -> dict[str, bytes]:
    """name (with its file extension) -> bytes of each valid input mutated: the dome on 6 x 6
    vertices (50 triangles) in every mesh format, and a footprint file."""
    import trimesh

    folder = tmp_path_factory.mktemp("mesh_bases")
    mesh = trimesh.Trimesh(*dome_mesh(6), process=False)
    files = {
        "dome.obj": mesh.export(file_type="obj"),
        "dome.stl": mesh.export(file_type="stl"),
        "ascii.stl": mesh.export(file_type="stl_ascii"),
        "dome.ply": mesh.export(file_type="ply", encoding="binary"),
        "ascii.ply": mesh.export(file_type="ply", encoding="ascii"),
        "dome.off": mesh.export(file_type="off"),
        "house.txt": FOOTPRINT,
    }
    data = {name: v.encode() if isinstance(v, str) else bytes(v) for name, v in files.items()}
    for name, raw in data.items():  # each base is read and solved as it is
        (folder / name).write_bytes(raw)
        assert run(folder / name, folder / f"out_{name}") == 0, name
    return data


def command(case: Path, out: Path) -> list[str]:
    """``optimize`` on the mesh as the target surface, or on the footprint as the pattern."""
    if case.suffix == ".txt":
        return ["optimize", "--surface", "dome", "--pattern", f"mesh:{case}", "--out", str(out)]
    return ["optimize", "--surface", f"mesh:{case}", "--pattern", "grid:3x3", "--out", str(out)]


def run(case: Path, out: Path) -> int:
    return main_code(command(case, out))


# ----------------------------------------------------------------------------- the mutator
def bad_number(text: str, rng) -> tuple[str, str]:
    """A number of the file (a coordinate, an index, a count) made NaN, huge, junk, ..."""
    found = list(_NUMBER.finditer(text))
    if not found:
        return text, "no number"
    match, value = rng.choice(found), rng.choice(NUMBERS)
    return text[: match.start()] + value + text[match.end() :], f"{match[0]!r} -> {value!r}"


def lines(text: str, rng) -> tuple[str, str]:
    """Lines deleted, repeated (a repeated vertex, face or point), swapped or junk."""
    rows = text.split("\n")
    how = rng.choice(["delete", "repeat", "swap", "junk", "reverse"])
    i, j = rng.randrange(len(rows)), rng.randrange(len(rows))
    if how == "delete":
        del rows[i]
    elif how == "repeat":
        rows.insert(i, rows[i])
    elif how == "swap":
        rows[i], rows[j] = rows[j], rows[i]
    elif how == "reverse":
        rows.reverse()
    else:
        rows.insert(i, rng.choice(["f", "v", "facet normal", "3", "3 0 0 0", "element face 9",
                                   "endsolid", "mtllib none.mtl", "o x", "1 2 3 4 5 6", "# ,",
                                   "v 1 2", "f 1 2", "f 1 1 1", "f 0 1 2", "f -99 1 2",
                                   "end_header", "\t", "vertex nan nan nan"]))  # fmt: skip
    return "\n".join(rows), f"{how} line {i} ({j})"


def obj_faces(text: str, rng) -> tuple[str, str]:
    """OBJ faces: degenerate, out of range, fractional, of many vertices (a fan), relative."""
    faces = [m for m in re.finditer(r"^f .*$", text, re.M)]
    if not faces:
        return text, "no face"
    face = rng.choice(faces)
    new = rng.choice(["f 1 1 1", "f 1 2 99999", "f 0 1 2", "f 1.5 2 3", "f -1 -2 -3", "f 1 2",
                      "f " + " ".join(str(k) for k in range(1, 37)), "f 1/1/1 2//2 3/x",
                      "f 1 2 3 1 2 3", "f -100000 1 2", "f 2147483648 1 2"])  # fmt: skip
    return text[: face.start()] + new + text[face.end() :], f"{face[0]!r} -> {new!r}"


def collapse(text: str, rng) -> tuple[str, str]:
    """OBJ vertices: all at one point, on a vertical line, scaled to 1e300, or one far away."""
    rows = text.split("\n")
    where = [k for k, r in enumerate(rows) if r.startswith("v ")]
    if not where:
        return text, "no vertex"
    how = rng.choice(["point", "vertical", "scale", "far"])
    for k in where if how != "far" else [rng.choice(where)]:
        x, y, z = (float(v) for v in rows[k].split()[1:4])
        x, y, z = {
            "point": (1.0, 1.0, 1.0),
            "vertical": (1.0, 1.0, z),
            "scale": (x * 1e300, y * 1e300, z),
            "far": (x + 1e7, y, z),
        }[how]
        rows[k] = f"v {x!r} {y!r} {z!r}"
    return "\n".join(rows), f"vertices {how}"


def header_count(text: str, rng) -> tuple[str, str]:
    """A count in a PLY or OFF header that lies: larger, smaller, huge, negative."""
    if text.startswith("OFF"):
        rows = text.split("\n")
        row = next(k for k, r in enumerate(rows) if k > 0 and r.strip() and r[0] != "#")
        counts = rows[row].split()
        which = rng.randrange(len(counts))
        counts[which] = rng.choice(["0", "1", "10000000", "-3", "999999999999", "51", "35"])
        rows[row] = " ".join(counts)
        return "\n".join(rows), f"OFF counts {rows[row]!r}"
    found = list(re.finditer(r"^element (\w+) (\d+)$", text, re.M))
    if not found:
        return text, "no count"
    match = rng.choice(found)
    value = rng.choice(["0", "1", "10000000", "4294967295", "-3", "37", "49", "x"])
    new = f"element {match[1]} {value}"
    return text[: match.start()] + new + text[match.end() :], f"{match[0]!r} -> {new!r}"


def ply_properties(text: str, rng) -> tuple[str, str]:
    """A PLY property of an unknown or wrong type, or a list of a huge count type."""
    found = list(re.finditer(r"^property .*$", text, re.M))
    if not found:
        return text, "no property"
    match = rng.choice(found)
    new = rng.choice(["property float128 x", "property list uchar float vertex_indices",
                      "property list int int vertex_indices", "property char z", "property",
                      "property list uint8 uint32 vertex_indices extra"])  # fmt: skip
    return text[: match.start()] + new + text[match.end() :], f"{match[0]!r} -> {new!r}"


TEXT_MUTATIONS: dict[str, list[Callable]] = {
    "obj": [bad_number, bad_number, lines, lines, obj_faces, obj_faces, collapse],
    "stl": [bad_number, bad_number, lines, lines],
    "ply": [bad_number, bad_number, lines, header_count, header_count, ply_properties],
    "off": [bad_number, bad_number, lines, header_count, header_count],
    "txt": [bad_number, bad_number, lines, lines, lines],
}


def binary_stl(data: bytes, rng) -> tuple[bytes, str]:
    """A binary STL whose count lies, whose triangles hold junk, or whose header says solid."""
    count = int.from_bytes(data[80:84], "little")
    how = rng.choice(["count", "count", "float", "float", "solid", "cut", "extra", "degenerate"])
    if how == "count":
        new = rng.choice([0, 1, count - 1, count + 1, 2 * count, 2**32 - 1, 10**7])
        return data[:80] + new.to_bytes(4, "little") + data[84:], f"count {count} -> {new}"
    if how == "float":
        k = rng.randrange(count)
        at = 84 + 50 * k + 12 + 4 * rng.randrange(9)  # a corner's coordinate
        value = rng.choice(FLOATS)
        return data[:at] + struct.pack("<f", value) + data[at + 4 :], f"triangle {k} {value}"
    if how == "solid":
        return b"solid " + data[6:], "a binary STL whose header starts with 'solid'"
    if how == "cut":
        k = rng.randrange(len(data))
        return data[:k], f"cut at byte {k}"
    if how == "extra":
        return data + bytes(rng.randrange(1, 120)), "bytes after the triangles"
    k = rng.randrange(count)  # a triangle of three equal corners
    at = 84 + 50 * k + 12
    return data[:at] + data[at : at + 12] * 3 + data[at + 36 :], f"triangle {k} degenerate"


def binary_ply(data: bytes, rng) -> tuple[bytes, str]:
    """A binary PLY: its header's counts lie, or its data is cut or changed."""
    end = data.index(b"end_header\n") + len(b"end_header\n")
    if rng.random() < 0.5:
        text, what = header_count(data[:end].decode(), rng)
        return text.encode() + data[end:], what
    k = rng.randrange(end, len(data))
    if rng.random() < 0.5:
        return data[:k], f"cut at byte {k}"
    return data[:k] + bytes([rng.randrange(256)]) * 4 + data[k + 4 :], f"bytes {k}.. changed"


def text_damage(data: bytes, rng) -> tuple[bytes, str]:
    return byte_damage(data, rng, ("cut", "byte", "latin-1", "empty", "nul"))


def mutant(name: str, data: bytes, rng: random.Random) -> tuple[bytes, list[str]]:
    """Bytes of one mutant of the base ``name``, and what was done to it."""
    if rng.random() < 0.15:
        damaged, what = text_damage(data, rng)
        return damaged, [what]
    if name in ("dome.stl", "dome.ply"):
        damage = binary_stl if name == "dome.stl" else binary_ply
        done = []
        for _ in range(rng.choice([1, 1, 2])):
            data, what = damage(data, rng)
            done.append(what)
        return data, done
    text, done = data.decode(), []
    for _ in range(rng.choice([1, 1, 2, 3])):
        text, what = rng.choice(TEXT_MUTATIONS[name.rsplit(".", 1)[1]])(text, rng)
        done.append(what)
    return text.encode(), done


MUTANTS = {
    "dome.obj": 30,
    "dome.stl": 30,
    "ascii.stl": 15,
    "dome.ply": 20,
    "ascii.ply": 20,
    "dome.off": 20,
    "house.txt": 30,
}


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_mutated_meshes_and_footprints_end_in_an_exit_code(
    name, bases, tmp_path, monkeypatch, capsys
):
    base = bases[name]
    rng = random.Random(f"fuzz-mesh-{name}")
    work = tmp_path / "cwd"  # stray relative writes would land here
    work.mkdir()
    monkeypatch.chdir(work)
    codes = []
    for k in range(MUTANTS[name]):
        data, done = mutant(name, base, rng)
        assert len(data) <= 2 * len(base) + 4096
        case = tmp_path / f"case{k}" / name
        case.parent.mkdir()
        case.write_bytes(data)
        out = tmp_path / f"out{k}"
        label = f"{name} mutant {k} ({'; '.join(done)})"
        codes.append(run_command(command(case, out), label, tmp_path, [case], capsys))
        shutil.rmtree(case.parent)
        shutil.rmtree(out, ignore_errors=True)
    # the mutants reach past the first checks: some are still read, some refused
    assert codes.count(2) >= MUTANTS[name] // 5 and codes.count(0) >= 1, codes


def test_the_bases_are_the_dome():
    """The bases are the dome's formula on 6 x 6 vertices: a target the grid lies on."""
    vertices, triangles = dome_mesh(6)
    assert len(triangles) == 50 and np.ptp(vertices[:, :2], axis=0).tolist() == [3.0, 3.0]


def test_defects_found_by_the_mutants(tmp_path, capsys):
    """A mesh vertex at 1e308 overflowed (a RuntimeWarning); a footprint with two points
    1e-300 apart crashed Triangle (a segmentation fault)."""
    obj = tmp_path / "far.obj"
    obj.write_text("v 0 0 0\nv 3 0 0\nv 0 3 1e308\nv 3 3 0\nf 1 2 4\nf 1 4 3\n")
    footprint = tmp_path / "gap.txt"
    footprint.write_text("0,0\n3,0\n3,1e-300\n1.5,3\n0,2\n")
    for case, message in (
        (obj, f"mesh {obj}: vertex 2 at [0.0, 3.0, 1e+308] lies farther than 1e+06 m from the "
              "origin (Settings.limits.max_coordinate)"),
        (footprint, "has two points, or a point and a side, 0 m apart, less than 1e-09 of its "
                    "size of 3 m (Settings.inputs.footprint_min_gap)"),  # GEOS's distance: 0
    ):  # fmt: skip
        assert run(case, tmp_path / "out") == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("rigidfold: error: ") and message in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["far.obj", "gap.txt"]
