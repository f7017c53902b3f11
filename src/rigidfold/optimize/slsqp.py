"""SciPy SLSQP on problem (6): the paper's solver.

``exact=True`` passes CasADi's exact gradient and constraint Jacobian (rigidfold's
paper-faithful reference); ``exact=False`` lets SciPy difference them numerically, as the
paper did (its baseline: 72 s per solve for 115 variables).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

# SciPy's SLSQP exit modes (scipy/optimize/_slsqp_py.py)
_OUTCOME = {0: "solved", 9: "iteration_limit", 3: "infeasible", 4: "infeasible"}


def run_slsqp(
    problem, xi0: np.ndarray, w: np.ndarray, *, exact: bool = True
) -> tuple[np.ndarray, int, str, str]:
    """Solve from ``xi0`` with fixed-crease weights ``w``.

    returns : (xi (n,), iterations, outcome, SciPy's message)
    """
    s = problem.settings
    lo_rows = np.flatnonzero(np.isfinite(problem.lbg))
    hi_rows = np.flatnonzero(np.isfinite(problem.ubg))
    lo, hi = problem.lbg[lo_rows], problem.ubg[hi_rows]

    def objective(xi):
        return float(problem.objective(xi, w)[0])

    def objective_and_gradient(xi):
        f, grad = problem.objective_gradient(xi, w)
        return float(f), np.asarray(grad, dtype=float).ravel()

    def inequalities(xi):  # >= 0
        g = np.asarray(problem.constraints(xi, w), dtype=float).ravel()
        return np.concatenate([g[lo_rows] - lo, hi - g[hi_rows]])

    def inequality_jacobian(xi):
        jac = problem.constraint_jacobian(xi, w)[1].full()
        return np.vstack([jac[lo_rows], -jac[hi_rows]])

    constraint = {"type": "ineq", "fun": inequalities}
    options = {"maxiter": s.slsqp_max_iter, "ftol": s.slsqp_ftol}
    if exact:
        constraint["jac"] = inequality_jacobian
        res = minimize(
            objective_and_gradient,
            xi0,
            jac=True,
            method="SLSQP",
            constraints=[constraint],
            options=options,
        )
    else:
        res = minimize(objective, xi0, method="SLSQP", constraints=[constraint], options=options)
    outcome = _OUTCOME.get(int(res.status), "failed")
    return np.asarray(res.x, dtype=float), int(res.nit), outcome, f"SLSQP: {res.message}"
