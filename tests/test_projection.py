"""The projection onto F = 0 and the large-pattern path of the IPOPT solver (issue 19).

Unit tests over reference patterns (the residuals are F, their Jacobian its derivative),
invariants (every projected iterate is feasible; the fold-angle gradient equals the mechanism
analysis's), and the solver's path: paper-size patterns run IPOPT alone, large ones project,
and every size projects first in a run with the deployability check.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import paper_generate as generate
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import GenerateOptions
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.kinematics import fold_angles_and_gradients
from rigidfold.optimize import Status, projection
from rigidfold.optimize.hessian import angle_derivatives
from rigidfold.optimize.projection import Projection
from rigidfold.optimize.residuals import Residuals, angle_gradients, fold_angle_gradients
from rigidfold.study.runner import STUDY_OPTIONS

CASES = [
    ("bezier", "1", {"seed": 3}),
    ("bezier", "2", {"seed": 5}),
    ("hp", "11", {"symmetric": True}),
    ("dome", "grid:7x7", {"size": "3x3"}),
    ("dome", "mesh:0,0;3,0;3,2;1.5,2.6;0,2", {"edge_length": 0.5}),
]


def _perturbed(problem, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return problem.start_point() + 0.02 * rng.standard_normal(problem.n_variables)


@pytest.mark.parametrize(("surface", "pattern", "kw"), CASES)
def test_residuals_square_to_the_objective_and_differentiate_to_its_jacobian(surface, pattern, kw):
    problem = case_from_specs(surface, pattern, **kw).problem(build_ipopt=False)
    rng = np.random.default_rng(1)
    xi = _perturbed(problem, 2)
    w = (rng.random(problem.pattern.n_edges) < 0.3).astype(float)
    res = Residuals(problem.pattern, problem.map)
    r, J = res(xi, w)
    F, F1, _ = (float(v) for v in problem.objective(xi, w))
    assert r @ r == pytest.approx(F, rel=1e-12)
    assert r[: res.n_inner] @ r[: res.n_inner] == pytest.approx(F1, rel=1e-12)
    assert J.shape == (len(r), problem.n_variables)
    d = rng.standard_normal(problem.n_variables)
    h = 1e-6
    fd = (res(xi + h * d, w, False)[0] - res(xi - h * d, w, False)[0]) / (2 * h)
    assert np.abs(J @ d - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max())


def test_element_gradients_equal_the_hessian_module_and_the_mechanism_analysis():
    rng = np.random.default_rng(4)
    corners = rng.standard_normal((50, 3, 3))
    theta, grad = angle_gradients(corners)
    u, v = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    theta_ref, g6, _ = angle_derivatives(u, v)
    np.testing.assert_allclose(theta, theta_ref, rtol=1e-12)
    np.testing.assert_allclose(grad[:, 3:], g6, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(grad[:, :3], -g6[:, :3] - g6[:, 3:], rtol=1e-10, atol=1e-12)
    coords = rng.standard_normal((40, 3))
    stencils = np.array([rng.choice(40, 4, replace=False) for _ in range(30)])
    rho, g = fold_angle_gradients(coords[stencils])
    rho_ref, g_ref, _ = fold_angles_and_gradients(coords, stencils)
    np.testing.assert_allclose(rho, rho_ref, atol=1e-13)
    np.testing.assert_allclose(g, g_ref, rtol=1e-9, atol=1e-10)


@pytest.fixture(scope="module")
def solved_grid():
    """A 21 x 21 grid on the dome (441 vertices, the large-pattern path) and its solution."""
    case = case_from_specs("dome", "grid:21x21", size="3x3")
    problem = case.problem()
    return case, problem, problem.solve()


def test_large_pattern_ipopt_hands_over_to_the_projection(solved_grid):
    case, _, result = solved_grid
    assert case.pattern.n_vertices >= DEFAULTS.solver.projection_vertices
    assert result.status is Status.CONVERGED
    assert result.F <= DEFAULTS.solver.projection_tol
    assert result.max_violation == 0.0
    # the lifted dome breaks the sector-angle bounds: IPOPT first, stopped early, then polished
    assert "the start violates a constraint" in result.message
    assert "User_Requested_Stop" in result.message
    assert "projection: converged, F = " in result.message


def test_paper_size_patterns_run_ipopt_alone():
    result = case_from_specs("dome", "grid:11x11", size="3x3").problem().solve()
    assert result.status is Status.CONVERGED
    assert result.message.startswith("IPOPT: Solve_Succeeded")
    assert "projection" not in result.message


def test_a_larger_threshold_keeps_ipopt_alone_on_a_large_pattern():
    settings = DEFAULTS.with_(projection_vertices=10**6)
    case = case_from_specs("dome", "grid:15x15", size="3x3", settings=settings)
    result = case.problem().solve()
    assert result.status is Status.CONVERGED
    assert "projection" not in result.message


def test_fixing_one_more_crease_is_a_short_projection(solved_grid):
    _, problem, result = solved_grid
    rho = np.abs(result.pattern.fold_angles)
    folded = np.flatnonzero(~result.pattern.is_boundary_edge & (rho > 1e-3))
    crease = folded[np.argmin(rho[folded])]  # as the criteria tend to: a crease folded little
    fixed = result.pattern.fixed.copy()
    fixed[crease] = True
    again = problem.solve(fixed=fixed, start=result.coords)
    assert again.status is Status.CONVERGED
    assert again.message.startswith("projection: converged, F = ")
    assert abs(again.pattern.fold_angles[crease]) < 1e-7
    assert again.max_violation == 0.0
    assert again.iterations < DEFAULTS.solver.projection_max_iter


def test_a_run_with_the_deployability_check_projects_first_at_every_size():
    """``GenerateOptions.projection``: with the deployability check (the design tool's
    search) every solve begins with the projection, on a paper-size pattern too; the paper's
    Step 5 and the study keep IPOPT alone there (Tables 5-8)."""
    assert GenerateOptions().project_first
    assert not GenerateOptions(deploy_check=False).project_first
    assert GenerateOptions(deploy_check=False, projection="always").project_first
    assert not GenerateOptions(projection="large").project_first
    assert not STUDY_OPTIONS.project_first
    case = case_from_specs("dome", "grid:11x11", size="3x3")
    assert case.pattern.n_vertices < DEFAULTS.solver.projection_vertices
    first = case.problem().solve()
    assert first.status is Status.CONVERGED
    rho = np.abs(first.pattern.fold_angles)
    folded = np.flatnonzero(~first.pattern.is_boundary_edge & (rho > 1e-3))
    fixed = first.pattern.fixed.copy()
    fixed[folded[np.argmin(rho[folded])]] = True
    projected = case.problem(project_first=True).solve(fixed=fixed, start=first.coords)
    alone = case.problem().solve(fixed=fixed, start=first.coords)
    assert projected.status is Status.CONVERGED and alone.status is Status.CONVERGED
    assert projected.message.startswith("projection: converged, F = ")
    assert projected.max_violation == 0.0
    assert alone.message.startswith("IPOPT: ")
    assert "projection" not in alone.message


def test_an_unknown_projection_is_refused_by_name():
    with pytest.raises(RigidfoldError, match="unknown projection 'nearest'"):
        GenerateOptions(projection="nearest")


@pytest.fixture(scope="module")
def tight_grid(solved_grid):
    """The 21 x 21 problem with the dz bound pulled in to its solution's own largest |dz|."""
    case, _, result = solved_grid
    coords = result.coords
    dz = np.abs(coords[:, 2] - case.surface.height(coords[:, 0], coords[:, 1])).max()
    return case_from_specs(
        "dome", "grid:21x21", size="3x3", settings=DEFAULTS.with_(dz=float(dz) + 1e-9)
    ).problem(build_ipopt=False)


