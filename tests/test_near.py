"""Near-mechanisms first (issue 49, item 5): at a shape whose DOF counted with the gap has
fewer exact mechanisms, the candidates that turn in the near-mechanisms but hardly in the
exact ones are fixed first; their fix keeps the exact motion (checked in the frame's
displacements, a second method), and the run tries them before its ranked candidates."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.mesh import CreasePattern
from rigidfold.selection.near import near_candidates

DATA = Path(__file__).parent / "data" / "near_mechanism"
# A DOF-2 shape of the search (pattern 1 on Bezier surface 2027, S-hat, look-ahead; the
# broad set, session 25) whose every DOF-1 child it tried was second-order rigid: one exact
# mechanism (singular value ~1e-17 of the largest) and one near-mechanism (~4e-7, counted
# under the gap, 1e-6), the latter at two vertices whose creases turn by less than 2e-4 rad.
SHAPE = DATA / "paper1_bezier2027_dof2.npz"
LOCK_TOL = DEFAULTS.mechanism.lock_tol
RATIO = DEFAULTS.generation.near_ratio


@pytest.fixture(scope="module")
def shape() -> CreasePattern:
    data = np.load(SHAPE)
    return CreasePattern(
        coords=data["coords"],
        faces=data["faces"].astype(np.int64),
        edges=data["edges"].astype(np.int64),
        fixed=data["fixed"],
    )


@pytest.fixture(scope="module")
def analyses(shape):
    m = DEFAULTS.mechanism
    gap = DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
    return analyze(shape, settings=gap), analyze(shape)


def test_the_shape_has_a_near_mechanism_beside_its_exact_one(analyses):
    counted, exact = analyses
    assert counted.dof == 2 and exact.dof == 1


def test_the_first_candidates_keep_the_exact_motion(analyses):
    counted, exact = analyses
    found = near_candidates(counted, exact, None, RATIO, LOCK_TOL)
    assert found
    shares = [share for _, share in found]
    assert shares == sorted(shares) and max(shares) < RATIO
    e = exact.H[:, 0] / np.linalg.norm(exact.H[:, 0])
    row_of = {int(c): j for j, c in enumerate(counted.hinges)}
    for group, share in found:
        # fixing c keeps the counted motions H a with H_phi[c] a = 0 (d = 2: one line)
        r = counted.H_phi[row_of[group[0]]]
        kept = counted.H @ np.array([-r[1], r[0]])
        overlap = abs(kept @ e) / np.linalg.norm(kept)
        assert overlap > 1 - 10 * share**2 - 1e-6  # the exact motion, to second order in r
    # a crease that turns in the exact motion keeps a motion far from it
    hinge = int(np.argmax(np.abs(exact.H_phi[:, 0])))
    r = counted.H_phi[hinge]
    kept = counted.H @ np.array([-r[1], r[0]])
    assert abs(kept @ e) / np.linalg.norm(kept) < 0.9


def test_groups_are_judged_whole_and_only_where_every_crease_is_free(analyses, shape):
    counted, exact = analyses
    alone = near_candidates(counted, exact, None, RATIO, LOCK_TOL)
    singles = [(int(c),) for c in counted.hinges]
    assert near_candidates(counted, exact, singles, RATIO, LOCK_TOL) == alone
    best = alone[0][0][0]
    fixed_edge = int(np.flatnonzero(shape.fixed)[0]) if shape.fixed.any() else None
    boundary_edge = int(shape.boundary_edges[0])
    with_held = [(best, fixed_edge if fixed_edge is not None else boundary_edge)]
    assert near_candidates(counted, exact, with_held, RATIO, LOCK_TOL) == []


def test_the_best_candidate_keeps_the_exact_motion_and_removes_the_near_one(analyses, shape):
    """A second method: the shape analysed again with its best near candidate fixed, at the
    same geometry (first order; the search then re-solves), keeps its exact DOF 1 and its
    gap count falls from 2 to 1; a crease that turns in the exact motion leaves DOF 0."""
    counted, exact = analyses
    m = DEFAULTS.mechanism
    gap = DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
    (best,), _ = near_candidates(counted, exact, None, RATIO, LOCK_TOL)[0]
    fixed = shape.fixed.copy()
    fixed[best] = True
    repaired = shape.with_fixed(fixed)
    assert analyze(repaired).dof == exact.dof == 1
    assert analyze(repaired, settings=gap).dof == 1
    # a crease that turns in the exact motion takes it away instead
    hinge = int(exact.hinges[np.argmax(np.abs(exact.H_phi[:, 0]))])
    fixed = shape.fixed.copy()
    fixed[hinge] = True
    assert analyze(shape.with_fixed(fixed)).dof == 0


def test_no_candidates_without_near_mechanisms_or_without_exact_ones(analyses):
    counted, exact = analyses
    assert near_candidates(exact, exact, None, RATIO, LOCK_TOL) == []
    assert near_candidates(counted, counted, None, RATIO, LOCK_TOL) == []


def test_none_where_the_shape_has_more_near_mechanisms_than_near_max(analyses):
    counted, exact = analyses  # one near-mechanism
    found = near_candidates(counted, exact, None, RATIO, LOCK_TOL)
    assert near_candidates(counted, exact, None, RATIO, LOCK_TOL, most=1) == found
    assert near_candidates(counted, exact, None, RATIO, LOCK_TOL, most=0) == []


def test_the_settings_are_checked():
    with pytest.raises(RigidfoldError, match="near_tries"):
        DEFAULTS.with_(near_tries=-1)
    for bad in (-1, 2.5, True):
        with pytest.raises(RigidfoldError, match="near_max"):
            DEFAULTS.with_(near_max=bad)
    with pytest.raises(RigidfoldError, match="near_ratio"):
        DEFAULTS.with_(near_ratio=-0.1)


def test_a_run_tries_the_near_mechanisms_candidates_first():
    """Pattern 1 on Bezier surface 2027 with the look-ahead and the check (the case above):
    every candidate tried first has its share below near_ratio and is one crease; where the
    shape had any, they come before its ranked candidates (one crease per solve: a shape
    that gets a set of creases has no near sweep, tests/test_batch.py)."""
    case = case_from_specs("bezier", "1", seed=2027)
    options = GenerateOptions(  # the paper's solver, IPOPT alone: the case above
        deform=False, lookahead=True, seed=2027, time_limit=120, batch="off", projection="large"
    )
    run = generate(case, options)
    near = [a for a in run.attempts if a.near is not None]
    assert near
    assert all(a.near < RATIO and len(a.fixed_added) == 1 for a in near)
    assert all(a.near is not None for a in run.attempts if a.outcome is AttemptOutcome.NO_GAIN)
    for a in near:  # after the solve that made the shape, or another candidate tried first
        before = run.attempts[a.index - 1]
        assert before.near is not None or before.outcome in (
            AttemptOutcome.ACCEPTED,
            AttemptOutcome.DEAD_END,
        )


def test_a_near_fix_that_raises_the_count_is_not_kept(monkeypatch):
    """A solution of a near candidate with more DOF than its shape is ``no_gain``: counted in
    no N, never a solution, and the shape goes on with its ranked candidates."""
    import rigidfold.generate.steps as steps

    calls: list[int] = []

    def one_candidate(counted, exact, groups, ratio, floor, most=None):
        calls.append(counted.dof)
        return [((int(counted.hinges[0]),), 0.0)] if len(calls) == 1 else []

    solve = steps._Steps.try_fix

    def raised(self, current, shape, fix, score, **kwargs):
        rec, trial = solve(self, current, shape, fix, score, **kwargs)
        if len(calls) == 1 and rec.outcome is AttemptOutcome.ACCEPTED:
            rec.dof = current.mechanism.dof + 1  # as if the solve found a softer shape
        return rec, trial

    def one_near(self, rank_tol):  # every shape has one near-mechanism: fix_near looks
        return self.dof - 1

    monkeypatch.setattr(steps, "near_candidates", one_candidate)
    monkeypatch.setattr(steps._Steps, "try_fix", raised)
    monkeypatch.setattr(steps.Mechanism, "dof_at", one_near)
    case = case_from_specs("dome", "grid:4x4", size="2x2")
    run = generate(case, GenerateOptions(deform=False, lookahead=True, time_limit=60))
    first = run.attempts[1]
    assert first.near == 0.0 and first.outcome is AttemptOutcome.NO_GAIN
    assert run.n_reduce >= 1 and all(
        s.mechanism.dof < run.solutions[0].mechanism.dof for s in run.solutions[1:]
    )
    assert run.solutions[1].step == 1 and run.attempts[2].near is None


def test_a_shape_rigid_but_for_near_mechanisms_is_a_dead_end(monkeypatch):
    """With ``near_rigid_backtrack``, a shape after the first without exact mechanisms is
    backtracked at once: its solution becomes a dead end and its parent goes on."""
    from rigidfold.mechanism import Mechanism

    exact_dof = Mechanism.dof_at
    rigid: list[Mechanism] = []  # the first child's mechanism, held (its exact count is 0)

    def first_child_rigid(self, rank_tol):  # the exact count (fix_near, the sets' size)
        if self.pattern.fixed.sum() == 1 and (not rigid or rigid[0] is self):
            rigid[:] = [self]
            return 0
        return exact_dof(self, rank_tol)

    monkeypatch.setattr(Mechanism, "dof_at", first_child_rigid)
    settings = DEFAULTS.with_(near_rigid_backtrack=True)
    case = case_from_specs("dome", "grid:4x4", size="2x2", settings=settings)
    assert not case.pattern.fixed.any()
    run = generate(case, GenerateOptions(deform=False, lookahead=True, time_limit=60))
    assert rigid and rigid[0].dof >= 1  # accepted with DOF counted, none exact
    assert run.attempts[1].outcome is AttemptOutcome.DEAD_END
    assert run.attempts[2].outcome is not AttemptOutcome.DEAD_END  # the parent went on


@pytest.mark.parametrize("method", ["kinematic", "sparse", "frame"])
def test_the_exact_count_from_the_gap_counts_factorisation_is_a_second_analysis(shape, method):
    """``Mechanism.dof_at``: the DOF of the gap count's own factorisation at the rank
    threshold is the DOF a second analysis at that threshold finds, by every method."""
    m = DEFAULTS.mechanism
    gap = DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
    counted = analyze(shape, method=method, settings=gap)
    exact = analyze(shape, method=method)
    assert counted.dof == 2 and exact.dof == 1
    assert counted.dof_at(m.rank_tol) == exact.dof
    assert counted.dof_at(m.rank_tol * m.dof_gap) == counted.dof
    assert counted.dof_at(0.0) <= exact.dof
    with pytest.raises(ValueError, match="above"):
        exact.dof_at(m.rank_tol * m.dof_gap)


def _same_count_near_run(monkeypatch, settings):
    """A run on a 5 x 5 grid where every shape has one near-mechanism and one near candidate
    whose solve keeps its shape's count; each call of fix_near recorded as (shapes to skip
    before, whether it looked for candidates, shapes to skip after, next skip after)."""
    import rigidfold.generate.steps as steps

    looked: list[bool] = []
    calls: list[tuple[int, bool, int, int]] = []

    def one_candidate(counted, exact, groups, ratio, floor, most=None):
        looked.append(True)
        return [((int(counted.hinges[0]),), 0.0)]

    solve = steps._Steps.try_fix

    def same_count(self, current, shape, fix, score, **kwargs):
        rec, trial = solve(self, current, shape, fix, score, **kwargs)
        if score is None and rec.outcome is AttemptOutcome.ACCEPTED:
            rec.dof = current.mechanism.dof  # a near fix that traded one soft mode for another
        return rec, trial

    fix_near = steps._Steps.fix_near

    def recorded(self, current, shape):
        skip, n = self.near_skip, len(looked)
        done = fix_near(self, current, shape)
        calls.append((skip, len(looked) > n, self.near_skip, self.near_backoff))
        return done

    def one_near(self, rank_tol):
        return self.dof - 1

    monkeypatch.setattr(steps, "near_candidates", one_candidate)
    monkeypatch.setattr(steps._Steps, "try_fix", same_count)
    monkeypatch.setattr(steps._Steps, "fix_near", recorded)
    monkeypatch.setattr(steps.Mechanism, "dof_at", one_near)
    case = case_from_specs("dome", "grid:5x5", size="2x2", settings=settings)
    options = GenerateOptions(deform=False, lookahead=True, time_limit=120, batch="off")
    return generate(case, options), calls


def test_a_near_fix_that_keeps_the_count_is_not_kept_and_the_next_shapes_skip(monkeypatch):
    """With ``near_gain`` a near fix must take a DOF away: one that keeps its shape's count
    is ``no_gain``, and after a shape whose near fixes all gained nothing the next 1, 2, 4,
    ... shapes (that would look) go without looking."""
    run, calls = _same_count_near_run(monkeypatch, DEFAULTS.with_(near_gain=True))
    near = [a for a in run.attempts if a.near is not None]
    assert near and all(a.outcome is AttemptOutcome.NO_GAIN for a in near)
    assert not any(a.near is not None for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED)
    looked = [c for c in calls if c[1]]
    assert len(looked) >= 2 and any(c[0] > 0 for c in calls)
    for skip, look, skip_after, backoff in calls:
        if skip > 0:  # skipped: no candidates looked for, one shape fewer to skip
            assert not look and skip_after == skip - 1
        elif look:  # looked, gained nothing: the next skip doubles
            assert skip_after == backoff
    assert [c[3] for c in looked] == [2**k for k in range(len(looked))]


def test_without_near_gain_a_near_fix_of_the_same_count_is_kept(monkeypatch):
    """Without ``near_gain`` (the default): a near fix is refused only when its count rose;
    one that keeps the count is a solution, and no shape skips the near-mechanisms."""
    assert DEFAULTS.generation.near_gain is False
    run, calls = _same_count_near_run(monkeypatch, DEFAULTS)
    assert any(a.near is not None and a.outcome is AttemptOutcome.ACCEPTED for a in run.attempts)
    assert not any(a.outcome is AttemptOutcome.NO_GAIN for a in run.attempts)
    assert all(c[0] == 0 and c[2] == 0 for c in calls)


def test_near_gain_is_a_boolean():
    with pytest.raises(RigidfoldError, match="near_gain"):
        DEFAULTS.with_(near_gain="yes")
