"""--time-limit: the run ends with its best design named, checked, and a true verdict."""

from __future__ import annotations

import json

import pytest

import rigidfold.generate.deploy_check as deploy_check
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Stop, generate
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import SolverName


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
    case = case_from_specs("bezier", "1", seed=1)
    run = generate(case, GenerateOptions(deform=False), time_limit=1e-6)
    assert run.stop is Stop.TIME_LIMIT and run.stop_reason == "time limit of 1e-06 s reached"
    assert len(run.solutions) == 1 and run.final is run.solutions[0]
    assert run.dof_margin is not None and run.dof_margin["dof"] == run.final_dof


@pytest.mark.parametrize("bad", [0, -1.0, float("inf"), "10", True])
def test_a_time_limit_must_be_a_positive_number_of_seconds(bad):
    with pytest.raises(RigidfoldError, match="time limit"):
        GenerateOptions(time_limit=bad)


@pytest.mark.parametrize("stop", [Stop.TIME_LIMIT, Stop.NO_CANDIDATE], ids=["limit", "candidates"])
def test_a_run_that_falls_short_searches_its_chain_for_the_design_it_names(monkeypatch, stop):
    """Stopped at DOF 9, a run whose solutions' paths deploy down to DOF 15 and none below
    names the DOF-15 solution, not after one trace per solution from the last back: stopped
    by its time limit, by bisecting its chain (about log2 of its solutions' traces); with no
    candidate left, by probing from the last solution back in doubling steps, then
    bisecting (about 2 log2(d), d the DOF-15 solution's distance from the last)."""
    import math
    from types import SimpleNamespace

    import rigidfold.generate.steps as generation

    traced: list[int] = []

    def deploys_down_to_15(pattern, *, dof, **_):
        traced.append(dof)
        return SimpleNamespace(deploys=dof >= 15, cut=False)

    monkeypatch.setattr(deploy_check, "trace_path", deploys_down_to_15)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", deploys_down_to_15)
    if stop is Stop.TIME_LIMIT:
        monkeypatch.setattr(
            generation._Steps, "out_of_time", lambda self: len(self.run.attempts) > 12
        )
    else:
        real = generation._Steps.reduce

        def reduce(self, solution):
            return Stop.NO_CANDIDATE if len(self.run.attempts) > 12 else real(self, solution)

        monkeypatch.setattr(generation._Steps, "reduce", reduce)
        for move in ("unbatch", "restart", "backtrack"):  # no other chain: this one ends
            monkeypatch.setattr(generation._Steps, move, lambda self, *_, **__: False)
    options = GenerateOptions(deform=False, time_limit=3600.0, batch="off")  # a long chain
    run = generate(case_from_specs("bezier", "1", seed=1), options)
    assert run.stop is stop
    dofs = [s.mechanism.dof for s in run.solutions]
    assert min(dofs) < 15 <= max(dofs) and dofs == sorted(dofs, reverse=True)
    assert run.final is not None and run.final.mechanism.dof == 15
    d = len(dofs) - dofs.index(15)  # the traces of a scan from the last back
    if stop is Stop.TIME_LIMIT:
        assert 0 < len(traced) <= math.ceil(math.log2(len(dofs))) + 1 < d
    else:
        assert traced[0] == dofs[-1]  # the last solution first
        assert 0 < len(traced) <= 2 * math.ceil(math.log2(d)) < d


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

    seen: list = []
    real = deploy_check.trace_path

    def spy(pattern, **kw):
        seen.append(kw.get("deadline"))
        return real(pattern, **kw)

    monkeypatch.setattr(deploy_check, "trace_path", spy)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", spy)
    case = case_from_specs("bezier", "1", seed=1)
    t0 = time.monotonic()
    generate(case, GenerateOptions(deform=False, deploy_check=True, time_limit=3600.0))
    assert seen and all(d is not None and t0 + 3599.0 < d < t0 + 3601.0 for d in seen)
    seen.clear()
    generate(case, GenerateOptions(deform=False, deploy_check=True, target_dof=18))
    assert seen and all(d is None for d in seen)


