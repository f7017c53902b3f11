"""What a solver of problem (6) is: ``solve(xi0, w) -> SolverRun``.

A solver is built once per ``FormFindingProblem`` (``problem.solver(name)``) and keeps what
it builds (IPOPT's ``nlpsol``, its Hessian callback); each ``solve`` runs it from one start
with one set of fixed creases. rigidfold's own verdict on the run (``Status``) is made by
``rigidfold.optimize.problem.classify`` from the solver's ``SolverOutcome``. What a solver
(and the closed-form Hessian) reads from the problem is the Protocol ``SolverProblem``, which
``FormFindingProblem`` satisfies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import casadi as ca
import numpy as np

from rigidfold.config import Settings
from rigidfold.mesh import CreasePattern
from rigidfold.optimize.nlp import NLP
from rigidfold.optimize.variables import LinearMap
from rigidfold.outcomes import Outcome
from rigidfold.protocols import TargetSurface


class SolverOutcome(Outcome):
    """How the solver itself says a run ended (before rigidfold judges the point)."""

    SOLVED = "solved", "the solver reports convergence"
    INFEASIBLE = "infeasible", "the solver reports an infeasible problem"
    ITERATION_LIMIT = "iteration_limit", "the solver reached its iteration or time limit"
    STALLED = (
        "stalled",
        "the run was ended where its least feasible F had not halved in its stall window "
        "(see :func:`stalled`)",
    )
    FAILED = "failed", "the solver failed"


@dataclass(frozen=True, eq=False)
class SolverRun:
    """One run of a solver on problem (6).

    xi : (n,) float64
        The independent variables it returned.
    iterations : int
    outcome : SolverOutcome
    message : str
        The solver's own words, e.g. ``"IPOPT: Solve_Succeeded"``.
    """

    xi: np.ndarray
    iterations: int
    outcome: SolverOutcome
    message: str


class SolverProblem(Protocol):
    """What the solvers and the closed-form Hessian read from a built problem (6).

    objective : ca.Function (xi, w) -> (F, F1, F2)
    objective_gradient : ca.Function (xi, w) -> (F, dF (n,))
    constraints : ca.Function (xi, w) -> g (m,)
    constraint_jacobian : ca.Function (xi, w) -> (g (m,), dg (m, n))
    project_first : the IPOPT solver begins with the projection onto F = 0 at every size
    (see ``FormFindingProblem``, which satisfies it).
    """

    project_first: bool
    pattern: CreasePattern
    surface: TargetSurface
    settings: Settings
    map: LinearMap
    nlp: NLP
    objective: ca.Function

    @property
    def objective_gradient(self) -> ca.Function: ...

    @property
    def constraint_jacobian(self) -> ca.Function: ...

    @property
    def constraints(self) -> ca.Function: ...

    def violation(self, coords: np.ndarray, fixed: np.ndarray) -> float:
        """Largest violation of any constraint of (6) at a shape (V, 3), fixed (E,) bool."""
        ...


class Solver(Protocol):
    """A solver of problem (6), built for one ``SolverProblem`` (a ``FormFindingProblem``)."""

    def solve(
        self,
        xi0: np.ndarray,
        w: np.ndarray,
        deadline: float | None = None,
        max_iter: int | None = None,
        stall: int | None = None,
    ) -> SolverRun:
        """Solve from ``xi0`` (n,) with fixed-crease weights ``w`` (E,); ``deadline`` (a time
        of ``time.monotonic()``; None: none) ends the run at its iterate, an iteration
        limit (``SolverOutcome.ITERATION_LIMIT``), and so does ``max_iter`` (None: the
        solver's limit of the settings), where it is lower than that limit. ``stall``
        (None: never) ends it where its least feasible F has not halved in that many
        iterations while above F_tol (``SolverOutcome.STALLED``, :func:`stalled`)."""
        ...


def stalled(best: list[float], window: int | None, f_tol: float) -> bool:
    """Whether a run has stalled: ``best[i]`` is the least F of its feasible iterates up to
    iteration i (i = 0, 1, ...; inf before the first), and it is above ``f_tol`` and has
    not halved in the last ``window`` iterations, which began at a feasible iterate.

    Only feasible iterates count: a start off the constraints (a child's parent shape with
    one more crease fixed may have F near 0 and violate the dz bound) has a small F that
    means nothing. Newton-type iterations that reach a zero of F (a shape with the fixed
    creases flat) halve it far faster than that near the end; a run whose best F stays
    within a factor of two for ``window`` iterations sits at a local minimum of F above F_tol
    (the creases cannot be flattened within dz from there) or crawls along the bounds of
    (6). Of the child solves of the 25 drawn and roof cases and of 37 cases of the broad set
    that converged, none went 60 iterations above F_tol without halving its best F (at worst
    it fell to about a quarter), while 68 of the 76 of the drawn cases that did not converge
    would have ended there, most on a plateau of F for hundreds of iterations
    (``benchmarks/stall_traces.py``, docs/broad_set.md, session 46).
    """
    if window is None or len(best) <= window:
        return False
    before, now = best[-1 - window], best[-1]
    return bool(np.isfinite(before) and now > f_tol and now > 0.5 * before)
