"""--time-limit: the run ends with its best design named, checked, and a true verdict."""

from __future__ import annotations

import json

import pytest

from rigidfold.case import make_case
from rigidfold.cli import main
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Stop, generate
from rigidfold.generate_options import GenerateOptions


def test_a_time_limit_ends_the_run_with_a_named_design_and_exit_1(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(
        [
            "generate",
            "--surface",
            "bezier",
            "--seed",
            "1",
            "--pattern",
            "1",
            "--time-limit",
            "1e-6",
            "--no-deform",
            "--no-report",
            "--quiet",
            "--out",
            str(out),
        ]
    )
    assert code == 1
    last = capsys.readouterr().out.strip().splitlines()[-1]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stop"] == "time_limit"
    verdict = summary["verdict"]
    assert verdict["outcome"] == "fell_short" and "time limit" in verdict["message"]
    # the final design is named, exists, and its DOF is the one summary.json gives
    final = verdict["final_design"]
    assert final is not None and (out / final).is_file() and final in last
    step = summary["final_step"]
    assert summary["per_solution"][step]["dof"] == summary["final_dof"]
    assert summary["final_dof"] >= summary["lowest_dof"]
    assert (out / "final").is_dir()


def test_generate_stops_at_the_limit_between_solves():
    case = make_case("bezier", "1", seed=1)
    run = generate(case, GenerateOptions(deform=False), time_limit=1e-6)
    assert run.stop is Stop.TIME_LIMIT and run.stop_reason == "time limit of 1e-06 s reached"
    assert len(run.solutions) == 1 and run.final is run.solutions[0]
    assert run.dof_margin is not None and run.dof_margin["dof"] == run.final_dof


@pytest.mark.parametrize("bad", [0, -1.0, float("inf"), "10", True])
def test_a_time_limit_must_be_a_positive_number_of_seconds(bad):
    with pytest.raises(RigidfoldError, match="time limit"):
        GenerateOptions(time_limit=bad)