@pytest.mark.parametrize(
    ("solver", "settings"),
    [
        (SolverName.IPOPT, {}),
        # the composite: projection, IPOPT, projection
        (SolverName.IPOPT, {"projection_vertices": 10}),
        (SolverName.SLSQP, {}),
    ],
)
def test_a_solve_past_its_deadline_ends_at_its_iterate(solver, settings):
    """Issue 49, item 3: the solve under way gets the run's remaining time. A deadline that
    has passed ends it at once, as an iteration limit (not accepted: the start is no zero of
    F); one far off changes nothing."""
    import time

    from rigidfold.config import DEFAULTS
    from rigidfold.optimize import Status

    case = case_from_specs("dome", "grid:5x5", size="3x3", settings=DEFAULTS.with_(**settings))
    problem = case.problem(build_ipopt=solver is SolverName.IPOPT)
    plain = problem.solve(solver=solver)
    assert plain.status is Status.CONVERGED
    far = problem.solve(solver=solver, deadline=time.monotonic() + 3600.0)
    assert far.status is plain.status and far.iterations == plain.iterations and far.F == plain.F
    cut = problem.solve(solver=solver, deadline=time.monotonic() - 1.0)
    assert cut.status is Status.ITERATION_LIMIT
    assert cut.iterations < plain.iterations
    again = problem.solve(solver=solver)  # the deadline was that solve's only
    assert again.status is Status.CONVERGED and again.iterations == plain.iterations


def test_a_solve_cut_by_the_time_limit_is_no_rejected_candidate(monkeypatch):
    """A candidate's solve that the time limit ends is recorded as ``time_limit``, not in
    N_exceed, and the run stops at the limit with its last solution."""
    import time

    import rigidfold.generate.steps as generation
    from rigidfold.generate import AttemptOutcome

    def passed_after_three(self):
        return time.monotonic() - 1.0 if len(self.run.attempts) >= 3 else None

    monkeypatch.setattr(generation._Steps, "deadline", property(passed_after_three))
    monkeypatch.setattr(generation._Steps, "out_of_time", lambda self: len(self.run.attempts) > 3)
    options = GenerateOptions(deform=False, time_limit=3600.0)
    run = generate(case_from_specs("bezier", "1", seed=1), options)
    assert run.stop is Stop.TIME_LIMIT
    last = run.attempts[-1]
    assert last.outcome is AttemptOutcome.TIME_LIMIT and last.iterations <= 1
    assert run.n_exceed == 0 and run.n_path == 0
    assert len(run.solutions) == 3 and run.to_dict()["n_solves"] == 4


def test_a_trace_cut_by_the_time_limit_is_no_rejected_path(monkeypatch):
    """A candidate whose path trace the time limit ends has no verdict: outcome
    ``time_limit``, not N_path, and the run stops there; a cut trace is never kept as a
    solution's path."""
    import time

    from rigidfold.generate import AttemptOutcome

    real = deploy_check.trace_path

    def cut(pattern, **kw):
        return real(pattern, **(kw | {"deadline": time.monotonic() - 1.0}))

    monkeypatch.setattr(deploy_check, "trace_path", cut)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", cut)
    options = GenerateOptions(deform=False, time_limit=3600.0)
    run = generate(case_from_specs("bezier", "1", seed=1), options)
    assert run.stop is Stop.TIME_LIMIT
    assert run.attempts[-1].outcome is AttemptOutcome.TIME_LIMIT
    assert run.attempts[-1].path is not None and run.attempts[-1].path["cut"]
    assert run.n_path == 0 and run.n_rigid == 0
    assert all(s.path is None or not s.path.cut for s in run.solutions)


