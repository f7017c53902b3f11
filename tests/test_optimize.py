"""Problem (6): variable elimination, exact derivatives, solver behaviour."""

from __future__ import annotations

import numpy as np
import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import FormFindingProblem, SolverName, Status, build_linear_map
from rigidfold.surfaces import Bezier, Dome


@pytest.fixture(scope="module")
def bezier_problem() -> FormFindingProblem:
    case = case_from_specs("bezier", "1", seed=3)
    return case.problem(build_ipopt=False)


# ---------------------------------------------------------------- Table 4, (7)-(11)
@pytest.mark.parametrize(
    ("surface", "pattern", "symmetric", "n"),
    [
        ("bezier", "1", False, 115),
        ("bezier", "2", False, 124),
        ("dome", "11", False, 315),
        ("dome", "11", True, 83),
        ("hp", "11", False, 315),
        ("hp", "11", True, 83),
    ],
)
def test_independent_variables_table4(surface, pattern, symmetric, n):
    case = case_from_specs(surface, pattern, seed=0, symmetric=symmetric)
    lmap = build_linear_map(case.pattern, case.planes)
    assert lmap.n_variables == n


@pytest.mark.parametrize("surface", ["dome", "hp"])
def test_linear_map_satisfies_constraints(surface):
    case = case_from_specs(surface, "11", symmetric=True)
    lmap = build_linear_map(case.pattern, case.planes)
    rng = np.random.default_rng(0)
    xi = lmap.restrict(case.pattern.coords) + 0.05 * rng.standard_normal(lmap.n_variables)
    coords = lmap.expand(xi)
    assert lmap.residual(coords) < 1e-12
    assert np.allclose(lmap.restrict(coords), xi)
    # corners never move, and mirror images stay mirror images
    assert np.allclose(coords[case.pattern.corners], case.pattern.coords[case.pattern.corners])
    for plane in case.planes:
        image = plane.reflect(coords[:, :2])
        dist = np.min(np.linalg.norm(image[:, None] - coords[None, :, :2], axis=2), axis=1)
        assert dist.max() < 1e-12


def test_linear_map_is_sparse_and_built_block_by_block(monkeypatch):
    """(7)-(9) are eliminated one small block (a vertex and its mirror images) at a time: T is
    a sparse matrix with a few entries per coordinate, and no dense matrix of the pattern's
    size is factorised."""
    import scipy.linalg
    import scipy.sparse as sp

    shapes = []
    qr = scipy.linalg.qr

    def recording_qr(matrix, *args, **kwargs):
        shapes.append(matrix.shape)
        return qr(matrix, *args, **kwargs)

    monkeypatch.setattr(scipy.linalg, "qr", recording_qr)
    for surface in ("dome", "hp"):
        case = case_from_specs(surface, "grid:21x21", size="3x3", symmetric=True)
        lmap = build_linear_map(case.pattern, case.planes)
        assert sp.issparse(lmap.T) and lmap.T.shape == (3 * 441, lmap.n_variables)
        assert lmap.T.nnz <= 3 * lmap.T.shape[0]
        assert max(max(shape) for shape in shapes) <= 24  # 4 mirror images x 3 coordinates x 2
        shapes.clear()
        rng = np.random.default_rng(0)
        coords = lmap.expand(lmap.restrict(case.pattern.coords) + rng.standard_normal(318))
        assert lmap.residual(coords) < 1e-12


def test_derivatives_handed_to_ipopt_have_o_of_e_nonzeros():
    """The constraint Jacobian and the Hessian of the Lagrangian IPOPT gets keep their true
    sparsity: a bounded number of nonzeros per row, so nnz grows like the number of edges."""
    per_edge = []
    for n in (7, 11, 21):
        case = case_from_specs("dome", f"grid:{n}x{n}", size="3x3")
        nlpsol = case.problem().solver(SolverName.IPOPT).nlpsol
        jac = nlpsol.get_function("nlp_jac_g").sparsity_out(1)
        hess = nlpsol.get_function("nlp_hess_l").sparsity_out(0)  # upper triangle
        assert max(np.diff(jac.T.colind())) <= 9  # an angle: three vertices
        assert max(np.diff((hess + hess.T).colind())) <= 100  # two rings of vertices
        per_edge.append((jac.nnz() / case.pattern.n_edges, hess.nnz() / case.pattern.n_edges))
    (j7, h7), (j11, h11), (j21, h21) = per_edge
    assert j21 < 1.1 * j11 and h21 < 1.2 * h11  # the boundary's share shrinks
    assert j21 < 1.3 * j7 and h21 < 1.5 * h7


