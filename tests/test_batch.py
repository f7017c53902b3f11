"""Several creases per solve (issue 49, item 2): the compatible set of ranked candidates
(independent rows in the mechanism space, no first-order lock), halved on failure, single
creases near the target; the paper's one crease per solve without the deployability check."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import rigidfold.generate.deploy_check as deploy_check
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.selection import lock_forecast, rank_candidates, score_creases
from rigidfold.selection.batch import compatible_set
from rigidfold.study import STUDY_OPTIONS


@pytest.fixture(scope="module")
def grid_shape():
    case = case_from_specs("dome", "grid:9x9", size="3x3")
    result = case.problem().solve()
    assert result.converged
    return result.pattern


def test_a_compatible_set_removes_one_dof_per_crease_and_locks_none(grid_shape):
    mech = analyze(grid_shape)
    ranked = [tuple(map(int, g)) for g, _ in rank_candidates(score_creases(mech), "s")]
    chosen = compatible_set(mech, ranked, 12)
    assert 2 <= len(chosen) <= 12 and chosen == sorted(chosen)
    union = tuple(e for k in chosen for e in ranked[k])
    forecast = lock_forecast(mech, [union])
    assert forecast.dof_after[0] == mech.dof - len(union)  # full rank in the mechanism space
    assert len(forecast.locks(0)) == 0  # no other crease locked at first order
    # the analysis of the shape with the set fixed, at the same geometry, agrees
    fixed = grid_shape.fixed.copy()
    fixed[list(union)] = True
    after = analyze(grid_shape.with_fixed(fixed))
    assert after.dof == mech.dof - len(union) and not after.has_lock


def test_a_set_takes_candidates_in_the_rankings_order_and_skips_what_it_is_told(grid_shape):
    mech = analyze(grid_shape)
    ranked = [tuple(map(int, g)) for g, _ in rank_candidates(score_creases(mech), "s")]
    chosen = compatible_set(mech, ranked, 4)
    assert chosen[0] == 0 or all(k not in chosen for k in range(chosen[0]))
    without_first = compatible_set(mech, ranked, 4, skip=lambda k: k == chosen[0])
    assert chosen[0] not in without_first
    assert compatible_set(mech, ranked, 1) == chosen[:1]
    assert compatible_set(mech, ranked, 0) == []


def test_batch_is_checked():
    assert GenerateOptions().batch == "auto"  # sets until the first dead end (issue 49)
    assert GenerateOptions(batch="off").batch == "off"
    # a study keeps the paper's order, with the deployability check too
    assert STUDY_OPTIONS.replace(deploy_check=True).batch == "off"
    assert GenerateOptions(batch="auto").batch == "auto"
    with pytest.raises(RigidfoldError, match="batch"):
        GenerateOptions(batch="yes")
    with pytest.raises(RigidfoldError, match="batch_max"):
        DEFAULTS.with_(batch_max=0)


def test_several_creases_per_solve_far_from_the_target_one_near_it(monkeypatch):
    """With the deployability check (batch auto), far from the target DOF sets of creases
    are fixed in one solve, each removing as many DOF at least as its size forecast allows;
    within batch_single_dof of the target every solve fixes one candidate; fewer solves than
    the one-crease order to the same target. A set's solution is not polished (it is never
    traced), every other one is; no near-mechanism is fixed alone at a shape that gets a set."""
    import rigidfold.generate.steps as steps

    polished: list[bool] = []
    solve = steps._Steps.solve

    def watched(self, fixed, start, added, score, *, polish=True):
        polished.append(polish)
        return solve(self, fixed, start, added, score, polish=polish)

    monkeypatch.setattr(steps._Steps, "solve", watched)
    case = case_from_specs("dome", "grid:11x11", size="3x3")
    single = DEFAULTS.generation.batch_single_dof
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8, batch="auto")
    run = generate(case, opts)
    assert run.final_dof == 8
    sets = [a for a in run.attempts if a.batch >= 2]
    assert sets and all(len(a.fixed_added) >= a.batch for a in sets)
    assert polished == [a.batch < 2 for a in run.attempts]
    shape_dof = run.initial_dof
    for a in run.attempts[1:]:
        if a.near is not None:  # one crease per solve from here: no set at this shape
            assert shape_dof - opts.target_dof - single < 2
        if a.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END):
            shape_dof = a.dof
    for a in sets:
        if a.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END):
            assert a.dof >= opts.target_dof + single
    # a set is sized by the exact DOF of its shape (the rank threshold), not the count
    # with the gap, whose near-mechanisms a set does not remove first
    accepted = [a for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]
    assert len(accepted) == len(run.solutions)
    rank_tol = DEFAULTS.mechanism.rank_tol
    exact = [s.mechanism.dof_at(rank_tol) for s in run.solutions]
    for k, a in enumerate(accepted[1:], start=1):
        if a.batch >= 2:
            assert a.batch <= exact[k - 1] - opts.target_dof - single
    paper = generate(case, opts.replace(batch="off"))
    assert all(a.batch == 0 for a in paper.attempts)
    assert len(run.attempts) < len(paper.attempts)


def test_the_papers_step_5_fixes_one_crease_per_solve():
    run = generate(
        case_from_specs("bezier", "1", seed=1), deploy_check=False, target_dof=10, batch="auto"
    )
    assert all(a.batch == 0 and len(a.fixed_added) <= 1 for a in run.attempts)


def _restarted(monkeypatch, batch: str, keep):
    """An 11 x 11 grid on the dome to DOF 8 whose first traced path is made to turn back, so
    that the first chain restarts at once under a 120-degree fold limit, keeping
    ``keep(solutions)`` of its solutions (in place of ``within``): (options, run, the first
    chain's attempts, the bounded chain's)."""
    import dataclasses

    from rigidfold.mechanism.path import PathStatus

    real, traces = deploy_check.trace_path, []

    def first_turns_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        traces.append(path)
        if len(traces) == 1:
            return dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        return path

    monkeypatch.setattr(deploy_check, "trace_path", first_turns_back)
    monkeypatch.setattr("rigidfold.generate.final.trace_path", first_turns_back)
    monkeypatch.setattr(
        "rigidfold.generate.chains.within", lambda solutions, limit: keep(solutions)
    )
    for module in ("chains", "steps"):  # restart at once
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
    settings = DEFAULTS.with_(
        restart_after=1, fold_limits=(math.radians(120.0),), unbatch_peel=False
    )
    case = case_from_specs("dome", "grid:11x11", size="3x3", settings=settings)
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8, batch=batch)
    run = generate(case, opts)
    first = [a for a in run.attempts if a.fold_limit_deg is None]
    bounded = [a for a in run.attempts if a.fold_limit_deg is not None]
    return opts, run, first, bounded


def test_auto_leaves_sets_at_the_first_dead_end_for_one_crease_per_solve(monkeypatch):
    """``batch`` auto without ``unbatch_peel``: at the batched first chain's first dead end
    (its first traced path made to turn back), the solutions from the first set on are
    retracted and the chain goes on from the shape before it (the initial one) one crease
    per solve, without a fold limit: from there the run is the paper's order (``batch``
    off)."""
    _, run, first, _ = _restarted(monkeypatch, "auto", keep=lambda solutions: 1)
    assert first[1].batch >= 2  # the first set was made at the initial shape
    turned = next(k for k, a in enumerate(first) if a.outcome is AttemptOutcome.PATH)
    assert any(a.batch >= 2 for a in first[:turned])
    after = first[turned + 1 :]
    assert after and all(a.batch == 0 and len(a.fixed_added) == 1 for a in after)
    assert after[0].dof == run.initial_dof - 1
    assert all(a.outcome is not AttemptOutcome.ACCEPTED for a in first[:turned] if a.batch >= 2)


def test_after_the_sets_the_run_is_the_one_crease_runs(monkeypatch):
    """Without ``unbatch_peel``, from the initial shape, the chain that follows the sets'
    dead end is the run of ``batch`` off, attempt for attempt (the same fixes, outcomes and
    DOF: the ranking draws from its generator as at the start)."""
    import rigidfold.generate.steps as steps
    from rigidfold.mechanism.path import PathStatus

    real, traces = deploy_check.trace_path, []

    def first_turns_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        traces.append(path)
        return replace(path, status=PathStatus.TURNED_BACK) if len(traces) == 1 else path

    settings = DEFAULTS.with_(restart_after=1, unbatch_peel=False)
    case = case_from_specs("dome", "grid:11x11", size="3x3", settings=settings)
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8)
    paper = generate(case, opts.replace(batch="off"))
    monkeypatch.setattr(deploy_check, "trace_path", first_turns_back)
    for module in ("chains", "steps"):  # given up at once
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
    rank, draws = steps._Steps.rank, []

    def watched(self, current):  # the generator's state as each shape is ranked
        draws.append((current.step, len(self.run.attempts), self.rng.bit_generator.state))
        return rank(self, current)

    monkeypatch.setattr(steps._Steps, "rank", watched)
    run = generate(case, opts.replace(batch="auto"))
    turned = next(a.index for a in run.attempts if a.outcome is AttemptOutcome.PATH)
    assert any(a.batch >= 2 for a in run.attempts[:turned])
    again = next(d for d in draws if d[1] > turned)
    assert again[0] == 0 and again[2] == draws[0][2]  # the initial shape, as at the start

    def seen(attempts):
        return [(a.fixed_added, a.outcome, a.dof) for a in attempts]

    assert seen(run.attempts[turned + 1 :]) == seen(paper.attempts[1:])
    assert run.final_dof == paper.final_dof == opts.target_dof


def test_on_batches_a_restarted_chain_too(monkeypatch):
    """``batch`` on: the dead-ended first chain restarts under the fold limit (here from
    the initial shape) and goes on with sets of creases."""
    _, _, first, bounded = _restarted(monkeypatch, "on", keep=lambda solutions: 1)
    assert any(a.batch >= 2 for a in first) and bounded
    assert all(a.fold_limit_deg is not None for a in bounded)
    assert any(a.batch >= 2 for a in bounded)


def _every_path_turns_back(monkeypatch, settings, batch: str):
    """An 11 x 11 grid on the dome to DOF 8 whose every traced path is made to turn back,
    a chain's seconds made free (so that the first chain gives up after ``restart_after``,
    not ``worth_more``) and no final design named: the run and the attempts of its first
    chain (no fold limit)."""
    import rigidfold.generate.chains as chains
    from rigidfold.mechanism.path import PathStatus, trace_path

    def turns_back(pattern, **kwargs):  # a few steps of the trace: only its end is asked
        short = kwargs["settings"].with_(path_max_steps=2)
        path = trace_path(pattern, **(kwargs | {"settings": short}))
        return replace(path, status=PathStatus.TURNED_BACK)

    monkeypatch.setattr(deploy_check, "trace_path", turns_back)
    monkeypatch.setattr(chains, "deployable_final", lambda *args, **kwargs: None)  # not asked
    for module in ("chains", "steps"):
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
    case = case_from_specs("dome", "grid:11x11", size="3x3", settings=settings)
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8, batch=batch)
    run = generate(case, opts)
    return run, [a for a in run.attempts if a.fold_limit_deg is None]


REJECTED = (AttemptOutcome.PATH, AttemptOutcome.RIGID, AttemptOutcome.NO_GAP)


def test_the_sets_end_sooner_at_rejected_paths(monkeypatch):
    """Once a set gave a solution, ``batch_end_after`` rejected paths at a shape end the
    sets, fewer than ``restart_after`` (3 here) allows: the next attempt fixes one crease at
    the initial shape. Without a set (none is made far enough from the target), the first
    chain's shape is given up after ``restart_after`` rejected paths, as with ``batch``
    off."""
    settings = DEFAULTS.with_(  # one bounded chain, given up soon, no backtracking, one round
        reseeds=0,
        restart_after=3,
        second_order=False,
        deploy_max_candidates=3,
        backtrack_max=0,
        fold_limits=(math.radians(120.0),),
        unbatch_peel=False,
    )
    ends = settings.generation.batch_end_after
    assert 1 <= ends < 3
    run, first = _every_path_turns_back(monkeypatch, settings, "auto")
    turned = [k for k, a in enumerate(first) if a.outcome in REJECTED][ends - 1]
    assert sum(a.outcome in REJECTED for a in first[: turned + 1]) == ends
    assert any(a.batch >= 2 and a.outcome is AttemptOutcome.DEAD_END for a in first[:turned])
    assert first[turned + 1].batch == 0 and len(first[turned + 1].fixed_added) == 1
    assert first[turned + 1].dof == run.initial_dof - 1
    # no set: the paper's order, given up after restart_after rejected paths
    unbatched = settings.with_(batch_single_dof=1000)
    _, first = _every_path_turns_back(monkeypatch, unbatched, "auto")
    assert all(a.batch == 0 for a in first)
    assert sum(a.outcome in REJECTED for a in first) == 3
    _, off = _every_path_turns_back(monkeypatch, unbatched, "off")
    assert [(a.fixed_added, a.outcome) for a in off] == [(a.fixed_added, a.outcome) for a in first]


def test_a_set_is_sized_by_the_exact_dof_not_the_near_mechanisms_counted_with_them():
    """With the gap count a shape's DOF include its near-mechanisms (singular values
    between the rank threshold and the gap), which a set of creases does not remove first:
    the set's room is the exact DOF less the target and ``batch_single_dof``. The shape is
    a solved 11 x 11 grid on the dome; ten of its singular values are put in the near band."""
    import rigidfold.generate.steps as steps

    case = case_from_specs("dome", "grid:11x11", size="3x3")
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, batch="auto")
    run_steps = steps._Steps(case, opts, None, None)
    rec, trial = run_steps.solve(case.pattern.fixed.copy(), None, (), None)
    run_steps.record(rec, trial)
    current = run_steps.run.solutions[-1]
    g, m = DEFAULTS.generation, DEFAULTS.mechanism
    run_steps.batch_size = g.batch_max
    mech = current.mechanism
    assert mech.dof_at(m.rank_tol) == mech.dof  # no near-mechanism of its own
    room = mech.dof - opts.target_dof - g.batch_single_dof
    assert run_steps.set_size(current) == min(g.batch_max, room)
    near = np.full(10, math.sqrt(m.dof_gap) * m.rank_tol * mech.rank_scale)
    softer = replace(mech, rank_values=np.concatenate([mech.rank_values, near]))
    assert softer.dof == mech.dof and softer.dof_at(m.rank_tol) == mech.dof - 10
    assert run_steps.set_size(replace(current, mechanism=softer)) == min(g.batch_max, room - 10)


def _turning_back(monkeypatch, turned: set[int], peel: bool):
    """The 11 x 11 grid on the dome to DOF 8 with ``batch`` auto and ``unbatch_peel``
    ``peel``, the traced paths numbered in ``turned`` (1 the first) made to turn back and a
    chain's seconds made free (a shape is given up at its first rejected path): the run."""
    from rigidfold.mechanism.path import PathStatus

    real, traces = deploy_check.trace_path, []

    def turns_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        traces.append(path)
        return replace(path, status=PathStatus.TURNED_BACK) if len(traces) in turned else path

    monkeypatch.setattr(deploy_check, "trace_path", turns_back)
    for module in ("chains", "steps"):
        monkeypatch.setattr(f"rigidfold.generate.{module}.attempt_time", lambda rec: 0.0)
    settings = DEFAULTS.with_(restart_after=1, unbatch_peel=peel)
    case = case_from_specs("dome", "grid:11x11", size="3x3", settings=settings)
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8)
    return generate(case, opts.replace(batch="auto"))


