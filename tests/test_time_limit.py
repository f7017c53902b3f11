"""--time-limit: the run ends with its best design named, checked, and a true verdict."""

from __future__ import annotations

import json

import pytest

from rigidfold.cli.commands import main
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Stop, generate
from rigidfold.generate.case import make_case
from rigidfold.generate.options import GenerateOptions


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


def test_a_time_limited_run_bisects_its_chain_for_the_design_it_names(monkeypatch):
    """Stopped by its time limit at DOF 9, a run whose solutions' paths deploy down to DOF
    15 and none below names the DOF-15 solution after about log2 of its solutions' traces,
    not one trace per solution from the last back."""
    import math
    from types import SimpleNamespace

    import rigidfold.generate.steps as generation

    traced: list[int] = []

    def deploys_down_to_15(pattern, *, dof, **_):
        traced.append(dof)
        return SimpleNamespace(deploys=dof >= 15)

    solves = iter(range(10**6))
    monkeypatch.setattr(generation, "trace_path", deploys_down_to_15)
    monkeypatch.setattr(generation._Steps, "out_of_time", lambda self: next(solves) >= 12)
    options = GenerateOptions(deform=False, time_limit=3600.0)
    run = generate(make_case("bezier", "1", seed=1), options)
    assert run.stop is Stop.TIME_LIMIT
    dofs = [s.mechanism.dof for s in run.solutions]
    assert min(dofs) < 15 <= max(dofs)
    assert run.final is not None and run.final.mechanism.dof == 15
    assert 0 < len(traced) <= math.ceil(math.log2(len(dofs))) + 1 < len(dofs) - dofs.index(15)


def test_a_path_trace_ends_at_its_deadline_out_of_budget():
    """A trace given a deadline that has passed ends at once, ``max_steps`` (out of budget),
    saying the time limit ended it; a deadline far off changes nothing."""
    import time

    import numpy as np

    from rigidfold.mechanism.path import PathStatus, trace_path
    from rigidfold.patterns.miura import miura

    shape = miura(3, 3, height=0.6)
    cut = trace_path(shape, dof=1, deadline=time.monotonic())
    assert cut.status is PathStatus.MAX_STEPS and cut.steps == 0
    assert "time limit" in cut.message
    free = trace_path(shape, dof=1, deadline=time.monotonic() + 3600.0)
    plain = trace_path(shape, dof=1)
    assert free.status is plain.status and free.steps == plain.steps
    assert np.array_equal(free.points, plain.points)


def test_the_candidates_paths_are_traced_to_the_runs_deadline(monkeypatch):
    """Generation hands its time limit to every candidate's trace as a deadline, so that a
    long trace does not overrun the limit (none without a limit)."""
    import time

    import rigidfold.generate.steps as generation

    seen: list = []
    real = generation.trace_path

    def spy(pattern, **kw):
        seen.append(kw.get("deadline"))
        return real(pattern, **kw)

    monkeypatch.setattr(generation, "trace_path", spy)
    case = make_case("bezier", "1", seed=1)
    t0 = time.monotonic()
    generate(case, GenerateOptions(deform=False, deploy_check=True, time_limit=3600.0))
    assert seen and all(d is not None and t0 + 3599.0 < d < t0 + 3601.0 for d in seen)
    seen.clear()
    generate(case, GenerateOptions(deform=False, deploy_check=True, target_dof=18))
    assert seen and all(d is None for d in seen)
