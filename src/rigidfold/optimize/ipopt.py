"""IPOPT (through CasADi) on problem (6), with exact gradient, Jacobian and Hessian."""

from __future__ import annotations

import casadi as ca
import numpy as np

from rigidfold.config import Settings

_OUTCOME = {
    "Solve_Succeeded": "solved",
    "Solved_To_Acceptable_Level": "solved",
    "Infeasible_Problem_Detected": "infeasible",
    "Maximum_Iterations_Exceeded": "iteration_limit",
    "Maximum_CpuTime_Exceeded": "iteration_limit",
    "Maximum_WallTime_Exceeded": "iteration_limit",
}


def ipopt_options(settings: Settings, tol: float | None = None) -> dict:
    """CasADi ``nlpsol`` options for IPOPT from the settings (silent, exact Hessian).

    Bounds are relaxed and constraints accepted only far inside ``constraint_tol``, so a
    converged point meets every constraint to that tolerance.
    """
    return {
        "print_time": False,
        "error_on_fail": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.tol": settings.ipopt_tol if tol is None else tol,
        "ipopt.max_iter": settings.ipopt_max_iter,
        "ipopt.mu_strategy": settings.ipopt_mu_strategy,
        "ipopt.constr_viol_tol": 0.1 * settings.constraint_tol,
        "ipopt.bound_relax_factor": 0.01 * settings.constraint_tol,
    }


def ipopt_solver(problem) -> ca.Function:
    """The CasADi ``nlpsol`` of a FormFindingProblem, built once and cached on it.

    The Hessian of the Lagrangian is ``settings.ipopt_hessian``: "closed-form"
    (``rigidfold.optimize.hessian``) or "casadi" (CasADi's symbolic Hessian).
    """
    if problem._ipopt is None:
        nlp = {"x": problem._xi, "p": problem._w, "f": problem._F, "g": problem._g}
        options = ipopt_options(problem.settings)
        if problem.settings.ipopt_hessian == "closed-form":
            from rigidfold.optimize.hessian import closed_form_hess_lag

            problem._hess_lag = closed_form_hess_lag(problem)  # CasADi keeps no reference
            options["hess_lag"] = problem._hess_lag
        problem._ipopt = ca.nlpsol("form_finding", "ipopt", nlp, options)
    return problem._ipopt


def run_ipopt(problem, xi0: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, int, str, str]:
    """Solve from ``xi0`` with fixed-crease weights ``w``.

    returns : (xi (n,), iterations, outcome, IPOPT's return status)
    """
    solver = ipopt_solver(problem)
    sol = solver(x0=xi0, p=w, lbg=problem.lbg, ubg=problem.ubg)
    stats = solver.stats()
    status = str(stats.get("return_status", "unknown"))
    outcome = _OUTCOME.get(status, "failed")
    xi = np.asarray(sol["x"], dtype=float).ravel()
    return xi, int(stats.get("iter_count", 0)), outcome, f"IPOPT: {status}"
