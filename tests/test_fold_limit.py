"""The restarts with a fold limit (issue 40): where a run's chain dead-ends with the
deployability check, it starts again from the initial shape with bound (12) at the next of
``Settings.generation.fold_limits`` on every solve."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import rigidfold.generate.deploy_check as deploy_check
import rigidfold.generate.steps as generation
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, Stop, generate, with_fold_limit
from rigidfold.generate.case_options import SettingsOptions
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.path import PathStatus


def fields_by_name(record) -> dict:
    return {f.name: f for f in dataclasses.fields(record)}


def _largest_fold_deg(pattern) -> float:
    free = ~pattern.fixed & ~pattern.is_boundary_edge
    return float(np.degrees(np.abs(pattern.fold_angles[free]).max()))


def test_the_restart_case_has_bound_12_at_the_limit():
    case = case_from_specs("dome", "1", seed=1)
    limit = math.radians(100)
    bounded = with_fold_limit(case, GenerateOptions(), limit)
    assert bounded.settings.design.rho_max == limit
    assert bounded.pattern is case.pattern and bounded.surface is case.surface
    # the paper's Step 5 (no check), the user's own bound (12): no restart
    assert with_fold_limit(case, GenerateOptions(deploy_check=False), limit) is case
    own = case_from_specs("dome", "1", seed=1, settings=DEFAULTS.with_(rho_max=math.radians(90)))
    assert with_fold_limit(own, GenerateOptions(), limit) is own
    assert all(0 < a < math.pi for a in DEFAULTS.generation.fold_limits)
    with pytest.raises(RigidfoldError, match="fold limit must lie in"):
        DEFAULTS.with_(fold_limits=(math.radians(190),))


def test_dead_ends_restart_the_chain_within_each_fold_limit_in_turn(monkeypatch):
    """The first two DOF-1 candidates' paths are made to turn back: with ``restart_after``
    1 the first chain is given up at the first; the chain bounded at 60 degrees, whose
    budget of rejected paths (``deploy_max_candidates`` 1) is spent, at the second, without
    backtracking; the chain bounded at 40 degrees (pattern 1 folds to about 50 on the way)
    keeps every free crease within it down to a DOF-1 design that deploys."""
    real = deploy_check.trace_path
    calls = []

    def first_two_turn_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        calls.append(path)
        if len(calls) <= 2:
            return dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        return path

    monkeypatch.setattr(deploy_check, "trace_path", first_two_turn_back)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", first_two_turn_back)
    limits = (60.0, 40.0)
    settings = DEFAULTS.with_(
        restart_after=1,
        deploy_max_candidates=1,
        fold_limits=tuple(math.radians(a) for a in limits),
        second_order_first=False,  # every candidate traced: the first two are the made-up
    )
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    taken_at_once: list[int] = []
    run = generate(
        case,
        criterion="s",
        seed=1,
        lookahead=True,
        deform=False,
        batch="off",  # a dead end of the sets would end the sets, not the chain
        on_retract=lambda _run, taken: taken_at_once.append(len(taken)),
    )

    chains: dict = {}
    for attempt in run.attempts:
        chains.setdefault(attempt.fold_limit_deg, []).append(attempt)
    assert list(chains) == [None, *(pytest.approx(a) for a in limits)]
    retracted = []
    for limit, attempts in list(chains.items())[:2]:  # the chains given up
        # the made-up dead end (its second-order test may find it rigid too)
        assert attempts[-1].outcome in (AttemptOutcome.PATH, AttemptOutcome.RIGID)
        accepted = [a for a in attempts if a.outcome is AttemptOutcome.DEAD_END]
        retracted.append(len(accepted))
        assert len(accepted) == len(attempts) - (2 if limit is None else 1)
    assert taken_at_once == retracted  # each chain taken back in one call, none backtracked
    assert chains[None][0].outcome is AttemptOutcome.ACCEPTED  # the initial shape is kept
    assert sum(retracted) == run.n_backtrack
    assert run.stop is Stop.TARGET_REACHED and run.final is not None
    assert run.final.path is not None and run.final.path.deploys
    tol = math.degrees(math.sqrt(2 * DEFAULTS.solver.constraint_tol)) + 1e-6
    for solution in run.solutions[1:]:  # the last chain's
        assert _largest_fold_deg(solution.result.pattern) <= limits[-1] + tol


def test_a_chain_that_deploys_is_not_restarted():
    run = generate(case_from_specs("dome", "1", seed=1), target_dof=12, deform=False)
    assert run.final_dof == 12
    assert all(a.fold_limit_deg is None for a in run.attempts)


def test_the_command_line_limits_in_degrees():
    default = DEFAULTS.generation.fold_limits
    assert SettingsOptions().settings().generation.fold_limits == default
    assert SettingsOptions(fold_limit=()).settings().generation.fold_limits == ()
    limits = SettingsOptions(fold_limit=(150.0, 90.0)).settings().generation.fold_limits
    assert limits == pytest.approx((math.radians(150), math.radians(90)))
    from rigidfold.cli.units import parser_of

    flag = fields_by_name(SettingsOptions)["fold_limit"].metadata["flag"]
    parse = parser_of(flag.parse)  # the command line reads the text (issue 46, item 2)
    assert parse("0") == () and parse("120,90") == (120.0, 90.0)
    for bad in ("200", "abc", "90,"):
        with pytest.raises(RigidfoldError):
            parse(bad)


def test_a_bounded_shape_whose_solves_fail_is_given_up_after_the_budget(monkeypatch):
    """Under bound (12) a shape whose candidates' solves do not converge (N_exceed) is given
    up after ``deploy_max_candidates`` of them, not after every candidate (the paper's Step
    7, which the unbounded chain keeps); the run ends with the chain that got lowest."""
    real_solve, real_trace = generation._Steps.solve, deploy_check.trace_path
    traces = []

    def first_turns_back(pattern, **kwargs):
        path = real_trace(pattern, **kwargs)
        traces.append(path)
        return (
            dataclasses.replace(path, status=PathStatus.TURNED_BACK) if len(traces) == 1 else path
        )

    def bounded_solves_fail(self, *args, **kwargs):
        rec, trial = real_solve(self, *args, **kwargs)
        if self.fold_limit is not None:
            rec.outcome = AttemptOutcome.EXCEED
        return rec, trial

    monkeypatch.setattr(deploy_check, "trace_path", first_turns_back)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", first_turns_back)
    monkeypatch.setattr(generation._Steps, "solve", bounded_solves_fail)
    settings = DEFAULTS.with_(  # one round (tests/test_reseed.py)
        restart_after=1, deploy_max_candidates=2, fold_limits=(math.radians(60.0),), reseeds=0
    )
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    # the paper's solver, IPOPT alone, with which this case's first path turns back
    run = generate(case, criterion="s", seed=1, batch="off", projection="large")
    bounded = [a for a in run.attempts if a.fold_limit_deg is not None]
    assert [a.outcome for a in bounded] == [AttemptOutcome.EXCEED] * 2
    assert run.stop is Stop.NO_DEPLOYABLE  # the first chain's stop, with its chain
    assert run.final_dof == run.lowest_dof > 1  # the first chain, taken back again
    accepted = [a for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]
    assert len(accepted) == len(run.solutions) and all(a.fold_limit_deg is None for a in accepted)


def _first_turn_back(monkeypatch, count: int, then: PathStatus | None = None) -> list:
    """The first ``count`` traced paths are made to turn back, the later ones to end as
    ``then`` (None: as traced); returns the traces."""
    real = deploy_check.trace_path
    calls: list = []

    def turn_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        calls.append(path)
        if len(calls) <= count:
            return dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        return path if then is None else dataclasses.replace(path, status=then)

    monkeypatch.setattr(deploy_check, "trace_path", turn_back)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", turn_back)
    return calls


def test_the_ladder_goes_on_whatever_the_bounded_chain_accepted(monkeypatch):
    """Issue 49, item 4: a bounded chain that accepts no solution at all (every bounded
    solve fails) still hands over to the next fold limit; each limit is tried in turn."""
    _first_turn_back(monkeypatch, 1)
    real_solve = generation._Steps.solve

    def bounded_solves_fail(self, *args, **kwargs):
        rec, trial = real_solve(self, *args, **kwargs)
        if self.fold_limit is not None:
            rec.outcome = AttemptOutcome.EXCEED
        return rec, trial

    monkeypatch.setattr(generation._Steps, "solve", bounded_solves_fail)
    limits = (60.0, 40.0)
    settings = DEFAULTS.with_(
        restart_after=1,
        deploy_max_candidates=2,
        fold_limits=tuple(math.radians(a) for a in limits),
    )
    for module in ("chains", "steps"):  # restart at once
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    # the paper's solver, IPOPT alone, with which this case's chains restart
    run = generate(case, criterion="s", seed=1, projection="large")
    tried = {a.fold_limit_deg for a in run.attempts if a.fold_limit_deg is not None}
    assert sorted(round(t) for t in tried) == sorted(limits)
    assert run.final_dof == run.lowest_dof  # the first chain, the lowest, is the run's


def test_a_restart_keeps_the_solutions_within_its_bound(monkeypatch):
    """A restart at a fold limit keeps the chain's solutions before the first one with a
    free crease beyond the limit (they solve (6) under bound (12) too), never the last (its
    candidates failed); a limit below the first solution's folds keeps the initial shape
    only."""
    for limit_deg in (179.0, 20.0):
        _first_turn_back(monkeypatch, 1)
        for module in ("chains", "steps"):  # restart at once
            monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
        settings = DEFAULTS.with_(
            restart_after=1, deploy_max_candidates=3, fold_limits=(math.radians(limit_deg),)
        )
        case = case_from_specs("bezier", "1", seed=1, settings=settings)
        taken: list[int] = []
        run = generate(
            case,
            criterion="s",
            seed=1,
            lookahead=True,
            deform=False,
            batch="off",  # the one-crease chain: the restart keeps what lies within the limit
            on_retract=lambda _run, t: taken.append(len(t)),  # noqa: B023
        )
        first = [a for a in run.attempts if a.fold_limit_deg is None]
        chain = [a for a in first if a.outcome.value in ("accepted", "dead_end")]
        assert len(chain) > 2
        assert taken, "the first chain was restarted"
        kept = len(chain) - taken[0]
        if limit_deg > 90:  # every free crease of pattern 1 stays far below it
            assert taken[0] == 1 and kept == len(chain) - 1
        else:
            assert kept == 1  # the initial shape


def test_the_first_chain_is_not_given_up_while_trying_is_cheaper(monkeypatch):
    """Past ``restart_after`` rejected paths, the first chain keeps trying the candidates of
    its shape forecast to deploy while they have cost less than re-solving the chain (here
    every attempt costs 1: the chain's solutions cost more than three candidates), and a
    candidate that deploys (here the fourth, made to) ends the run without a restart; where
    re-solving costs nothing, it restarts after ``restart_after``."""
    settings = DEFAULTS.with_(
        restart_after=1, second_order=False, fold_limits=(math.radians(60.0),)
    )
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    _first_turn_back(monkeypatch, 3, then=PathStatus.FLAT)
    for module in ("chains", "steps"):  # the chain's cost, a shape's
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 1.0)
    run = generate(case, criterion="s", seed=1, lookahead=True, deform=False)
    assert all(a.fold_limit_deg is None for a in run.attempts)
    assert sum(a.outcome is AttemptOutcome.PATH for a in run.attempts) >= 3
    assert run.stop is Stop.TARGET_REACHED and run.final.path.deploys
    _first_turn_back(monkeypatch, 3, then=PathStatus.FLAT)
    for module in ("chains", "steps"):  # the chain's cost, a shape's
        monkeypatch.setattr(
            f"rigidfold.generate.{module}.attempt_time",
            lambda rec: 0.0 if rec.outcome is AttemptOutcome.ACCEPTED else 1.0,
        )
    run = generate(case, criterion="s", seed=1, lookahead=True, deform=False)
    assert any(a.fold_limit_deg is not None for a in run.attempts)


def test_a_shape_met_again_is_rejected_as_before_without_a_trace(monkeypatch):
    """A candidate's solution whose shape was rejected before (the same fixed creases, DOF
    and coordinates: a kept shape's candidate tried again after a restart at a fold limit)
    is rejected as before, its verdict taken from the earlier attempt (``path_from``),
    without a trace; with ``same_shape_tol`` 0 it is traced again."""
    traced: list[int] = []
    real = deploy_check.trace_path

    def never_deploys(pattern, **kwargs):
        traced.append(kwargs["dof"])
        return dataclasses.replace(real(pattern, **kwargs), status=PathStatus.TURNED_BACK)

    monkeypatch.setattr(deploy_check, "trace_path", never_deploys)
    for tol in (DEFAULTS.generation.same_shape_tol, 0.0):
        traced.clear()
        settings = DEFAULTS.with_(deploy_check_max_dof=0, same_shape_tol=tol)  # check all
        case = case_from_specs("bezier", "1", seed=1, settings=settings)
        steps = generation._Steps(case, GenerateOptions(deform=False, batch="off"), None, None)
        _, first = steps.solve(case.pattern.fixed.copy(), None, (), None)
        crease = int(np.flatnonzero(~case.pattern.fixed & ~case.pattern.is_boundary_edge)[0])
        fixed = first.result.pattern.fixed.copy()
        fixed[crease] = True
        start = first.result.coords
        (a, trial_a), (b, trial_b) = (steps.solve(fixed, start, (crease,), 0.0) for _ in "ab")
        assert a.outcome in (AttemptOutcome.PATH, AttemptOutcome.RIGID) and a.path_from is None
        assert np.array_equal(trial_a.result.coords, trial_b.result.coords)
        assert b.outcome is a.outcome and b.dof == a.dof
        if tol > 0:
            assert b.path_from == a.index and b.path == a.path
            assert b.second_order == a.second_order
            assert traced == [first.mechanism.dof, a.dof]  # the initial shape's, a's
        else:
            assert b.path_from is None and traced == [first.mechanism.dof, a.dof, a.dof]
