"""Bounded inputs (issue 17): deep JSON, seeds, study size, small CLI defects; each refused
at once with one line on stderr, exit code 2, no traceback."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code, run_cli
from rigidfold.config import DEFAULTS
from rigidfold.io import jsonable, read_fold, write_json
from rigidfold.patterns import grid

DATA = Path(__file__).parent / "data"
TRIANGLE = {"vertices_coords": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "faces_vertices": [[0, 1, 2]]}


def one_line_error(proc: subprocess.CompletedProcess, message: str) -> None:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert message in lines[0], lines[0]


# ---------------------------------------------------------------- defect 4: deeply nested JSON
@pytest.mark.parametrize("where", ["top", "rigidfold-key"])
def test_deeply_nested_fold_file_is_refused(tmp_path, where):
    path = tmp_path / "deep.fold"
    if where == "top":
        path.write_text("[" * 100_000 + "]" * 100_000)
    else:
        text = json.dumps(TRIANGLE)[:-1] + ', "rigidfold:x": ' + "[" * 600 + "]" * 600 + "}"
        path.write_text(text)
    proc = run_cli("analyze", str(path))
    one_line_error(proc, f"nested deeper than {DEFAULTS.limits.max_json_depth} levels")
    with pytest.raises(ValueError, match=r"deep\.fold: nested deeper"):
        read_fold(path)


def test_deeply_nested_data_is_not_written(tmp_path):
    deep: list = []
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(ValueError, match="nested deeper than"):
        jsonable({"a": deep})
    with pytest.raises(ValueError, match="nested deeper than"):
        write_json(tmp_path / "x.json", {"a": deep})
    with pytest.raises(ValueError, match="FOLD data: nested deeper than"):
        read_fold({**TRIANGLE, "rigidfold:x": deep})
    assert list(tmp_path.iterdir()) == []
    # rigidfold's own data nests far less than the limit
    assert jsonable({"a": [[[1.0]]]}) == {"a": [[[1.0]]]}


# --------------------------------------------------------------- defect 6: seeds out of range
@pytest.mark.parametrize("seed", ["10000000000000000000000", "-1", str(2**63)])
def test_seed_out_of_range_is_refused_at_once(tmp_path, seed):
    out = tmp_path / "o"
    proc = run_cli(
        "optimize", "--surface", "bezier", "--pattern", "1", "--seed", seed, "--out", str(out)
    )
    one_line_error(
        proc, f"argument --seed: seed must be a non-negative integer below 2**63, got {seed}"
    )
    proc = run_cli("study", "--surfaces", "1", "--first-seed", seed, "--db", str(tmp_path / "s.db"))
    one_line_error(proc, "argument --first-seed: seed must be a non-negative integer below 2**63")
    assert list(tmp_path.iterdir()) == []


def test_seeds_are_checked_by_the_library():
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.study import plan

    with pytest.raises(ValueError, match=r"seed must be a non-negative integer below 2\*\*63"):
        case_from_specs("bezier", "1", seed=2**63)
    with pytest.raises(ValueError, match="--first-seed must be a non-negative integer"):
        plan(["1"], ["s"], 1, first_seed=10**22)
    with pytest.raises(ValueError, match="the last seed"):
        plan(["1"], ["s"], 2, first_seed=2**63 - 1)
    assert plan(["1"], ["s"], 1, first_seed=2**63 - 1)[0].seed == 2**63 - 1


# ------------------------------------------------------------- defect 9: study size is bounded
def test_huge_study_is_refused_at_once(tmp_path):
    import time

    from rigidfold.study import plan

    t0 = time.perf_counter()
    proc = run_cli("study", "--surfaces", "1000000000", "--db", str(tmp_path / "s.db"))
    one_line_error(
        proc,
        f"--surfaces 1000000000 makes 8000000000 runs (1000000000 surfaces x 2 patterns x 4 "
        f"criteria), more than the limit of {DEFAULTS.limits.max_study_runs}",
    )
    assert time.perf_counter() - t0 < 30
    assert list(tmp_path.iterdir()) == []
    small = DEFAULTS.with_(max_study_runs=8)
    assert len(plan(["1", "2"], ["s", "shat"], 2, settings=small)) == 8
    with pytest.raises(ValueError, match="makes 12 runs"):
        plan(["1", "2"], ["s", "shat"], 3, settings=small)


# ------------------------------------------------------------------- defect 12: small ones
def test_expression_starting_with_minus_is_accepted(tmp_path):
    from rigidfold.cli.parser import attached_values as _attached_values

    out = str(tmp_path / "o")
    proc = run_cli(
        "optimize", "--surface", "bezier", "--expr", "-x*y", "--pattern", "1", "--out", out
    )
    one_line_error(proc, "--expr is only used with --surface expr, not bezier")
    proc = run_cli(
        "optimize", "--surface", "expr", "--expr", "-log(x)", "--pattern", "1", "--out", out
    )
    one_line_error(proc, "not finite")
    assert _attached_values(["a", "--expr", "-x", "--", "--expr", "-y"]) == [
        "a",
        "--expr=-x",
        "--",
        "--expr",
        "-y",
    ]
    assert _attached_values(["--expr"]) == ["--expr"]


@pytest.mark.parametrize("command", ["optimize", "generate"])
def test_bad_expression_creates_no_output_directory(tmp_path, command):
    out = tmp_path / "o"
    proc = run_cli(
        command, "--surface", "expr", "--expr", "x +", "--pattern", "1", "--out", str(out)
    )
    one_line_error(proc, "invalid expression")
    assert not out.exists()


def test_mixed_2d_and_3d_vertices_are_refused(tmp_path):
    path = tmp_path / "mixed.fold"
    data = {
        "vertices_coords": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1]],
        "faces_vertices": [[0, 1, 2], [1, 3, 2]],
    }
    path.write_text(json.dumps(data))
    one_line_error(run_cli("analyze", str(path)), "vertices_coords[3] has 2 coordinates")


def test_huge_coordinates_are_refused_without_warnings(tmp_path):
    path = tmp_path / "huge.fold"
    data = {
        "vertices_coords": [[0, 0, 0], [1e300, 0, 0], [0, 1e300, 0], [1e300, 1e300, 1]],
        "faces_vertices": [[0, 1, 2], [1, 3, 2]],
        "frame_unit": "m",
    }
    path.write_text(json.dumps(data))
    proc = run_cli("analyze", str(path))
    one_line_error(proc, "vertices_coords[1] = [1e+300, 0, 0] lies farther than 1e+06 m")
    assert "Warning" not in proc.stderr


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_full_standard_output_is_one_line(tmp_path):
    path = tmp_path / "t.fold"
    path.write_text(json.dumps(TRIANGLE))
    with open("/dev/full", "w") as full:
        proc = subprocess.run(
            [sys.executable, "-m", "rigidfold.cli", "analyze", str(path)],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
            timeout=120,
        )
    one_line_error(proc, "cannot write the output: No space left on device")


def test_full_disk_leaves_no_temporary_file(tmp_path, monkeypatch):
    def no_space(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", no_space)
    with pytest.raises(ValueError, match=r"cannot write '.*x\.json': No space left on device"):
        write_json(tmp_path / "x.json", {"a": 1})
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- defect 3: size of the work
def test_analysis_too_large_is_refused_before_allocating():
    import time

    from rigidfold.generate.specs import parse_pattern
    from rigidfold.mechanism import analysis_bytes, analyze, check_analysis_size
    from rigidfold.mesh import CreasePattern

    xy, faces = grid(300, 300, 30.0, 30.0, "centre")
    big = CreasePattern.from_faces(np.column_stack([xy, np.zeros(len(xy))]), faces)
    for method in ("kinematic", "frame"):
        t0 = time.perf_counter()
        with pytest.raises(ValueError, match=r"analysis of 90000 vertices .* GiB, more than"):
            analyze(big, method=method)
        assert time.perf_counter() - t0 < 30  # the 548 GiB allocation is never tried
    # the estimate of pattern 1: C is (E + 9) x 3V = 129 x 147, Q is 147 x 147
    small = CreasePattern.from_faces(parse_pattern("1").xy, parse_pattern("1").faces)
    assert analysis_bytes(small.n_edges + 9, 3 * small.n_vertices) == 8 * (147**2 + 2 * 129 * 147)
    check_analysis_size(small)
    with pytest.raises(ValueError, match=r"Settings\.limits\.max_analysis_bytes"):
        check_analysis_size(small, DEFAULTS.with_(max_analysis_bytes=1000))


def test_generate_of_a_pattern_too_large_to_analyse_stops_before_solving(tmp_path):
    # a 230 x 230 grid read from a FOLD file: even its sparse analysis (generate's method at
    # this size) would need about 11 GiB (a grid: pattern is limited to 20000 triangles,
    # which the sparse analysis takes in about 1 GiB)
    xy, faces = grid(230, 230, 23.0, 23.0, "centre")
    fold = tmp_path / "big.fold"
    fold.write_text(
        json.dumps(
            {
                "file_spec": 1.1,
                "frame_unit": "m",
                "vertices_coords": np.column_stack([xy, np.zeros(len(xy))]).tolist(),
                "faces_vertices": faces.tolist(),
            }
        )
    )
    proc = run_cli(
        "generate",
        "--surface",
        "dome",
        "--pattern",
        str(fold),
        "--quiet",
        "--out",
        str(tmp_path / "o"),
    )
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    # refused on its triangle count (Settings.limits.max_pattern_faces, checked on the file's real
    # faces since issue 30 item 5), before the estimate of the analysis's memory is needed
    assert (
        "has 104882 triangles, more than 20000 (Settings.limits.max_pattern_faces)" in proc.stderr
    )
    assert not (tmp_path / "o" / "summary.json").exists()


def star_polygon(n: int, seed: int) -> np.ndarray:
    """(n, 2) vertices of a non-convex star-shaped polygon, counter-clockwise: n random
    angles, each at a random radius in [0.5, 1]."""
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0.0, 2.0 * np.pi, n))
    radius = rng.uniform(0.5, 1.0, n)
    return np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])


def comb_polygon(teeth: int) -> np.ndarray:
    """(n, 2) vertices of a comb (non-convex, counter-clockwise) whose base side carries
    three vertices per tooth in a straight line (collinear corners)."""
    base = [(x, 0.0) for i in range(teeth) for x in (2 * i, 2 * i + 0.5, 2 * i + 1)]
    top = [(2.0 * teeth, 0.0), (2.0 * teeth, 10.0)]
    for i in reversed(range(1, teeth)):
        top += [(2 * i + 1.5, 10.0), (2 * i + 1.5, 3.0), (2 * i + 0.5, 3.0), (2 * i + 0.5, 10.0)]
    top += [(1.5, 10.0), (0.0, 10.0)]
    return np.array(base + top, dtype=float)


def shoelace(xy: np.ndarray) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


@pytest.mark.parametrize(
    ("shape", "n"), [("star", 800), ("star", 3000), ("star", 5000), ("comb", 2996)]
)
def test_large_polygon_faces_are_triangulated(shape, n):
    """One polygon face of thousands of vertices is read into n - 2 triangles that tile it.

    Clipping the best ear of all (the triangulation before mapbox_earcut) took 92 s for an
    800-gon and grows as n^3: hours for these. Each face here is read in well under a second."""
    xy = star_polygon(n, seed=n) if shape == "star" else comb_polygon(n // 7)
    assert len(xy) == n
    fold = {"vertices_coords": xy.tolist(), "faces_vertices": [list(range(n))]}
    data = read_fold(fold, rigid_panels=True)
    p = data.pattern
    assert p.n_faces == n - 2
    assert data.assignment.count("J") == n - 3 and data.assignment.count("B") == n
    assert np.all(p.face_normals[:, 2] > 0)
    tri = p.coords[p.faces][:, :, :2]
    a, b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    areas = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 2
    assert np.all(areas > 0)
    assert areas.sum() == pytest.approx(shoelace(xy), rel=1e-12)


def test_large_polygon_face_in_3d_and_from_a_file(tmp_path):
    """A 3000-gon tilted in 3D is triangulated in its own plane; as a crease pattern file it
    is read, fitted into 3 m x 3 m, its diagonals free creases (without --rigid-panels)."""
    from rigidfold.generate.specs import parse_pattern

    n = 3000
    xy = star_polygon(n, seed=1)
    c, s = np.cos(0.4), np.sin(0.4)
    coords = np.column_stack([xy[:, 0], c * xy[:, 1], s * xy[:, 1] + 2.0])
    data = read_fold({"vertices_coords": coords.tolist(), "faces_vertices": [list(range(n))]})
    p = data.pattern
    assert p.n_faces == n - 2 and data.assignment.count("J") == n - 3
    tri = p.coords[p.faces]
    area3d = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    assert area3d.sum() == pytest.approx(shoelace(xy), rel=1e-9)

    path = tmp_path / "panel.fold"
    path.write_text(
        json.dumps({"vertices_coords": xy.tolist(), "faces_vertices": [list(range(n))]})
    )
    plan = parse_pattern(str(path))
    assert len(plan.faces) == n - 2 and len(plan.fixed) == 0
    assert np.ptp(plan.xy, axis=0).max() == pytest.approx(3.0)


@pytest.mark.parametrize(
    ("pattern", "message"),
    [
        (["grid:3x3", "--size", "1e-10x1e-10"], "pattern 'grid:3x3' is 1e-10 m x 1e-10 m"),
        (["grid:3x3", "--size", "1e300x1e300"], "pattern 'grid:3x3' is 1e+300 m x 1e+300 m"),
        (["mesh:0,0;1e-9,0;0,1e-9"], "the footprint '0,0; 1e-09,0; 0,1e-09' is 1e-09 m x"),
        (["mesh:0,0;1e200,0;0,1e200"], "footprint point 2 (1e+200, 0) lies farther than 1e+06"),
        (["FILE", "--scale", "1e250"], "cp.fold at --scale 1e+250 is 1e+250 m x 1e+250 m"),
        (["FILE", "--size", "1e300x1e300"], "cp.fold fitted into --size is 1e+300 m x"),
        (["TINY"], "tiny.fold (drawn in m) is 1e-10 m x 1e-10 m"),
    ],
)
def test_pattern_plans_too_small_or_too_large_are_refused(tmp_path, capsys, pattern, message):
    """A plan under 1 mm (a file in the wrong unit: the solvers' absolute tolerances are met
    trivially or their derivatives turn NaN, with CasADi's warnings on stderr) or over
    1000 km (overflow: an OverflowError traceback, NumPy's RuntimeWarnings) is refused in
    one line before anything is written (the fuzz test found the tiny one)."""
    square = {"vertices_coords": [[0, 0], [1, 0], [1, 1], [0, 1]], "faces_vertices": [[0, 1, 2, 3]]}
    (tmp_path / "cp.fold").write_text(json.dumps(square))
    tiny = [[0, 0], [1e-10, 0], [1e-10, 1e-10], [0, 1e-10]]
    (tmp_path / "tiny.fold").write_text(
        json.dumps(square | {"frame_unit": "m", "vertices_coords": tiny})
    )
    files = {"FILE": str(tmp_path / "cp.fold"), "TINY": str(tmp_path / "tiny.fold")}
    spec = [files.get(pattern[0], pattern[0]), *pattern[1:]]
    out = tmp_path / "out"
    code = main_code(["optimize", "--surface", "dome", "--pattern", *spec, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert message in err and "Settings.limits.max_coordinate" in err, err
    assert not out.exists()


def test_a_file_name_that_is_not_utf8_is_developed_whole(tmp_path):
    """``develop`` of ``sq<0xff>.fold`` (bytes that are not UTF-8) wrote ``sq<0xff>.fold``
    and then failed on the SVG, whose title held the name ("surrogates not allowed"). Now
    both files are written under that name, their titles show U+FFFD, and the file names
    are printed as their bytes even where stdout's encoding is strict."""
    import shutil

    name = os.fsdecode(b"sq\xff")
    source = tmp_path / f"{name}.fold"
    shutil.copy(DATA / "fold_examples" / "squaretwist.fold", source)
    env = {**os.environ, "PYTHONIOENCODING": "utf-8:strict"}
    argv = ["develop", str(source), "--out", str(tmp_path / "o")]
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *argv],
        capture_output=True,
        env=env,
        check=False,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == b""
    assert os.fsencode(tmp_path / "o" / f"{name}.svg") in proc.stdout
    assert sorted(os.listdir(os.fsencode(tmp_path / "o"))) == [b"sq\xff.fold", b"sq\xff.svg"]
    svg = (tmp_path / "o" / f"{name}.svg").read_text(encoding="utf-8")
    assert "sq\ufffd: development" in svg
    fold = json.loads((tmp_path / "o" / f"{name}.fold").read_text())
    assert "sq\ufffd: the folded form" in json.dumps(fold, ensure_ascii=False)
