"""A child's solve in a design search ends at ``Settings.generation.child_max_iter``, or where
its best F stalls for ``child_stall`` iterations above F_tol (the first solve and the paper's
Step 5 keep the solver's limit of the settings and never stall)."""

from __future__ import annotations

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import FormFindingProblem, SolverName, Status
from rigidfold.optimize.solver import stalled


@pytest.fixture
def limits(monkeypatch):
    """The (``max_iter``, ``stall``) of every solve of (6), in order."""
    seen: list[tuple[int | None, int | None]] = []
    solve = FormFindingProblem.solve

    def recording(self, *args, max_iter=None, stall=None, **kwargs):
        seen.append((max_iter, stall))
        return solve(self, *args, max_iter=max_iter, stall=stall, **kwargs)

    monkeypatch.setattr(FormFindingProblem, "solve", recording)
    return seen


@pytest.mark.parametrize("deploy_check", [True, False])
def test_children_are_solved_to_their_own_limit(limits, deploy_check):
    settings = DEFAULTS.with_(child_max_iter=77, child_stall=66)
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    run = generate(case, GenerateOptions(criterion="shat", seed=1, deploy_check=deploy_check))
    assert run.solutions and len(limits) >= 3
    assert limits[0] == (None, None)  # the first solve, from the target surface
    assert set(limits[1:]) == ({(77, 66)} if deploy_check else {(None, None)})


def test_a_child_at_its_limit_is_not_a_solution():
    """Children of IPOPT alone (``projection`` "large" on a small pattern) allowed two
    iterations: those it does not solve in two end at the limit, as attempts that fail
    (N_exceed), never as solutions."""
    settings = DEFAULTS.with_(child_max_iter=2)
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    run = generate(case, GenerateOptions(criterion="shat", seed=1, projection="large"))
    children = run.attempts[1:]
    limited = [a for a in children if a.status is Status.ITERATION_LIMIT]
    assert limited and all(a.iterations == 2 for a in limited)
    assert all(a.outcome is AttemptOutcome.EXCEED for a in limited)
    assert run.n_exceed >= len(limited)
    assert all(a.iterations <= 2 for a in children)


def test_the_stall_rule():
    """Stalled: the best F, above F_tol, has not halved in the window's iterations."""
    f_tol = 1e-7
    plateau = [1e-3, 2e-4, 1.3e-6, 1.3e-6, 1.3e-6, 1.29e-6]
    assert not stalled(plateau[:3], 2, f_tol)  # halved within the last two
    assert not stalled(plateau[:4], 2, f_tol)
    assert stalled(plateau[:5], 2, f_tol)
    assert not stalled(plateau, None, f_tol)  # no window: never
    assert not stalled(plateau, 10, f_tol)  # fewer iterations than the window
    halving = [2.0**-k for k in range(40)]  # a steady descent is never stalled
    assert not any(stalled(halving[:n], 1, 0.0) for n in range(1, 41))
    assert not stalled([1e-7, 1e-7, 1e-7], 1, f_tol)  # at F_tol: not above it
    inf = float("inf")  # no feasible iterate yet: the window has not begun
    assert not stalled([inf, inf, inf], 2, f_tol)
    assert not stalled([inf, 1e-3, 1e-3], 2, f_tol)
    assert stalled([inf, 1e-3, 1e-3, 1e-3], 2, f_tol)


@pytest.fixture(scope="module")
def pattern_1():
    """Pattern 1 on Bezier seed 1, its problem and its first solution."""
    case = case_from_specs("bezier", "1", seed=1, settings=DEFAULTS)
    problem = case.problem()
    first = problem.solve()
    assert first.status is Status.CONVERGED
    return case, problem, first


@pytest.mark.parametrize("solver", [SolverName.IPOPT, SolverName.SLSQP])
def test_a_solve_whose_f_stalls_ends_stalled(pattern_1, solver):
    """Every interior crease fixed: no shape within dz has them all flat, F stays far above
    F_tol; with a window of three iterations both solvers end the run there, as STALLED
    (before their own ends), and without one they run to their own verdict."""
    case, problem, first = pattern_1
    fixed = case.pattern.interior_edges
    free = problem.solve(fixed=fixed, start=first.coords, solver=solver)
    short = problem.solve(fixed=fixed, start=first.coords, solver=solver, stall=3)
    assert free.status is not Status.STALLED and free.F > DEFAULTS.design.f_tol
    assert short.status is Status.STALLED and short.F > DEFAULTS.design.f_tol
    assert short.iterations < free.iterations
    assert "stalled" in short.message


def test_the_default_window_leaves_converging_solves_alone(pattern_1):
    """Half the interior creases fixed: the child converges (in more than 100 iterations)
    the same with the default window as without one."""
    case, problem, first = pattern_1
    fixed = case.pattern.interior_edges[: len(case.pattern.interior_edges) // 2]
    free = problem.solve(fixed=fixed, start=first.coords)
    windowed = problem.solve(fixed=fixed, start=first.coords, stall=DEFAULTS.generation.child_stall)
    assert free.status is Status.CONVERGED and windowed.status is Status.CONVERGED
    assert windowed.iterations == free.iterations
