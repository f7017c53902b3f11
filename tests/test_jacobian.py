"""Closed-form gradient of F and constraint Jacobian of (6) (``rigidfold.optimize.jacobian``).

Unit tests over reference patterns: both equal CasADi's symbolic derivatives, with the same
sparsity, with and without constraint (12); and the large-pattern IPOPT solver uses them
(without building CasADi's) and still solves.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import SolverName, Status
from rigidfold.optimize.jacobian import (
    ClosedFormGradient,
    ClosedFormJacobian,
    closed_form_first_derivatives,
)
from rigidfold.optimize.residuals import Residuals

WITH_RHO = DEFAULTS.with_(rho_max=math.radians(160))
CASES = [
    ("bezier", "1", {"seed": 3}),
    ("bezier", "2", {"seed": 5, "settings": WITH_RHO}),
    ("hp", "11", {"symmetric": True, "settings": WITH_RHO}),
    ("dome", "grid:7x7", {"size": "3x3"}),
    ("dome", "mesh:0,0;3,0;3,2;1.5,2.6;0,2", {"edge_length": 0.5, "settings": WITH_RHO}),
    ("expr", "2", {"expr": "0.2*sin(x)*cos(0.5*y)"}),
]


def _point(problem, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A perturbed initial shape (n,) and random fixed-crease weights (E,)."""
    rng = np.random.default_rng(seed)
    xi = problem.start_point() + 0.02 * rng.standard_normal(problem.n_variables)
    w = (rng.random(problem.pattern.n_edges) < 0.3).astype(float)
    w[problem.pattern.is_boundary_edge] = 0.0
    return xi, w


@pytest.mark.parametrize(("surface", "pattern", "kw"), CASES)
def test_closed_form_jacobian_equals_casadis(surface, pattern, kw):
    problem = case_from_specs(surface, pattern, **kw).problem(build_ipopt=False)
    xi, w = _point(problem, 1)
    jacobian = ClosedFormJacobian(problem)
    g, nonzeros = jacobian.values(xi, w)
    g_ref, dg_ref = problem.constraint_jacobian(xi, w)
    # CasADi's structure, or more: it folds constants (sin 0 = 0 on a fixed boundary line)
    ours, theirs = (ca.DM(s, 1).full() != 0 for s in (jacobian.sparsity, dg_ref.sparsity()))
    assert not (theirs & ~ours).any()
    if surface != "expr":
        assert jacobian.sparsity == dg_ref.sparsity()
    scale = max(1.0, float(np.abs(dg_ref.nonzeros()).max()))
    np.testing.assert_allclose(g, np.asarray(g_ref).ravel(), rtol=0, atol=1e-13)
    dense = ca.DM(jacobian.sparsity, nonzeros).full()
    np.testing.assert_allclose(dense, dg_ref.full(), rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize(("surface", "pattern", "kw"), CASES)
def test_closed_form_gradient_equals_casadis(surface, pattern, kw):
    problem = case_from_specs(surface, pattern, **kw).problem(build_ipopt=False)
    xi, w = _point(problem, 2)
    F, grad = ClosedFormGradient(Residuals(problem.pattern, problem.map)).values(xi, w)
    F_ref, grad_ref = problem.objective_gradient(xi, w)
    assert F[0] == pytest.approx(float(F_ref), rel=1e-12)
    scale = max(1.0, float(np.abs(np.asarray(grad_ref)).max()))
    np.testing.assert_allclose(grad, np.asarray(grad_ref).ravel(), rtol=0, atol=1e-12 * scale)


def test_callbacks_evaluate_as_casadi_functions():
    problem = case_from_specs("bezier", "1", seed=3, settings=WITH_RHO).problem(build_ipopt=False)
    xi, w = _point(problem, 3)
    grad_f, jac_g = closed_form_first_derivatives(problem)
    f, grad = grad_f(xi, w)
    g, dg = jac_g(xi, w)
    f_ref, grad_ref = problem.objective_gradient(xi, w)
    g_ref, dg_ref = problem.constraint_jacobian(xi, w)
    assert float(f) == pytest.approx(float(f_ref), rel=1e-12)
    np.testing.assert_allclose(np.asarray(grad), np.asarray(grad_ref), atol=1e-11)
    np.testing.assert_allclose(np.asarray(g), np.asarray(g_ref), atol=1e-13)
    assert isinstance(dg, ca.DM)
    assert dg.sparsity() == dg_ref.sparsity()
    np.testing.assert_allclose(dg.nonzeros(), dg_ref.nonzeros(), atol=1e-11)


def test_large_pattern_solver_uses_the_closed_form_derivatives():
    settings = DEFAULTS.with_(projection_vertices=40)  # 7 x 7 = 49 vertices takes the path
    problem = case_from_specs("dome", "grid:7x7", size="3x3", settings=settings).problem()
    nlpsol = problem.solver(SolverName.IPOPT).nlpsol
    assert "constraint_jacobian" not in problem.__dict__  # CasADi's was never built
    assert "objective_gradient" not in problem.__dict__
    assert nlpsol.get_function("nlp_jac_g").class_name() == "CallbackInternal"
    result = problem.solve()
    assert result.status is Status.CONVERGED
    reference = case_from_specs("dome", "grid:7x7", size="3x3").problem()
    assert "constraint_jacobian" in reference.__dict__  # paper sizes: CasADi's, as before
    assert reference.solve().status is Status.CONVERGED
