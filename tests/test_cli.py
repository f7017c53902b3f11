"""The command line: outputs, exit codes, one-line errors without tracebacks."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import run_cli
from rigidfold.cli import main
from rigidfold.io import read_fold


def test_optimize_writes_fold_and_summary(tmp_path, capsys):
    code = main(
        ["optimize", "--surface", "bezier", "--seed", "2", "--pattern", "1", "--out", str(tmp_path)]
    )
    assert code == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "converged"
    assert summary["F"] <= 1e-7
    assert (summary["V"], summary["E"], summary["F_faces"]) == (49, 120, 72)
    assert summary["n_variables"] == 115
    assert summary["max_abs_dz_m"] <= 0.3
    assert summary["min_sector_angle_deg"] >= 30 - 1e-6
    assert summary["max_sector_angle_deg"] <= 120 + 1e-6
    data = read_fold(tmp_path / "solution.fold")
    assert data.pattern.n_vertices == 49
    assert data.metadata["status"] == "converged"
    assert data.metadata["surface"]["seed"] == 2
    assert data.frame_classes == ["foldedForm"]
    assert "converged" in capsys.readouterr().out


def test_optimize_fixed_creases_are_joins(tmp_path):
    code = main(
        [
            "optimize",
            "--surface",
            "bezier",
            "--seed",
            "2",
            "--pattern",
            "1",
            "--fixed",
            "7,8",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    raw = json.loads((tmp_path / "solution.fold").read_text())
    assert raw["edges_assignment"][7] == "J" and raw["edges_assignment"][8] == "J"
    assert json.loads((tmp_path / "summary.json").read_text())["fixed_creases"] == [7, 8]


def test_optimize_symmetric_expression(tmp_path):
    code = main(
        ["optimize", "--surface", "hp", "--pattern", "11", "--symmetric", "--out", str(tmp_path)]
    )
    assert code == 0
    assert json.loads((tmp_path / "summary.json").read_text())["n_variables"] == 83


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--surface", "cone", "--pattern", "1"], "unknown surface 'cone' (choose from bezier"),
        (["--surface", "bezier", "--pattern", "9"], "unknown pattern '9'"),
        (["--surface", "bezier", "--pattern", "1", "--dz", "0"], "dz must be a positive"),
        (["--surface", "bezier", "--pattern", "1", "--dz", "-1"], "dz must be a positive"),
        (
            ["--surface", "bezier", "--pattern", "1", "--theta-min", "120", "--theta-max", "30"],
            "theta_min < theta_max",
        ),
        (["--surface", "expr", "--expr", "__import__('os')", "--pattern", "1"], "refused"),
        (["--surface", "expr", "--expr", "x +", "--pattern", "1"], "invalid expression"),
        (["--surface", "expr", "--expr", "log(x)", "--pattern", "1"], "not finite"),
        (["--surface", "expr", "--pattern", "1"], "needs --expr"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "999"], "out of range"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "0"], "boundary edge"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "a"], "comma-separated"),
        (["--surface", "bezier", "--pattern", "1", "--symmetric"], "no mirror planes"),
        (["--surface", "bezier", "--pattern", "1", "--seed", "x"], "invalid int value"),
    ],
)
def test_bad_input_one_line_exit_2(tmp_path, args, message):
    proc = run_cli("optimize", *args, "--out", str(tmp_path / "o"))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert message in lines[0]
    assert "Traceback" not in proc.stderr


def test_output_path_that_is_a_file(tmp_path):
    target = tmp_path / "file"
    target.write_text("")
    proc = run_cli("optimize", "--surface", "dome", "--pattern", "11", "--out", str(target))
    assert proc.returncode == 2
    assert "cannot write to output directory" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_help_lists_optimize():
    proc = run_cli("--help")
    assert proc.returncode == 0 and "optimize" in proc.stdout


def test_closed_pipe_is_no_traceback():
    """``rigidfold analyze X --json | head -c 0``: the reader is gone before anything is
    written."""
    fold = Path(__file__).parent / "data" / "fold_examples" / "squaretwist.fold"
    proc = subprocess.Popen(
        [sys.executable, "-m", "rigidfold.cli", "analyze", str(fold), "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()
    with proc.stderr:
        err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141
    assert "Traceback" not in err and "BrokenPipe" not in err and err == ""


def test_version_and_quiet_exit():
    from rigidfold import __version__

    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", "--version"], capture_output=True, text=True
    )
    assert proc.returncode == 0 and proc.stdout.strip() == f"rigidfold {__version__}"


@pytest.mark.parametrize("verbose", [False, True])
def test_what_opensees_prints_at_exit_is_hidden_unless_verbose(tmp_path, verbose):
    fold = Path(__file__).parent / "data" / "fold_examples" / "squaretwist.fold"
    flags = ["--verbose"] if verbose else []
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "rigidfold.cli",
            *flags,
            "deform",
            str(fold),
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert ("Process 0 Terminating" in proc.stderr) is verbose


def test_develop_of_a_sheet_folded_flat_prints_nothing_from_casadi(tmp_path):
    """simple.fold has creases folded 180 degrees: the start of problem (13) puts vertices on
    one point, where CasADi used to print NaN-gradient warnings."""
    fold = Path(__file__).parent / "data" / "fold_examples" / "simple.fold"
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", "develop", str(fold), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert proc.stdout.startswith("converged: D = ")