def test_the_traces_naming_the_final_design_have_a_deadline_and_are_counted(monkeypatch):
    """After the search, the bisection's traces end a grace after the search's end (the
    limit T less the reserve for the final stages, :mod:`rigidfold.generate.budget`), and
    their seconds are in time_s.path."""
    import time

    import rigidfold.generate.steps as generation

    seen: list = []
    real = deploy_check.trace_path

    def slow(pattern, **kw):
        seen.append(kw.get("deadline"))
        time.sleep(0.01)
        return real(pattern, **kw)

    monkeypatch.setattr(deploy_check, "trace_path", slow)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", slow)
    monkeypatch.setattr(generation._Steps, "out_of_time", lambda self: len(self.run.attempts) > 6)
    t0 = time.monotonic()
    run = generate(
        case_from_specs("bezier", "1", seed=1), GenerateOptions(deform=False, time_limit=100)
    )
    assert run.stop is Stop.TIME_LIMIT and seen
    from rigidfold.generate.budget import time_budget

    # at the latest a grace after T less the idle reserve; the machine's load may stretch
    # the reserve, never beyond half of T
    idle = time_budget(t0, 100, case_from_specs("bezier", "1").pattern.n_vertices, DEFAULTS)
    assert all(d is not None and t0 + 50 < d < idle.naming + 1 for d in seen)
    assert run.final_path_time >= 0.01 * len(seen)
    assert run.to_dict()["time_s"]["path"] >= run.final_path_time


def test_a_time_limited_run_ends_within_its_grace():
    """Issue 49, item 3: a run of a pattern that needs far longer than its limit T returns
    by T + max(time_limit_grace_min, time_limit_grace T) (what it may take after the last
    solve's deadline: the analysis of one shape and the margin of the final design, here
    given a few seconds more on a shared machine)."""
    import time

    t0 = time.monotonic()
    run = generate(
        case_from_specs("dome", "grid:15x15", size="3x3"),
        GenerateOptions(deform=False, criterion="s", lookahead=True),
        time_limit=2.0,
    )
    wall = time.monotonic() - t0
    assert run.stop is Stop.TIME_LIMIT
    g = DEFAULTS.generation
    assert wall < 2.0 + max(g.time_limit_grace_min, 2.0 * g.time_limit_grace) + 3.0


def test_a_first_solve_cut_by_the_time_limit_ends_the_run_at_the_limit(monkeypatch):
    """The first solve that the limit ends says so: the stop is ``time_limit`` (no
    "no developable polyhedron", whose hints (a larger dz, other bounds) would mislead), its
    attempt's outcome ``time_limit``, no solution."""
    import time

    from rigidfold.generate import AttemptOutcome
    from rigidfold.generate.budget import TimeBudget

    monkeypatch.setattr(TimeBudget, "first_solve", property(lambda self: time.monotonic() - 1.0))
    run = generate(
        case_from_specs("bezier", "1", seed=1), GenerateOptions(deform=False), time_limit=5
    )
    assert run.stop is Stop.TIME_LIMIT and run.stop_reason == "time limit of 5 s reached"
    assert [a.outcome for a in run.attempts] == [AttemptOutcome.TIME_LIMIT]
    assert run.solutions == [] and run.final is None


def test_a_motion_cut_by_its_deadline_says_so_and_not_that_the_shape_is_stuck():
    """The final design's folding motion traced after a run's time limit ends at the run's
    deadline: its status is ``cut`` (the motion stage fails with that message), and the shape
    is not said to have no path to the plane."""
    import time

    from rigidfold.deform import MotionStatus, folding_motion
    from rigidfold.develop import develop

    run = generate(case_from_specs("bezier", "1", seed=1), GenerateOptions(deform=False))
    pattern = run.final.result.pattern
    flat = develop(pattern).coords2d
    cut = folding_motion(pattern, flat, dof=run.final_dof, deadline=time.monotonic() - 1.0)
    assert cut.status is MotionStatus.CUT and "time limit" in cut.message
    whole = folding_motion(pattern, flat, dof=run.final_dof, deadline=time.monotonic() + 3600)
    assert whole.status is MotionStatus.OK


