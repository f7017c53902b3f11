"""What a solver of problem (6) is: ``solve(xi0, w) -> SolverRun``.

A solver is built once per ``FormFindingProblem`` (``problem.solver(name)``) and keeps what
it builds (IPOPT's ``nlpsol``, its Hessian callback); each ``solve`` runs it from one start
with one set of fixed creases. rigidfold's own verdict on the run (``Status``) is made by
``rigidfold.optimize.problem.classify`` from the solver's ``SolverOutcome``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from rigidfold.status import Outcome


class SolverOutcome(Outcome):
    """How the solver itself says a run ended (before rigidfold judges the point)."""

    SOLVED = "solved", "the solver reports convergence"
    INFEASIBLE = "infeasible", "the solver reports an infeasible problem"
    ITERATION_LIMIT = "iteration_limit", "the solver reached its iteration or time limit"
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


class Solver(Protocol):
    """A solver of problem (6), built for one ``FormFindingProblem``."""

    def solve(self, xi0: np.ndarray, w: np.ndarray) -> SolverRun:
        """Solve from ``xi0`` (n,) with fixed-crease weights ``w`` (E,)."""
        ...
