"""Several creases per solve (issue 49, item 2): the compatible set of ranked candidates
(independent rows in the mechanism space, no first-order lock), halved on failure, single
creases near the target; the paper's one crease per solve without the deployability check."""

from __future__ import annotations

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.selection import lock_forecast, rank_candidates, score_creases
from rigidfold.selection.batch import compatible_set


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
    assert GenerateOptions().batch == "off"  # the paper's order unless asked
    assert GenerateOptions(batch="auto").batch == "auto"
    with pytest.raises(RigidfoldError, match="batch"):
        GenerateOptions(batch="yes")
    with pytest.raises(RigidfoldError, match="batch_max"):
        DEFAULTS.with_(batch_max=0)


def test_several_creases_per_solve_far_from_the_target_one_near_it():
    """With the deployability check (batch auto), far from the target DOF sets of creases
    are fixed in one solve, each removing as many DOF at least as its size forecast allows;
    within batch_single_dof of the target every solve fixes one candidate; fewer solves than
    the one-crease order to the same target."""
    case = case_from_specs("dome", "grid:11x11", size="3x3")
    single = DEFAULTS.generation.batch_single_dof
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8, batch="auto")
    run = generate(case, opts)
    assert run.final_dof == 8
    sets = [a for a in run.attempts if a.batch >= 2]
    assert sets and all(len(a.fixed_added) >= a.batch for a in sets)
    for a in sets:
        if a.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END):
            assert a.dof >= opts.target_dof + single
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
    ``keep(solutions)`` of its solutions (in place of ``_within``): (options, run, the first
    chain's attempts, the bounded chain's)."""
    import dataclasses
    import math

    import rigidfold.generate.steps as generation
    from rigidfold.mechanism.path import PathStatus

    real, traces = generation.trace_path, []

    def first_turns_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        traces.append(path)
        if len(traces) == 1:
            return dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        return path

    monkeypatch.setattr(generation, "trace_path", first_turns_back)
    monkeypatch.setattr(generation, "_within", lambda solutions, limit: keep(solutions))
    monkeypatch.setattr(generation, "_attempt_time", lambda rec: 0.0)  # restart at once
    settings = DEFAULTS.with_(restart_after=1, fold_limits=(math.radians(120.0),))
    case = case_from_specs("dome", "grid:11x11", size="3x3", settings=settings)
    opts = GenerateOptions(deform=False, criterion="s", lookahead=True, target_dof=8, batch=batch)
    run = generate(case, opts)
    first = [a for a in run.attempts if a.fold_limit_deg is None]
    bounded = [a for a in run.attempts if a.fold_limit_deg is not None]
    return opts, run, first, bounded


@pytest.mark.parametrize("batch", ["auto", "on"])
def test_auto_batches_the_first_chain_and_a_restart_fixes_one_crease_per_solve(monkeypatch, batch):
    """``batch`` auto: when the batched first chain dead-ends and the run restarts under a
    fold limit, the new chain is the paper's one crease per solve (a different chain, not
    the same one under the bound); ``on`` batches every chain. The restart is made to keep
    the initial shape only, so that the bounded chain starts far from the target."""
    _, run, first, bounded = _restarted(monkeypatch, batch, keep=lambda solutions: 1)
    assert any(a.batch >= 2 for a in first)
    assert bounded
    if batch == "auto":  # from the initial shape, one crease per solve
        assert all(a.batch == 0 and len(a.fixed_added) == 1 for a in bounded)
        assert bounded[0].dof == run.initial_dof - 1
    else:
        assert any(a.batch >= 2 for a in bounded)


@pytest.mark.parametrize("batch", ["auto", "on"])
def test_an_auto_restart_keeps_no_shape_made_by_a_set(monkeypatch, batch):
    """Where the restart may keep every shape of the dead-ended chain but its last (all
    within the fold limit), ``auto`` goes back to the shape before the first set (here the
    initial one) and ``on`` goes on from the kept shapes."""
    opts, run, first, bounded = _restarted(
        monkeypatch, batch, keep=lambda solutions: len(solutions) - 1
    )
    assert first[1].batch >= 2 and bounded  # the first set was made at the initial shape
    if batch == "auto":
        assert bounded[0].dof == run.initial_dof - 1
    else:
        assert bounded[0].dof <= opts.target_dof + 1
