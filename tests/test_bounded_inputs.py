"""Bounded inputs (issue 17): deep JSON, seeds, study size, small CLI defects; each refused
at once with one line on stderr, exit code 2, no traceback."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.io import jsonable, read_fold, write_json

TRIANGLE = {"vertices_coords": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "faces_vertices": [[0, 1, 2]]}


def run_cli(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        check=False,
        timeout=120,
    )


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
    one_line_error(proc, f"nested deeper than {DEFAULTS.max_json_depth} levels")
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
    from rigidfold.case import make_case
    from rigidfold.study import plan

    with pytest.raises(ValueError, match=r"seed must be a non-negative integer below 2\*\*63"):
        make_case("bezier", "1", seed=2**63)
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
        f"criteria), more than the limit of {DEFAULTS.max_study_runs}",
    )
    assert time.perf_counter() - t0 < 30
    assert list(tmp_path.iterdir()) == []
    small = DEFAULTS.with_(max_study_runs=8)
    assert len(plan(["1", "2"], ["s", "shat"], 2, settings=small)) == 8
    with pytest.raises(ValueError, match="makes 12 runs"):
        plan(["1", "2"], ["s", "shat"], 3, settings=small)
