"""The smaller defects of issue 47, item 9, each with its test: a log without a header, a
summary that lists one solution 20,000 times, an F of 1e308 in a log, ``python -m
rigidfold.pinned --help``, ``--target-dof 0`` with the deployability check, ``--supports
0,,1``, and the design an interrupted run names."""

from __future__ import annotations

import dataclasses
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import main_code
from rigidfold.cli.structure_specs import parse_index_list
from rigidfold.errors import RigidfoldError
from rigidfold.generate import GenerateOptions, Stop, best_so_far, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.pipeline.verdict import run_verdict
from rigidfold.reporting import render_figures
from rigidfold.rundir import SolutionRecord, load_run, read_log

SMALL = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "grid:3x3"]
SMALL += ["--size", "1x1", "--no-deform", "--no-report", "--quiet"]
"""A run of seconds: DOF 5 to 1 on a 3 x 3 grid, its final design deploys."""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("small")
    assert main_code([*SMALL, "--out", str(out)]) == 0
    return out


@pytest.fixture
def copy(run_dir, tmp_path):
    return Path(shutil.copytree(run_dir, tmp_path / "run"))


# ------------------------------------------------------------------ a log without a header
@pytest.mark.parametrize(
    ("content", "what"),
    [(b"", "is empty"), (b'{"schema_ver', "holds only a torn first line")],
)
def test_a_log_without_its_header_is_refused(copy, content, what):
    (copy / "log.jsonl").write_bytes(content)
    with pytest.raises(RigidfoldError, match=f"log.jsonl' {what}: no header line"):
        read_log(copy / "log.jsonl")
    with pytest.raises(RigidfoldError, match="no header line"):
        load_run(copy)
    assert main_code(["report", str(copy)]) == 2


# ---------------------------------------------------- one solution listed 20,000 times
def test_a_solution_listed_again_is_refused_at_once(copy):
    summary = json.loads((copy / "summary.json").read_text())
    first = summary["solutions"][0]
    summary["solutions"] = [first] * 20_000
    (copy / "summary.json").write_text(json.dumps(summary))
    t0 = time.perf_counter()
    with pytest.raises(RigidfoldError, match=r"'solutions\[1\]' is .* which 'solutions\[0\]'"):
        load_run(copy)
    assert time.perf_counter() - t0 < 30  # read once, not 20,000 times (was: past 60 s)


# ------------------------------------------------------------------- F = 1e308 in a log
def test_an_enormous_F_is_drawn_without_overflow(copy):
    """``filterwarnings = error``: matplotlib's overflow warnings would fail the test."""
    lines = (copy / "log.jsonl").read_text().splitlines()
    row = json.loads(lines[1])
    row["F"] = 1e308
    lines[1] = json.dumps(row)
    (copy / "log.jsonl").write_text("\n".join(lines) + "\n")
    run = load_run(copy)
    assert run.attempts[0].F == 1e308
    figures = {f.name: f for f in render_figures(run)}
    assert figures["dof_and_F.png"].png.startswith(b"\x89PNG")


# ------------------------------------------------------------ python -m rigidfold.pinned
@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_pinned_help_prints_its_usage(flag):
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.pinned", flag],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("usage: python -m rigidfold.pinned")
    assert "no command" not in proc.stderr


# ------------------------------------------------------------------- --target-dof 0
def test_target_dof_0_with_the_deploy_check_is_refused_before_the_run(tmp_path, capsys):
    with pytest.raises(RigidfoldError, match="target DOF 0 asks for a rigid design"):
        GenerateOptions(target_dof=0)
    assert GenerateOptions(target_dof=0, deploy_check=False).target_dof == 0
    out = tmp_path / "run"
    assert main_code([*SMALL, "--target-dof", "0", "--out", str(out)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "--no-deploy-check" in line and not out.exists()


# ----------------------------------------------------------------- --supports 0,,1
@pytest.mark.parametrize("text", ["0,,1", "0,1,", ",0", " , "])
def test_an_empty_index_is_refused_naming_the_text(text):
    with pytest.raises(RigidfoldError, match=f"got {text!r}"):
        parse_index_list(text, "supports")


def test_supports_with_an_empty_item_exit_2(tmp_path, capsys):
    aframe = Path(__file__).parent / "data" / "aframe.fold"
    code = main_code(["structure", str(aframe), "--supports", "0,,1", "--out", str(tmp_path)])
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and "'0,,1'" in line and "item 2 is empty" in line
    assert parse_index_list("", "supports") == ()
    assert parse_index_list(" 3, 7 ", "supports") == (3, 7)


# ---------------------------------------------------- the design an interrupted run names
@pytest.fixture(scope="module")
def chain():
    """A run of DOF 5 to 1 with the deployability check: only the DOF-1 solution's path is
    traced (``deploy_check_max_dof``), and it deploys."""
    run = generate(case_from_specs("bezier", "grid:3x3", seed=1, size="1x1"), seed=1)
    dofs = [s.mechanism.dof for s in run.solutions]
    assert dofs == [5, 4, 3, 2, 1]
    assert [s.path is not None and s.path.deploys for s in run.solutions] == [False] * 4 + [True]
    return run


def _interrupted(run, solutions):
    stopped = dataclasses.replace(run, solutions=list(solutions), final_step=None)
    stopped.stop, stopped.stop_detail = Stop.INTERRUPTED, ""
    best_so_far(stopped)
    files = [Path(f"solutions/step_{s.step:02d}_dof_{s.mechanism.dof:02d}.fold") for s in solutions]
    records = [  # as the writer: the deployability check's path in each record
        SolutionRecord(
            s.step, s.mechanism.dof, deployability=None if s.path is None else s.path.to_dict()
        )
        for s in solutions
    ]
    return run_verdict(stopped, records, files, 1)


def test_an_interrupted_run_names_the_lowest_dof_design_known_to_deploy(chain):
    verdict = _interrupted(chain, chain.solutions)
    assert verdict.final_design == Path("solutions/step_04_dof_01.fold")
    assert "best design known to deploy: DOF 1" in verdict.message


def test_an_interrupted_run_names_no_design_when_none_is_known_to_deploy(chain):
    """Stopped at DOF 3: no path traced yet. Before, the DOF-3 solution was named as the
    best design so far, which the README calls the lowest-DOF one known to deploy."""
    verdict = _interrupted(chain, chain.solutions[:3])
    assert verdict.final_design is None
    assert "no design is known to deploy" in verdict.message
    assert "none of the 3 solutions" in verdict.message


# ------------------------------------------- a failed write of the final design's FOLD file
def test_a_failed_final_fold_write_ends_the_run_with_its_cause(tmp_path, monkeypatch, capsys):
    """Item 5: the final design's FOLD file (written with its diagram at the end) cannot be
    written: summary.json does not stay "running"; the run falls short naming the cause."""
    import rigidfold.pipeline.writer as writer

    def full_disk(path, *args, **kwargs):
        raise RigidfoldError(f"cannot write '{path}' (the disk is full)")

    monkeypatch.setattr(writer, "write_checked_shape", full_disk)
    out = tmp_path / "run"
    argv = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "1"]
    code = main_code([*argv, "--target-dof", "19", "--no-deform", "--quiet", "--out", str(out)])
    assert code == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stop"] != "running"
    assert summary["verdict"]["outcome"] == "fell_short"
    assert "the disk is full" in summary["verdict"]["message"]