def test_every_projected_iterate_stays_feasible(solved_grid, tight_grid):
    """With the dz bound pulled in to the solution's own largest |dz|, the projection may not
    step outside it: it ends at a feasible point, converged or not."""
    case, _, result = solved_grid
    coords, tight = result.coords, tight_grid
    projection = Projection(tight)
    w = np.zeros(case.pattern.n_edges)
    interior = np.flatnonzero(~result.pattern.is_boundary_edge)
    w[interior[np.argsort(-np.abs(result.pattern.fold_angles[interior]))[:3]]] = 1.0
    out = projection(tight.start_point(coords), w)
    assert tight.violation(tight.map.expand(out.xi), w > 0) <= 0.1 * DEFAULTS.solver.constraint_tol
    assert out.iterations >= 1


def test_a_step_blocked_by_a_bound_slides_along_it(solved_grid, tight_grid):
    """With the dz bound pulled in to the solution's own largest |dz|, fixing the three creases
    folded least needs a step that would push a vertex past the bound: the projection holds
    that constraint (its row joins J) and still converges, instead of refusing every step."""
    case, _, result = solved_grid
    coords, tight = result.coords, tight_grid
    rho = np.abs(result.pattern.fold_angles)
    folded = np.flatnonzero(~result.pattern.is_boundary_edge & (rho > 1e-3))
    w = np.zeros(case.pattern.n_edges)
    w[folded[np.argsort(rho[folded])[:3]]] = 1.0
    out = Projection(tight)(tight.start_point(coords), w)
    assert out.converged and out.feasible
    assert out.held >= 1
    assert "constraint held" in out.reason
    assert tight.violation(tight.map.expand(out.xi), w > 0) <= 0.1 * DEFAULTS.solver.constraint_tol
    F, _, _ = (float(v) for v in tight.objective(out.xi, w))
    assert F <= DEFAULTS.solver.projection_tol


