"""Projection onto F = 0: a Levenberg-Marquardt solver of problem (6) for large patterns.

Any shape that meets the constraints of (6) with F = 0 solves it, and from a shape close to
one, the nearest is found by Gauss-Newton steps of least norm on the residuals of
``rigidfold.optimize.residuals`` (``F = |r|^2``):

::

    dxi = -A^T (A A^T + mu I)^-1 (r, h),     A = (J; C_W),     mu = lambda |r| max diag(A A^T)

``J J^T`` has a row per interior vertex and fixed crease and a few dozen non-zeros per row,
so one step costs a sparse factorisation of that size (SuperLU); near a zero of F the steps
converge quadratically. The damping is proportional to |r| (Fan and Yuan's choice, which keeps
the fast local convergence where the zeros of F form a family, as they do here), and lambda
follows the ratio of the actual to the predicted decrease of F. Where the residual lies in
directions that the damping all but cuts off (or against a held bound), the steps creep, F
falling a per cent or less a step; given ``stall`` steps, the projection stops there
("stalled") once its last ``stall`` accepted steps together lowered F by less than half.

Every iterate meets the constraints of (6) (the dz, sector angle and fold angle bounds): the
projection starts only from a feasible shape and refuses a step that leaves the feasible set,
like one that does not decrease F. A constraint that a step would break joins the working
set W and is held: its row of the constraint Jacobian C (``rigidfold.optimize.jacobian``)
joins J, with the residual h that keeps it ``Settings.solver.projection_margin`` inside its bound,
so the next steps slide along the bound instead of being refused; a held constraint whose
multiplier (its entry of (A A^T + mu I)^-1 (r, h)) pulls it away from its bound is released.
This is what lets a step of ``generate`` move a shape whose sector angles or heights sit at
their bounds. The projection ends converged at F <= ``Settings.solver.projection_tol``; otherwise it
stops after ``Settings.solver.projection_max_iter`` factorisations and says so.

IPOPT's interior-point path finds zeros of F far from the start (the lifted target surface
is far from developable); the projection finds the near ones: after one more crease is
fixed in ``generate``, and at the end of an IPOPT run, whose last iterations creep along the
family of zeros of F without meeting IPOPT's own tolerance (see ``rigidfold.optimize.ipopt``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.optimize.jacobian import ClosedFormJacobian
from rigidfold.optimize.residuals import Residuals
from rigidfold.optimize.solver import SolverProblem

_GAIN = 1e-4  # least ratio of actual to predicted decrease for a step to be taken


@dataclass(frozen=True, eq=False)
class Projected:
    """The end of one projection.

    xi : (n,) float64, the last iterate (feasible unless the start was not); F : its
    objective; iterations : the factorisations it took; converged : F <=
    ``Settings.solver.projection_tol``; feasible : whether xi meets the constraints of (6)
    (False only for an infeasible start, which is not projected); held : how many constraints
    were held at the end; reason : why it stopped, in words.
    """

    xi: np.ndarray
    F: float
    iterations: int
    converged: bool
    feasible: bool
    held: int
    reason: str


@dataclass(frozen=True, eq=False)
class _Point:
    """What a step needs at one iterate: r (m,), J (m, n), g (c,) and the nonzeros of the
    constraint Jacobian (``ClosedFormJacobian.values``)."""

    r: np.ndarray
    J: sp.csr_matrix
    g: np.ndarray
    nonzeros: np.ndarray


class Projection:
    """The projection of a FormFindingProblem (a ``SolverProblem``), built once and kept.

    ``residuals`` and ``constraints`` (a ``ClosedFormJacobian``) are the problem's, built here
    unless given (the IPOPT solver shares its own).
    """

    def __init__(
        self,
        problem: SolverProblem,
        residuals: Residuals | None = None,
        constraints: ClosedFormJacobian | None = None,
    ) -> None:
        self.problem = problem
        self.settings = problem.settings
        self.residuals = residuals or Residuals(problem.pattern, problem.map)
        self.constraints = constraints or ClosedFormJacobian(problem)
        self.lbg, self.ubg = problem.nlp.lbg, problem.nlp.ubg

    def feasible(self, xi: np.ndarray, w: np.ndarray) -> bool:
        """Whether a point meets every constraint of (6), well inside ``constraint_tol``; a
        point that is no shape (a triangle collapsed, a coordinate not finite: an IPOPT
        iterate stopped early can be one) does not."""
        coords = self.problem.map.expand(xi)
        try:
            violation = self.problem.violation(coords, w > 0)
        except ValueError:  # rigidfold.mesh.CreasePattern refuses the shape
            return False
        return violation <= 0.1 * self.settings.solver.constraint_tol

    def __call__(
        self,
        xi0: np.ndarray,
        w: np.ndarray,
        *,
        tol: float | None = None,
        deadline: float | None = None,
        stall: int = 0,
    ) -> Projected:
        """Project from ``xi0`` (n,) with fixed-crease weights ``w`` (E,) to F <= ``tol``
        (default ``Settings.solver.projection_tol``); ``deadline`` (of ``time.monotonic()``):
        it stops there ("stopped"); ``stall`` (0: never): it stops once the last ``stall``
        accepted steps together lowered F by less than half ("stalled")."""
        s = self.settings
        tol = s.solver.projection_tol if tol is None else tol
        xi = np.asarray(xi0, dtype=float).copy()
        w = np.asarray(w, dtype=float)
        if not self.feasible(xi, w):
            with np.errstate(invalid="ignore", divide="ignore"):  # F of no shape is NaN
                r, _ = self.residuals(xi, w, jacobian=False)
            reason = "the start violates a constraint of (6)"
            return Projected(xi, float(r @ r), 0, False, False, 0, reason)
        held = np.zeros(0, dtype=np.int64)  # the working set W
        point = self._evaluate(xi, w)
        r, J, g = point.r, point.J, point.g
        A, ra = self._augment(point, held)
        F = float(r @ r)
        scale = -1.0  # the largest diagonal entry of A A^T at the start
        lam, nu = s.solver.projection_damping, 2.0
        slack = 0.1 * s.solver.constraint_tol
        taken = [F]  # F after each accepted step, the start first
        k = 0
        for k in range(s.solver.projection_max_iter):
            if F <= tol:
                return self._end(xi, F, k, held, "converged", tol)
            if deadline is not None and time.monotonic() > deadline:
                return self._end(xi, F, k, held, "stopped (its deadline)", tol)
            AA = (A @ A.T).tocsc()
            if scale < 0:
                scale = float(AA.diagonal().max())
            y = _solve(AA, lam * scale * np.sqrt(F), ra)
            loose = self._loose(held, g, y[len(r) :])
            if loose.any():  # held against the wrong side: let go
                held = held[~loose]
                A, ra = self._augment(point, held)
                continue
            step = -(A.T @ y)
            predicted = F - float(np.sum((r + J @ step) ** 2))
            trial = xi + step
            g_trial, nonzeros_trial = self.constraints.values(trial, w)
            broken = np.flatnonzero((g_trial < self.lbg - slack) | (g_trial > self.ubg + slack))
            blocked = np.setdiff1d(broken, held)
            if blocked.size:  # hold them and take the step again
                held = np.union1d(held, blocked)
                A, ra = self._augment(point, held)
                continue
            r_trial, _ = self.residuals(trial, w, jacobian=False)
            F_trial = float(r_trial @ r_trial)
            gain = (F - F_trial) / predicted if predicted > 0 else -1.0
            if gain > _GAIN and not broken.size and self.feasible(trial, w):
                xi, F = trial, F_trial
                point = self._evaluate(xi, w, (g_trial, nonzeros_trial))
                r, J, g = point.r, point.J, point.g
                A, ra = self._augment(point, held)
                lam *= 0.25 if gain > 0.75 else 1.0 if gain > 0.25 else 4.0
                nu = 2.0
                taken.append(F)
                if stall and len(taken) > stall and F > tol and F > 0.5 * taken[-1 - stall]:
                    return self._end(xi, F, k + 1, held, "stalled", tol)
            else:
                lam *= nu
                nu *= 2
        return self._end(xi, F, k + 1, held, "converged" if F <= tol else "stopped", tol)

    def _evaluate(
        self,
        xi: np.ndarray,
        w: np.ndarray,
        constraints: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> _Point:
        """Residuals, constraints and their Jacobians at xi; ``constraints`` are the
        (g, nonzeros) of ``ClosedFormJacobian.values`` there, when already known."""
        r, J = self.residuals(xi, w)
        assert J is not None
        g, nonzeros = self.constraints.values(xi, w) if constraints is None else constraints
        return _Point(r, J, g, nonzeros)

    def _augment(self, point: _Point, held: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
        """A = (J; C_W) and (r, h) at a point, for the held constraints ``held``."""
        if not held.size:
            return point.J, point.r
        margin = self.settings.solver.projection_margin
        g = point.g[held]
        lo, hi = self.lbg[held] + margin, self.ubg[held] - margin
        h = g - np.clip(g, lo, np.maximum(lo, hi))
        C = self.constraints.matrix(point.nonzeros)[held]
        return sp.vstack([point.J, C]).tocsr(), np.concatenate([point.r, h])

    def _loose(self, held: np.ndarray, g: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Which held constraints (bool, like ``held``) their multipliers y pull inwards.

        A step is ``-A^T y``, so a row held at its upper bound pushes its constraint down
        when its multiplier is positive, and one at its lower bound up when it is negative.
        """
        upper = np.abs(g[held] - self.ubg[held]) < np.abs(g[held] - self.lbg[held])
        return np.where(upper, y < 0, y > 0)

    def _end(
        self, xi: np.ndarray, F: float, k: int, held: np.ndarray, how: str, tol: float
    ) -> Projected:
        words = (
            f"{how}, F = {F:.3g} in {k} steps"
            if how == "converged"
            else (f"{how} at F = {F:.3g} after {k} steps")
        )
        if held.size:
            words += f", {held.size} constraint{'s' if held.size > 1 else ''} held"
        return Projected(xi, F, k, F <= tol, True, int(held.size), words)


def _solve(JJ: sp.csc_matrix, mu: float, r: np.ndarray) -> np.ndarray:
    """(J J^T + mu I)^-1 r by SuperLU in a minimum-degree order of the symmetric matrix."""
    M = (JJ + mu * sp.identity(JJ.shape[0], format="csc")).tocsc()
    return spla.splu(M, permc_spec="MMD_AT_PLUS_A").solve(r)