def test_peeling_retracts_the_sets_one_at_a_time_from_the_last(monkeypatch):
    """``unbatch_peel``: the batched chain's first dead end retracts its last set of creases
    only (the chain goes on one crease per solve from the shape before it, the earlier set
    kept); the next dead end retracts the set before it, here back to the initial shape.
    Without it, the first dead end goes back to before the first set."""
    run = _turning_back(monkeypatch, {1}, peel=True)
    first = next(k for k, a in enumerate(run.attempts) if a.outcome is AttemptOutcome.PATH)
    chain = run.attempts[:first]  # the first chain, every attempt accepted until the trace
    assert all(a.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END) for a in chain)
    sets = [k for k, a in enumerate(chain) if a.batch >= 2]
    assert len(sets) >= 2  # 37 DOF to 8 with sets far from the target: 8 creases, then more
    after = run.attempts[first + 1]
    assert after.batch == 0 and len(after.fixed_added) == 1
    assert after.dof == chain[sets[-1] - 1].dof - 1  # from the shape before the last set
    assert run.attempts[sets[-1]].outcome is AttemptOutcome.DEAD_END
    assert run.attempts[sets[0]].outcome is AttemptOutcome.ACCEPTED  # kept to the end
    assert run.final_dof == 8
    assert all(a.batch == 0 for a in run.attempts[first:])  # no set after a dead end

    run = _turning_back(monkeypatch, {1, 2}, peel=True)
    turned = [k for k, a in enumerate(run.attempts) if a.outcome is AttemptOutcome.PATH]
    assert len(turned) == 2
    again = run.attempts[turned[1] + 1]
    assert again.dof == chain[sets[-2] - 1].dof - 1  # the set before it retracted too
    assert all(run.attempts[k].outcome is AttemptOutcome.DEAD_END for k in sets)
    assert run.final_dof == 8

    run = _turning_back(monkeypatch, {1}, peel=False)
    first = next(k for k, a in enumerate(run.attempts) if a.outcome is AttemptOutcome.PATH)
    assert run.attempts[first + 1].dof == run.initial_dof - 1  # before the first set
    assert all(run.attempts[k].outcome is AttemptOutcome.DEAD_END for k in sets)


def test_unbatch_peel_is_a_boolean():
    with pytest.raises(RigidfoldError, match="unbatch_peel"):
        DEFAULTS.with_(unbatch_peel=1)