def test_a_projection_stopped_near_a_zero_is_taken_without_ipopt(solved_grid):
    """A feasible projection that stops at F <= ipopt_stop_f is the answer: IPOPT would stop
    at once. Here projection_tol is out of reach, so every step stops at its iteration limit."""
    _, _, result = solved_grid
    settings = DEFAULTS.with_(projection_tol=1e-300, projection_max_iter=8, ipopt_stop_f=1e-6)
    problem = case_from_specs("dome", "grid:21x21", size="3x3", settings=settings).problem()
    rho = np.abs(result.pattern.fold_angles)
    folded = np.flatnonzero(~result.pattern.is_boundary_edge & (rho > 1e-3))
    fixed = result.pattern.fixed.copy()
    fixed[folded[np.argmin(rho[folded])]] = True
    again = problem.solve(fixed=fixed, start=result.coords)
    assert again.message.startswith("projection: stopped at F = ")
    assert "IPOPT" not in again.message
    assert again.status is Status.CONVERGED
    assert again.F <= 1e-6 and again.max_violation == 0.0


def test_a_creeping_polish_stops_when_its_steps_stall(solved_grid, monkeypatch):
    """Steps cut to 2 % of the Gauss-Newton step lower F by about 4 % each: with ``stall``
    5 the projection stops once five accepted steps have not halved F ("stalled"), where
    without it it runs all ``projection_max_iter`` factorisations; full steps from the same
    start converge and never stall."""
    _, problem, result = solved_grid
    rho = np.abs(result.pattern.fold_angles)
    folded = np.flatnonzero(~result.pattern.is_boundary_edge & (rho > 1e-3))
    w = result.pattern.fixed.astype(float)
    w[folded[np.argmin(rho[folded])]] = 1.0
    start = problem.start_point(result.coords)
    tol = DEFAULTS.solver.polish_tol
    stall = DEFAULTS.solver.polish_stall_steps
    assert stall >= 1
    full = Projection(problem)(start, w, tol=tol, stall=stall)
    assert full.converged and "stalled" not in full.reason

    real = projection._solve
    monkeypatch.setattr(projection, "_solve", lambda JJ, mu, r: 0.02 * real(JJ, mu, r))
    creeping = Projection(problem)(start, w, tol=tol, stall=stall)
    assert creeping.reason.startswith("stalled at F = ")
    assert stall <= creeping.iterations < DEFAULTS.solver.projection_max_iter
    assert not creeping.converged and creeping.feasible
    F0, _, _ = (float(v) for v in problem.objective(start, w))
    assert 0.5 * F0 < creeping.F < F0
    endless = Projection(problem)(start, w, tol=tol)  # stall 0: never
    assert endless.iterations == DEFAULTS.solver.projection_max_iter
    assert endless.reason.startswith("stopped at F = ") and endless.F < creeping.F


def test_an_infeasible_start_is_not_projected():
    problem = case_from_specs("dome", "grid:21x21", size="3x3").problem(build_ipopt=False)
    out = Projection(problem)(problem.start_point(), np.zeros(problem.pattern.n_edges))
    assert not out.converged and not out.feasible
    assert out.iterations == 0
    assert "violates" in out.reason


def test_a_start_with_a_collapsed_triangle_is_not_projected():
    """The composite solver polishes IPOPT's last iterate, which can have a collapsed
    triangle (Origami Simulator's 6ptHypar-anti on the dome): no shape, so not feasible, and
    the solve fails as IPOPT's own would (the start kept), not with the pattern's error."""
    problem = case_from_specs("dome", "grid:7x7", size="3x3").problem(
        build_ipopt=False, project_first=True
    )
    pattern = problem.pattern
    coords = pattern.coords.copy()
    a, b, v = next(
        (a, b, v) for a, b, v in pattern.faces.tolist() if not pattern.is_boundary_vertex[v]
    )
    coords[v] = 0.5 * (coords[a] + coords[b])  # the face (a, b, v) has no area
    xi = problem.start_point(coords)
    out = Projection(problem)(xi, np.zeros(pattern.n_edges))
    assert not out.feasible and out.iterations == 0
    assert "violates" in out.reason


def test_generate_on_a_large_grid_projects_after_the_first_solve():
    case = case_from_specs("dome", "grid:15x15", size="3x3")
    assert case.pattern.n_vertices >= DEFAULTS.solver.projection_vertices
    messages = []
    run = generate(case, criterion="s", target_dof=GenerateOptions().target_dof)
    for sol in run.solutions:
        messages.append(sol.result.message)
    assert run.final_dof is not None and run.solutions
    assert all(s.result.max_violation == 0.0 for s in run.solutions)
    projected = [m.startswith("projection: converged") for m in messages[1:]]
    assert sum(projected) >= len(projected) // 2


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("projection_vertices", 2),
        ("projection_max_iter", 0),
        ("projection_tol", 0.0),
        ("projection_damping", -1.0),
        ("projection_margin", 0.0),
        ("polish_stall_steps", -1),
        ("ipopt_stop_f", float("nan")),
    ],
)
def test_projection_settings_are_validated(name, value):
    with pytest.raises(ValueError, match=name):
        DEFAULTS.with_(**{name: value})