def test_the_process_age_counts_from_the_start_of_the_process():
    """``--time-limit`` counts from the command's start: the age of this process is
    positive and grows with the clock (0.0 only where /proc cannot be read)."""
    import time

    from rigidfold.runtime.clock import process_age

    first = process_age()
    time.sleep(0.05)
    second = process_age()
    assert first > 0.0 and second >= first + 0.04


def test_the_time_budget_of_a_run(monkeypatch):
    """A run ends by T + max(10 s, 5 % of T) with the defaults; the search stops before T by
    the reserve for the final design's stages (grown with the pattern, at most a share of
    T, stretched by the machine's load) less half a grace; naming the final design ends a
    grace after the search, its path a grace and a half; the reserve fits between the
    path's end and the run's."""
    import time

    from rigidfold.generate.budget import time_budget

    g = DEFAULTS.generation
    assert time_budget(100.0, None, 50, DEFAULTS) is None
    for limit, vertices in [(180.0, 49), (180.0, 684), (600.0, 1681), (30.0, 1681), (4.0, 10)]:
        b = time_budget(100.0, limit, vertices, DEFAULTS)
        grace = max(10.0, 0.05 * limit) / 2
        assert b.grace == grace and b.end == 100.0 + limit + 2 * grace
        assert b.reserve <= g.time_limit_reserve_share * limit + 1e-12
        assert b.load() == 1.0  # just made
        assert b.search <= 100.0 + limit
        assert b.naming == b.search + grace and b.path == b.search + 1.5 * grace
        assert b.path + b.reserve <= b.end + 1e-9
    small, large = (time_budget(0.0, 180.0, v, DEFAULTS) for v in (49, 684))
    assert small.search >= 178.0  # a small pattern's stages take a few seconds
    assert large.reserve > small.reserve and large.search < small.search
    # a short limit keeps most of T for the search
    assert time_budget(0.0, 30.0, 1681, DEFAULTS).search >= 0.75 * 30.0
    # a loaded machine: twice the wall time of the CPU time stretches the reserve twice
    wall = [1000.0]
    monkeypatch.setattr(time, "monotonic", lambda: wall[0])
    monkeypatch.setattr(time, "process_time", lambda: wall[0] / 2)
    loaded = time_budget(0.0, 180.0, 684, DEFAULTS)
    wall[0] += 20.0  # 20 s of wall time, 10 s of CPU time
    assert loaded.load() == 2.0
    assert loaded.search == 180.0 - (2 * loaded.reserve - loaded.grace / 2)
    wall[0] += 1e6  # far more: at most load_max, and half of T kept for the search
    monkeypatch.setattr(time, "process_time", lambda: 500.0)
    assert loaded.load() == 1.0  # no CPU time measured: no stretch
    monkeypatch.setattr(time, "process_time", lambda: 501.0)
    assert loaded.load() == g.time_limit_load_max
    assert loaded.search >= 90.0


def test_a_limit_counts_from_the_commands_start_only_in_the_command():
    """In the ``rigidfold`` command (marked at its entry) a time limit counts from the
    process's start; a program calling the command line in its own process (these tests)
    counts from the run's start."""
    import os
    import subprocess
    import sys
    import time

    from rigidfold.runtime.clock import command_started

    assert command_started() is None  # pytest's process is not the command
    code = (
        "import time, rigidfold.runtime.clock as c; time.sleep(0.3); c.mark_command(); "
        "print(time.monotonic() - c.command_started())"
    )
    t0 = time.monotonic()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    age = float(out.stdout)
    tick = 1 / os.sysconf("SC_CLK_TCK")  # /proc gives the start in whole clock ticks
    assert 0.3 <= age <= time.monotonic() - t0 + tick