def test_boundary_vertices_stay_on_their_sides(bezier_problem):
    lmap, shape = bezier_problem.map, bezier_problem.pattern
    rng = np.random.default_rng(1)
    coords = lmap.expand(lmap.restrict(shape.coords) + 0.1 * rng.standard_normal(lmap.n_variables))
    for side in shape.boundary_sides:
        b1, b2, b3 = side.line
        assert np.allclose(b1 * coords[side.inner, 0] + b2 * coords[side.inner, 1] + b3, 0)


def test_asymmetric_surface_breaks_symmetry_constraints():
    """Mirror planes that the corner heights contradict are reported, not silently used."""
    bez = Bezier(2)
    dome = Dome()
    case = case_from_specs(bez, "11")
    with pytest.raises(ValueError, match="contradict"):
        build_linear_map(case.pattern, dome.mirror_planes)


# ---------------------------------------------------------------- exact derivatives
def _random_point(problem, seed):
    rng = np.random.default_rng(seed)
    xi = problem.start_point() + 0.03 * rng.standard_normal(problem.n_variables)
    w = np.zeros(problem.pattern.n_edges)
    w[rng.choice(problem.pattern.interior_edges, 12, replace=False)] = 1.0
    return xi, w


def _central_diff(fun, x, h=1e-6):
    cols = []
    for i in range(len(x)):
        e = np.zeros_like(x)
        e[i] = h
        cols.append((np.asarray(fun(x + e)) - np.asarray(fun(x - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def _rel(a, b):
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


@pytest.mark.parametrize("part", ["F1", "F2"])
@pytest.mark.parametrize("seed", [0, 1])
def test_objective_derivatives_match_finite_differences(bezier_problem, part, seed):
    fun = bezier_problem.derivative_functions()[part]
    xi, w = _random_point(bezier_problem, seed)
    value, grad, hess = (np.asarray(v) for v in fun(xi, w))
    fd_grad = _central_diff(lambda x: np.asarray(fun(x, w)[0]).item(), xi)
    fd_hess = _central_diff(lambda x: np.asarray(fun(x, w)[1]).ravel(), xi)
    assert value.item() > 0
    assert _rel(grad.ravel(), fd_grad) < 1e-6
    assert _rel(hess, fd_hess) < 1e-6


def test_angle_derivatives_match_finite_differences(bezier_problem):
    fun = bezier_problem.derivative_functions()["theta"]
    xi, _ = _random_point(bezier_problem, 5)
    lam = np.random.default_rng(6).standard_normal(3 * bezier_problem.pattern.n_faces)
    theta, jac, hess = (np.asarray(ca_value) for ca_value in fun(xi, lam))
    fd_jac = _central_diff(lambda x: np.asarray(fun(x, lam)[0]).ravel(), xi)
    fd_hess = _central_diff(lambda x: lam @ np.asarray(fun(x, lam)[1]), xi)
    assert _rel(jac, fd_jac) < 1e-6
    assert _rel(hess, fd_hess) < 1e-6
    # the symbolic angles are the mesh's own angles
    shape = bezier_problem.pattern.with_coords(bezier_problem.map.expand(xi))
    assert np.allclose(theta.ravel(), shape.corner_angles.T.ravel())


def test_objective_matches_mesh_geometry(bezier_problem):
    xi, w = _random_point(bezier_problem, 2)
    F, F1, F2 = (float(v) for v in bezier_problem.objective(xi, w))
    shape = bezier_problem.pattern.with_coords(bezier_problem.map.expand(xi)).with_fixed(w > 0)
    assert F1 == pytest.approx(np.sum(shape.angle_defects**2), rel=1e-12)
    assert F2 == pytest.approx(shape.flatness_residuals.sum(), rel=1e-12)
    assert F == pytest.approx(F1 + F2)


# ---------------------------------------------------------------- solving
def test_ipopt_solves_pattern1_and_result_is_consistent():
    case = case_from_specs("bezier", "1", seed=4)
    result = case.problem().solve()
    assert result.status is Status.CONVERGED
    assert result.F <= DEFAULTS.design.f_tol
    assert result.max_violation <= DEFAULTS.solver.constraint_tol
    shape = result.pattern
    assert np.sum(shape.angle_defects**2) == pytest.approx(result.F1, abs=1e-14)
    assert np.all(np.abs(shape.coords[:, 2] - case.surface.height(*shape.coords[:, :2].T)) <= 0.3)
    assert shape.corner_angles.min() >= DEFAULTS.design.theta_min - 1e-8


def test_fixed_creases_become_flat():
    case = case_from_specs("bezier", "1", seed=5)
    problem = case.problem()
    first = problem.solve()
    fold = np.abs(first.pattern.fold_angles)
    fold[first.pattern.is_boundary_edge] = np.inf
    flattest = np.argsort(fold)[:3]
    second = problem.solve(fixed=flattest, start=first.coords)
    assert second.converged
    assert second.pattern.n_facets == second.pattern.n_faces - 3
    assert np.all(second.pattern.flatness_residuals <= DEFAULTS.design.f_tol)


def test_fold_angle_bound():
    settings = DEFAULTS.with_(rho_max=np.radians(25.0))
    case = case_from_specs("bezier", "1", seed=6, settings=settings)
    result = case.problem().solve()
    free = result.pattern.free_creases
    assert np.degrees(np.abs(result.pattern.fold_angles[free]).max()) <= 25.0 + 1e-6


def test_pattern2_infeasible_start_is_repaired():
    case = case_from_specs("bezier", "2", seed=0)
    assert case.pattern.corner_angles.min() < DEFAULTS.design.theta_min
    result = case.problem().solve()
    assert result.converged
    assert result.pattern.corner_angles.min() >= DEFAULTS.design.theta_min - 1e-8


@pytest.mark.parametrize("solver", [SolverName.SLSQP, SolverName.SLSQP_FD])
def test_slsqp_reference_solvers_return_a_result(solver):
    """SLSQP runs on the same model and reports through the same result type."""
    case = case_from_specs("bezier", "1", seed=1, settings=DEFAULTS.with_(slsqp_max_iter=15))
    result = case.problem(build_ipopt=False).solve(solver=solver)
    assert result.solver == solver
    assert result.iterations <= 15
    assert result.status in (Status.CONVERGED, Status.ITERATION_LIMIT, Status.TOLERANCE_NOT_MET)
    assert result.F < float(
        case.problem(build_ipopt=False).objective(
            case.problem(build_ipopt=False).start_point(), np.zeros(case.pattern.n_edges)
        )[0]
    )


def test_iteration_limit_is_a_status_not_silence():
    case = case_from_specs("dome", "11", settings=DEFAULTS.with_(ipopt_max_iter=3))
    result = case.problem().solve()
    assert result.status is Status.ITERATION_LIMIT
    assert "Maximum_Iterations_Exceeded" in result.message


def test_a_solve_own_iteration_limit_is_ipopts():
    """A solve's own limit (a generation run's children, ``child_max_iter``) ends IPOPT where
    the settings' limit would: the same iterate, the same status."""
    problem = case_from_specs("dome", "11").problem()
    own = problem.solve(max_iter=3)
    limited = case_from_specs("dome", "11", settings=DEFAULTS.with_(ipopt_max_iter=3))
    settings = limited.problem().solve()
    assert own.status is Status.ITERATION_LIMIT and own.iterations == 3
    assert own.message == settings.message
    np.testing.assert_array_equal(own.pattern.coords, settings.pattern.coords)
    free = problem.solve()  # the same solver's next solve has no limit of its own
    assert free.converged and free.iterations > 3


def test_impossible_bounds_are_not_converged():
    """A tight dz bound on a strongly curved dome cannot be met with F <= F_tol."""
    case = case_from_specs("dome", "11", settings=DEFAULTS.with_(dz=1e-4))
    result = case.problem().solve()
    assert result.status in (Status.TOLERANCE_NOT_MET, Status.INFEASIBLE, Status.ITERATION_LIMIT)
    assert not result.converged


def test_bad_fixed_selection(bezier_problem):
    with pytest.raises(ValueError, match="out of range"):
        bezier_problem.fixed_mask([10_000])
    with pytest.raises(ValueError, match="boundary"):
        bezier_problem.fixed_mask([int(bezier_problem.pattern.boundary_edges[0])])
    with pytest.raises(ValueError, match="unknown solver"):
        bezier_problem.solve(solver="newton")


# ---------------------------------------------------------------- closed-form Hessian
@pytest.mark.parametrize(
    ("surface", "pattern", "symmetric", "rho_max"),
    [
        ("bezier", "1", False, None),
        ("bezier", "2", False, None),
        ("bezier", "1p", False, 1.0),
        ("dome", "11", True, None),
        ("hp", "11", True, 0.5),
    ],
)
def test_closed_form_hessian_equals_casadi(surface, pattern, symmetric, rho_max):
    """The element-assembled Hessian of the Lagrangian is CasADi's exact one, to round-off."""
    settings = DEFAULTS.with_(rho_max=rho_max)
    case = case_from_specs(surface, pattern, seed=7, symmetric=symmetric, settings=settings)
    _assert_closed_form_hessian_is_exact(case.problem(build_ipopt=False))


def test_closed_form_hessian_without_interior_vertices():
    """A strip of four triangles: no angle defect, so no Gauss-Newton part."""
    from rigidfold.mesh import CreasePattern
    from rigidfold.surfaces import HyperbolicParaboloid

    surface = HyperbolicParaboloid()
    xy = np.array([[0, 0], [1.5, 0], [3, 0], [0, 3], [1.5, 3], [3, 3]], dtype=float)
    coords = np.column_stack([xy, surface.height(xy[:, 0], xy[:, 1])])
    strip = CreasePattern.from_faces(coords, np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]))
    problem = FormFindingProblem(strip, surface, build_ipopt=False)
    assert len(strip.interior_vertices) == 0 and problem.n_variables == 4
    _assert_closed_form_hessian_is_exact(problem)
    assert FormFindingProblem(strip, surface).solve().converged


def _assert_closed_form_hessian_is_exact(problem) -> None:
    import casadi as ca

    from rigidfold.optimize.hessian import ClosedFormHessian

    nlp = problem.nlp
    xi, w = nlp.x, nlp.p
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", nlp.g.shape[0])
    lagrangian = lam_f * nlp.f + ca.dot(lam_g, nlp.g)
    reference = ca.Function("H", [xi, w, lam_f, lam_g], [ca.triu(ca.hessian(lagrangian, xi)[0])])
    hessian = ClosedFormHessian(problem)
    rng = np.random.default_rng(0)
    for trial in range(2):
        x0 = problem.start_point() + 0.01 * rng.standard_normal(problem.n_variables)
        weights = (rng.random(problem.pattern.n_edges) < 0.3).astype(float)
        lam = rng.standard_normal(nlp.g.shape[0])
        ref = reference(x0, weights, 1.0 + trial, lam)
        mine = ca.DM(hessian.sparsity, hessian.values(x0, weights, 1.0 + trial, lam))
        assert hessian.sparsity.nnz() == ref.nnz()
        scale = float(ca.norm_inf(ref))
        assert float(ca.norm_inf(ca.densify(ref) - ca.densify(mine))) <= 1e-12 * scale


def test_element_derivatives_match_finite_differences():
    from rigidfold.optimize.hessian import angle_derivatives, normal_cosine_derivatives

    rng = np.random.default_rng(3)
    uv = rng.standard_normal((4, 6))
    theta, grad, hess = angle_derivatives(uv[:, :3], uv[:, 3:])
    cos = np.einsum("ki,ki->k", uv[:, :3], uv[:, 3:]) / (
        np.linalg.norm(uv[:, :3], axis=1) * np.linalg.norm(uv[:, 3:], axis=1)
    )
    assert np.allclose(theta, np.arccos(cos))
    h = 1e-6
    for j in range(6):
        step = np.zeros(6)
        step[j] = h
        tp, gp, _ = angle_derivatives((uv + step)[:, :3], (uv + step)[:, 3:])
        tm, gm, _ = angle_derivatives((uv - step)[:, :3], (uv - step)[:, 3:])
        assert np.allclose(grad[:, j], (tp - tm) / (2 * h), atol=1e-8)
        assert np.allclose(hess[:, :, j], (gp - gm) / (2 * h), atol=1e-6)
    pts = rng.standard_normal((3, 18))
    _, grad, hess = normal_cosine_derivatives(
        pts[:, :9].reshape(3, 3, 3), pts[:, 9:].reshape(3, 3, 3)
    )
    for j in range(18):
        step = np.zeros(18)
        step[j] = h
        cp, gp, _ = normal_cosine_derivatives(
            (pts + step)[:, :9].reshape(3, 3, 3), (pts + step)[:, 9:].reshape(3, 3, 3)
        )
        cm, gm, _ = normal_cosine_derivatives(
            (pts - step)[:, :9].reshape(3, 3, 3), (pts - step)[:, 9:].reshape(3, 3, 3)
        )
        assert np.allclose(grad[:, j], (cp - cm) / (2 * h), atol=1e-7)
        assert np.allclose(hess[:, :, j], (gp - gm) / (2 * h), atol=1e-5)


def test_both_hessians_reach_the_same_solution():
    results = {}
    for hessian in ("closed-form", "casadi"):
        case = case_from_specs(
            "bezier", "1", seed=3, settings=DEFAULTS.with_(ipopt_hessian=hessian)
        )
        results[hessian] = case.problem().solve()
    a, b = results["closed-form"], results["casadi"]
    assert a.converged and b.converged
    assert a.iterations == b.iterations
    assert np.abs(a.coords - b.coords).max() < 1e-8


def test_unknown_hessian_is_refused():
    with pytest.raises(ValueError, match="ipopt_hessian must be"):
        DEFAULTS.with_(ipopt_hessian="bfgs")


@pytest.mark.parametrize("fold_deg, folded", [(20.0, False), (100.0, True), (179.0, True)])
def test_a_fixed_crease_folded_past_90_degrees_is_folded_back_not_a_flat_panel(fold_deg, folded):
    """The flatness term |n_a x n_b|^2 = sin^2(rho) vanishes at 180 degrees too: a solve that
    meets F_tol with a fixed crease folded onto its facets is not accepted."""
    from rigidfold.mesh import CreasePattern
    from rigidfold.optimize.problem import classify, folded_back
    from rigidfold.optimize.solver import SolverOutcome

    phi = np.radians(fold_deg)  # wing b turned about the crease (x axis) from the plane
    coords = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -np.cos(phi), np.sin(phi)]])
    pattern = CreasePattern.from_faces(coords, [[0, 1, 2], [1, 0, 3]])
    crease = int(np.flatnonzero(~pattern.is_boundary_edge)[0])
    assert np.isclose(np.degrees(abs(pattern.fold_angles[crease])), fold_deg)
    fixed = np.zeros(pattern.n_edges, bool)
    fixed[crease] = True
    found = folded_back(pattern.with_fixed(fixed))
    assert found.tolist() == ([crease] if folded else [])
    status, message = classify(SolverOutcome.SOLVED, 1e-12, 0.0, DEFAULTS, found)
    assert status is (Status.FOLDED_BACK if folded else Status.CONVERGED)
    if folded:
        assert f"fixed crease {crease} folded back" in message
