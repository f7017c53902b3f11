"""The one result type every solver of problem (6) returns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome


class Status(Outcome):
    """Outcome of a solve, judged by rigidfold (not only by the solver's own flag)."""

    CONVERGED = "converged", "F <= F_tol and every constraint met to constraint_tol"
    TOLERANCE_NOT_MET = "tolerance_not_met", "the solver stopped at a feasible point with F > F_tol"
    INFEASIBLE = (
        "infeasible",
        "the solver reports infeasibility, or the point violates a constraint",
    )
    ITERATION_LIMIT = (
        "iteration_limit",
        "the iteration (or time) limit was reached before F <= F_tol",
    )
    STALLED = (
        "stalled",
        "the solve was ended where its least feasible F had not halved in its stall window "
        "above F_tol (a child's solve in a design search, ``Settings.generation.child_stall``)",
    )
    FOLDED_BACK = (
        "folded_back",
        "F <= F_tol, but a fixed crease is folded onto itself (|fold angle| above 90 "
        "degrees): the flatness term |n_a x n_b|^2 = sin^2 vanishes at 180 degrees too, and "
        "its two facets overlap instead of making one flat panel",
    )
    FAILED = "failed", "any other solver failure (e.g. a line-search or evaluation error)"


@dataclass(frozen=True, eq=False)
class OptimizeResult:
    """Solution of problem (6).

    pattern : CreasePattern
        The optimised shape with the fixed-crease mask that was solved for.
    coords : (V, 3) float64
        Its vertex coordinates (``pattern.coords``).
    F, F1, F2 : float
        Objective and its developability and flatness parts at the returned point.
    max_violation : float
        Largest violation of any constraint of (6) (metres for dz and (7)-(9), radians for angles).
    status : Status
        How the solve ended (``status.message`` says what that means).
    message : str
        The detail: the solver's own words and rigidfold's verdict.
    iterations : int
    wall_time : float
        Seconds spent in the solve (not in building the model).
    solver : str
        "ipopt", "slsqp" or "slsqp-fd".
    n_variables : int
        Number of independent variables.
    """

    pattern: CreasePattern
    F: float
    F1: float
    F2: float
    max_violation: float
    status: Status
    message: str
    iterations: int
    wall_time: float
    solver: str
    n_variables: int

    @property
    def coords(self) -> np.ndarray:
        return self.pattern.coords

    @property
    def converged(self) -> bool:
        return self.status is Status.CONVERGED

    def to_dict(self) -> dict:
        """JSON-serialisable figures of the solve."""
        return {
            "status": self.status.value,
            "message": self.message,
            "solver": self.solver,
            "F": self.F,
            "F1": self.F1,
            "F2": self.F2,
            "max_violation": self.max_violation,
            "iterations": self.iterations,
            "wall_time_s": self.wall_time,
            "n_variables": self.n_variables,
        }
