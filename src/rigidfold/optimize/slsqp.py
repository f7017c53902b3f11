"""SciPy SLSQP on problem (6): the paper's solver.

``exact=True`` passes CasADi's exact gradient and constraint Jacobian (rigidfold's
paper-faithful reference); ``exact=False`` lets SciPy difference them numerically, as the
paper did (its baseline: 72 s per solve for 115 variables).
"""

from __future__ import annotations

import time

import numpy as np

from rigidfold.optimize.solver import SolverOutcome, SolverProblem, SolverRun, stalled

# SciPy's SLSQP exit modes (scipy/optimize/_slsqp_py.py)
_OUTCOME = {
    0: SolverOutcome.SOLVED,
    9: SolverOutcome.ITERATION_LIMIT,
    3: SolverOutcome.INFEASIBLE,
    4: SolverOutcome.INFEASIBLE,
}


class SlsqpSolver:
    """SLSQP on a FormFindingProblem, with exact (``exact=True``) or SciPy's finite-difference
    derivatives.

    The two-sided constraints of (6) become SLSQP's one-sided ``g >= 0`` rows here, once.
    """

    def __init__(self, problem: SolverProblem, *, exact: bool = True) -> None:
        lbg, ubg = problem.nlp.lbg, problem.nlp.ubg
        self.exact = exact
        self._settings = problem.settings
        self._objective = problem.objective
        self._objective_gradient = problem.objective_gradient
        self._constraints = problem.constraints
        self._constraint_jacobian = problem.constraint_jacobian
        self._lo_rows = np.flatnonzero(np.isfinite(lbg))
        self._hi_rows = np.flatnonzero(np.isfinite(ubg))
        self._lo, self._hi = lbg[self._lo_rows], ubg[self._hi_rows]

    def solve(
        self,
        xi0: np.ndarray,
        w: np.ndarray,
        deadline: float | None = None,
        max_iter: int | None = None,
        stall: int | None = None,
    ) -> SolverRun:
        """Solve from ``xi0`` (n,) with fixed-crease weights ``w`` (E,).

        The run's message is SciPy's, e.g. ``"SLSQP: Optimization terminated successfully"``.
        ``deadline`` (of ``time.monotonic()``): the run ends at the first iterate after it
        (SciPy's callback stops it; an iteration limit). ``max_iter``: SLSQP's iteration
        limit where it is below ``Settings.solver.slsqp_max_iter``. ``stall``: the run ends
        where its least feasible F has not halved in that many iterations above F_tol (the callback
        stops it; ``SolverOutcome.STALLED``).
        """
        from scipy.optimize import minimize  # only when SLSQP runs: not on the import path

        lo_rows, hi_rows, lo, hi = self._lo_rows, self._hi_rows, self._lo, self._hi

        def objective(xi):
            return float(self._objective(xi, w)[0])

        def objective_and_gradient(xi):
            f, grad = self._objective_gradient(xi, w)
            return float(f), np.asarray(grad, dtype=float).ravel()

        def inequalities(xi):  # >= 0
            g = np.asarray(self._constraints(xi, w), dtype=float).ravel()
            return np.concatenate([g[lo_rows] - lo, hi - g[hi_rows]])

        def inequality_jacobian(xi):
            jac = self._constraint_jacobian(xi, w)[1].full()
            return np.vstack([jac[lo_rows], -jac[hi_rows]])

        best: list[float] = []  # the best feasible F after each iteration (inf: none yet)
        f_tol = self._settings.design.f_tol
        feasible_tol = 0.1 * self._settings.solver.constraint_tol  # as IPOPT's

        def callback(intermediate_result):
            if deadline is not None and time.monotonic() > deadline:
                raise StopIteration
            if stall is None:
                return
            feasible = np.min(inequalities(intermediate_result.x), initial=0.0) >= -feasible_tol
            f = float(intermediate_result.fun) if feasible else np.inf
            best.append(min(f, best[-1] if best else np.inf))
            if stalled(best, stall, f_tol):
                raise StopIteration

        s = self._settings
        constraint = {"type": "ineq", "fun": inequalities}
        limit = s.solver.slsqp_max_iter
        if max_iter is not None:
            limit = min(limit, max_iter)
        options = {"maxiter": limit, "ftol": s.solver.slsqp_ftol}
        if self.exact:
            constraint["jac"] = inequality_jacobian
            res = minimize(
                objective_and_gradient,
                xi0,
                jac=True,
                method="SLSQP",
                constraints=[constraint],
                options=options,
                callback=callback,
            )
        else:
            res = minimize(
                objective,
                xi0,
                method="SLSQP",
                constraints=[constraint],
                options=options,
                callback=callback,
            )
        if deadline is not None and time.monotonic() > deadline and int(res.status) != 0:
            return SolverRun(
                xi=np.asarray(res.x, dtype=float),
                iterations=int(res.nit),
                outcome=SolverOutcome.ITERATION_LIMIT,
                message=f"SLSQP: stopped at its deadline ({res.message})",
            )
        if int(res.status) != 0 and stalled(best, stall, f_tol):
            return SolverRun(
                xi=np.asarray(res.x, dtype=float),
                iterations=int(res.nit),
                outcome=SolverOutcome.STALLED,
                message=f"SLSQP: F stalled ({res.message})",
            )
        return SolverRun(
            xi=np.asarray(res.x, dtype=float),
            iterations=int(res.nit),
            outcome=_OUTCOME.get(int(res.status), SolverOutcome.FAILED),
            message=f"SLSQP: {res.message}",
        )
