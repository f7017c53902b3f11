"""IPOPT (through CasADi) on problem (6), with exact gradient, Jacobian and Hessian.

The first derivatives are the problem's (CasADi's) or, for large patterns, given in closed
form, and IPOPT can be stopped early by an iteration callback (:class:`EarlyStop`): both
are what the composite solver of large patterns (:mod:`rigidfold.optimize.large`) asks of
it. The same callback ends a solve at a deadline (a run's time limit, :meth:`IpoptSolver.
solve`): CasADi fixes IPOPT's options (its ``max_wall_time`` too) when it builds the solver
once per problem, so the remaining time of each solve is the callback's to keep, and so is
a solve's own iteration limit where it is lower than the settings' (a generation run's
children, ``Settings.generation.child_max_iter``).
"""

from __future__ import annotations

import time

import casadi as ca
import numpy as np

from rigidfold.config import Settings
from rigidfold.optimize.hessian import closed_form_hess_lag
from rigidfold.optimize.solver import SolverOutcome, SolverProblem, SolverRun, stalled
from rigidfold.runtime.quiet import native_quiet

STALLED = "Stalled"
"""The status of a run that :class:`EarlyStop` ended where F stalled (not one of IPOPT's)."""

_OUTCOME = {
    "Solve_Succeeded": SolverOutcome.SOLVED,
    "Solved_To_Acceptable_Level": SolverOutcome.SOLVED,
    "Infeasible_Problem_Detected": SolverOutcome.INFEASIBLE,
    "Maximum_Iterations_Exceeded": SolverOutcome.ITERATION_LIMIT,
    "Maximum_CpuTime_Exceeded": SolverOutcome.ITERATION_LIMIT,
    "Maximum_WallTime_Exceeded": SolverOutcome.ITERATION_LIMIT,
    STALLED: SolverOutcome.STALLED,
    # EarlyStop asks, at F <= ipopt_stop_f (SOLVED), at its deadline, at its iteration
    # limit or where F stalled (see IpoptSolver.solve)
    "User_Requested_Stop": SolverOutcome.SOLVED,
}


def ipopt_options(settings: Settings, tol: float | None = None) -> dict:
    """CasADi ``nlpsol`` options for IPOPT from the settings (silent, exact Hessian).

    Bounds are relaxed and constraints accepted only far inside ``constraint_tol``, so a
    converged point meets every constraint to that tolerance. MUMPS gets 100 % more working
    space than its analysis estimates instead of IPOPT's 1000 %: it allocates that space at
    every factorisation, and the page faults of the larger one cost a tenth of a 41 x 41
    grid's solve in system time, for the same factors (the same iterates, measured on that
    grid and on 1271 solves of generation runs of patterns 1 and 2); IPOPT enlarges the space
    if MUMPS ever asks for more.
    """
    return {
        "print_time": False,
        "error_on_fail": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.tol": settings.solver.ipopt_tol if tol is None else tol,
        "ipopt.max_iter": settings.solver.ipopt_max_iter,
        "ipopt.mu_strategy": settings.solver.ipopt_mu_strategy,
        "ipopt.constr_viol_tol": 0.1 * settings.solver.constraint_tol,
        "ipopt.bound_relax_factor": 0.01 * settings.solver.constraint_tol,
        "ipopt.mumps_mem_percent": 100,
    }


class IpoptSolver:
    """IPOPT on the NLP of a FormFindingProblem, built once (at construction) and kept.

    The Hessian of the Lagrangian is ``settings.solver.ipopt_hessian``: "closed-form"
    (``rigidfold.optimize.hessian``, a callback this object keeps alive, as CasADi keeps no
    reference to it) or "casadi" (CasADi's symbolic Hessian).

    nlpsol : ca.Function
        CasADi's IPOPT solver; ``nlpsol.stats()`` holds the statistics of the last solve.
    """

    def __init__(
        self,
        problem: SolverProblem,
        *,
        first_derivatives: tuple[ca.Function, ca.Function] | None = None,
        early_stop: EarlyStop | None = None,
    ) -> None:
        nlp = problem.nlp
        self._lbg, self._ubg = nlp.lbg, nlp.ubg
        # kept alive: CasADi keeps no reference to a callback; without an F to stop at, it
        # only keeps the deadline of a solve
        self._stop = early_stop or EarlyStop(problem, None)
        # default: the problem's, so that CasADi does not differentiate (6) again
        self._first = first_derivatives or (
            problem.objective_gradient,
            problem.constraint_jacobian,
        )
        options = ipopt_options(problem.settings) | {
            "grad_f": self._first[0],
            "jac_g": self._first[1],
            # no multipliers of the parameters w: their symbolic gradient of the
            # Lagrangian would cost more to build than everything else
            "calc_lam_p": False,
            "no_nlp_grad": True,
        }
        options["iteration_callback"] = self._stop
        self._hess_lag = None
        if problem.settings.solver.ipopt_hessian == "closed-form":
            self._hess_lag = closed_form_hess_lag(problem)
            options["hess_lag"] = self._hess_lag
        with native_quiet():
            self.nlpsol: ca.Function = ca.nlpsol("form_finding", "ipopt", nlp.casadi(), options)

    def solve(
        self,
        xi0: np.ndarray,
        w: np.ndarray,
        deadline: float | None = None,
        max_iter: int | None = None,
        stall: int | None = None,
    ) -> SolverRun:
        """Solve from ``xi0`` (n,) with fixed-crease weights ``w`` (E,); the run's message
        is IPOPT's return status, e.g. ``"IPOPT: Solve_Succeeded"``. ``deadline``: a time
        of ``time.monotonic()`` after which the solve ends at its iterate (an iteration
        limit, ``"IPOPT: Maximum_WallTime_Exceeded"``); ``max_iter``: the solve ends at that
        iteration (``"IPOPT: Maximum_Iterations_Exceeded"``, as at IPOPT's own limit,
        ``Settings.solver.ipopt_max_iter``, which stays the bound); ``stall``: the solve
        ends where its least feasible F has not halved in that many iterations above F_tol
        (``"IPOPT: Stalled"``)."""
        self._stop.start(deadline, max_iter, stall)
        try:
            with native_quiet():
                sol = self.nlpsol(x0=xi0, p=w, lbg=self._lbg, ubg=self._ubg)
        finally:
            ended = self._stop.finish()
        stats = self.nlpsol.stats()
        status = str(stats.get("return_status", "unknown"))
        if ended is not None and status == "User_Requested_Stop":
            status = ended
        return SolverRun(
            xi=np.asarray(sol["x"], dtype=float).ravel(),
            iterations=int(stats.get("iter_count", 0)),
            outcome=_OUTCOME.get(status, SolverOutcome.FAILED),
            message=f"IPOPT: {status}",
        )


