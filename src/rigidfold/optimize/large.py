"""The solver of problem (6) on large patterns: projection, IPOPT, projection.

On patterns of at least ``Settings.solver.projection_vertices`` vertices, and on every pattern
where the problem projects first (``project_first``: a generation run with the deployability
check, ``GenerateOptions.projection``), ``--solver ipopt`` is this composite
(:func:`ipopt_solver` chooses). IPOPT gets the gradient of F and the
constraint Jacobian in closed form (:mod:`rigidfold.optimize.jacobian`; CasADi's cost most
of a large build), and the solver does three things: the projection onto F = 0 from the
start (:mod:`rigidfold.optimize.projection`), which is all that is needed after one more
crease is fixed (a projection that stops, feasible, at F <= ``Settings.solver.ipopt_stop_f`` is
taken too: IPOPT would stop there at once); otherwise IPOPT, stopped at its first feasible
iterate with F <= ``ipopt_stop_f`` by an iteration callback; then the projection from
there. IPOPT's last iterations on (6) creep along the family of zeros of F: on a 41 x 41
grid it reaches F = 1.5e-11 at iteration 98 of 180, and steps from a start that is already a
solution can take 158 iterations that leave F where it was (``docs/scale.md``).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from rigidfold.optimize.ipopt import EarlyStop, IpoptSolver
from rigidfold.optimize.jacobian import ClosedFormJacobian, closed_form_first_derivatives
from rigidfold.optimize.projection import Projection
from rigidfold.optimize.residuals import Residuals
from rigidfold.optimize.solver import Solver, SolverOutcome, SolverProblem, SolverRun


class ProjectedIpoptSolver:
    """Projection, IPOPT stopped early, projection (see the module's text); built once.

    projection : the Newton projection onto F = 0 with every constraint of (6) kept;
    ipopt : IPOPT with closed-form first derivatives and the early stop.
    """

    def __init__(self, problem: SolverProblem) -> None:
        self._stop_f = problem.settings.solver.ipopt_stop_f
        residuals = Residuals(problem.pattern, problem.map)
        jacobian = ClosedFormJacobian(problem)
        self.projection = Projection(problem, residuals, jacobian)
        self.ipopt = IpoptSolver(
            problem,
            first_derivatives=closed_form_first_derivatives(problem, residuals, jacobian),
            early_stop=EarlyStop(problem, self._stop_f),
        )

    @property
    def nlpsol(self) -> ca.Function:
        """CasADi's IPOPT solver of the middle step (``nlpsol.stats()``: its last run)."""
        return self.ipopt.nlpsol

    def solve(
        self,
        xi0: np.ndarray,
        w: np.ndarray,
        deadline: float | None = None,
        max_iter: int | None = None,
        stall: int | None = None,
    ) -> SolverRun:
        """Solve from ``xi0`` (n,) with fixed-crease weights ``w`` (E,); the run's message
        says what the projection did before and after IPOPT, and IPOPT's return status.
        ``deadline`` (of ``time.monotonic()``) ends each part at its iterate; ``max_iter``
        and ``stall`` bound IPOPT's iterations (the projections keep
        ``projection_max_iter``)."""
        first = self.projection(xi0, w, deadline=deadline)
        if first.converged or (first.feasible and first.F <= self._stop_f):
            # IPOPT would stop at once and hand the same point back
            return SolverRun(
                first.xi, first.iterations, SolverOutcome.SOLVED, f"projection: {first.reason}"
            )
        run = self.ipopt.solve(xi0, w, deadline, max_iter, stall)
        polish = self.projection(run.xi, w, deadline=deadline)
        iterations = first.iterations + run.iterations + polish.iterations
        message = f"projection: {first.reason}; {run.message}; projection: {polish.reason}"
        if polish.converged:
            return SolverRun(polish.xi, iterations, SolverOutcome.SOLVED, message)
        return SolverRun(polish.xi, iterations, run.outcome, message)


def ipopt_solver(problem: SolverProblem) -> Solver:
    """``--solver ipopt``: :class:`ProjectedIpoptSolver` where the problem projects first
    (``project_first``: a generation run with the deployability check, ``GenerateOptions.
    projection``) or has ``Settings.solver.projection_vertices`` vertices or more; IPOPT
    alone otherwise (the paper's solver)."""
    if (
        problem.project_first
        or problem.pattern.n_vertices >= problem.settings.solver.projection_vertices
    ):
        return ProjectedIpoptSolver(problem)
    return IpoptSolver(problem)