class EarlyStop(ca.Callback):
    """IPOPT's ``iteration_callback``: stop at a feasible iterate with F <= ``stop_f`` (None:
    never), at the first iterate after the solve's deadline, at the solve's iteration
    limit, or where its least feasible F has stalled (:meth:`start`,
    :func:`~rigidfold.optimize.solver.stalled`).

    CasADi calls it with nlpsol's outputs (x, f, g, lam_x, lam_g, lam_p) after each iteration;
    a return value of 1 ends the run as ``User_Requested_Stop`` at that iterate.
    """

    def __init__(self, problem: SolverProblem, stop_f: float | None) -> None:
        ca.Callback.__init__(self)
        self.stop_f = stop_f
        self.deadline: float | None = None
        self.max_iter: int | None = None
        self.stall: int | None = None
        self.best: list[float] = []  # the best feasible F after each iterate (inf: none yet)
        self.f_tol = problem.settings.design.f_tol
        self.calls = 0  # iterates seen in this solve: IPOPT calls at iteration 0 too
        self.ended: str | None = None  # IPOPT's status for a stop by the deadline or limit
        self.lbg, self.ubg = problem.nlp.lbg, problem.nlp.ubg
        self.tol = 0.1 * problem.settings.solver.constraint_tol
        self.sizes = {
            "x": problem.map.n_variables,
            "lam_x": problem.map.n_variables,
            "g": len(self.lbg),
            "lam_g": len(self.lbg),
            "f": 1,
            "lam_p": 0,
        }
        self.construct("early_stop", {})

    def get_n_in(self) -> int:
        return ca.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return ca.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "stop"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        size = self.sizes[ca.nlpsol_out(i)]
        return ca.Sparsity.dense(size, 1) if size else ca.Sparsity(0, 1)

    def start(
        self, deadline: float | None, max_iter: int | None = None, stall: int | None = None
    ) -> None:
        """Set the deadline of the next solve (a time of ``time.monotonic()``; None: none),
        its iteration limit (None: IPOPT's own) and its stall window (None: none)."""
        self.deadline, self.max_iter, self.stall = deadline, max_iter, stall
        self.calls, self.ended, self.best = 0, None, []

    def finish(self) -> str | None:
        """After a solve: the status that says why the callback ended it where that was its
        deadline, its iteration limit or a stall (None otherwise); the next solve has none
        of them."""
        ended = self.ended
        self.start(None)
        return ended

    def eval(self, arg):
        iteration, self.calls = self.calls, self.calls + 1
        if self.deadline is not None and time.monotonic() > self.deadline:
            self.ended = "Maximum_WallTime_Exceeded"
            return [1]
        f = float(arg[1])
        feasible = None  # decided only where needed
        if self.stop_f is not None and f <= self.stop_f:
            feasible = self._feasible(arg[2])
            if feasible:
                return [1]
        if self.max_iter is not None and iteration >= self.max_iter:
            self.ended = "Maximum_Iterations_Exceeded"
            return [1]
        if self.stall is not None:
            if feasible is None:
                feasible = self._feasible(arg[2])
            self.best.append(min(f if feasible else np.inf, self.best[-1] if self.best else np.inf))
            if stalled(self.best, self.stall, self.f_tol):
                self.ended = STALLED
                return [1]
        return [0]

    def _feasible(self, g) -> bool:
        """Whether constraint values g (m,) meet (6) far inside ``constraint_tol``."""
        g = np.asarray(g, dtype=float).ravel()
        violation = max(np.max(self.lbg - g, initial=0.0), np.max(g - self.ubg, initial=0.0))
        return bool(violation <= self.tol)
