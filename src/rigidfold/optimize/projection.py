"""Projection onto F = 0: a Levenberg-Marquardt solver of problem (6) for large patterns.

Any shape that meets the constraints of (6) with F = 0 solves it, and from a shape close to
one, the nearest is found by Gauss-Newton steps of least norm on the residuals of
``rigidfold.optimize.residuals`` (``F = |r|^2``):

::

    dxi = -J^T (J J^T + mu I)^-1 r,     mu = lambda |r| max diag(J J^T)

``J J^T`` has a row per interior vertex and fixed crease and a few dozen non-zeros per row,
so one step costs a sparse factorisation of that size (SuperLU); near a zero of F the steps
converge quadratically. The damping is proportional to |r| (Fan and Yuan's choice, which keeps
the fast local convergence where the zeros of F form a family, as they do here), and lambda
follows the ratio of the actual to the predicted decrease of F; a step that leaves
the feasible set of (6) (the dz, sector angle and fold angle bounds) is refused like one that
does not decrease F, so every iterate is feasible. The projection ends converged at
F <= ``Settings.projection_tol``; otherwise it stops after ``Settings.projection_max_iter``
factorisations and says so.

IPOPT's interior-point path finds zeros of F far from the start (the lifted target surface
is far from developable); the projection finds the near ones: after one more crease is
fixed in ``generate``, and at the end of an IPOPT run, whose last iterations creep along the
family of zeros of F without meeting IPOPT's own tolerance (see ``rigidfold.optimize.ipopt``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.optimize.residuals import Residuals
from rigidfold.optimize.solver import SolverProblem

_GAIN = 1e-4  # least ratio of actual to predicted decrease for a step to be taken


@dataclass(frozen=True, eq=False)
class Projected:
    """The end of one projection.

    xi : (n,) float64, the last feasible iterate; F : its objective; iterations : the
    factorisations it took; converged : F <= ``Settings.projection_tol``; reason : why it
    stopped, in words.
    """

    xi: np.ndarray
    F: float
    iterations: int
    converged: bool
    reason: str


class Projection:
    """The projection of a FormFindingProblem (a ``SolverProblem``), built once and kept."""

    def __init__(self, problem: SolverProblem) -> None:
        self.problem = problem
        self.settings = problem.settings
        self.residuals = Residuals(problem.pattern, problem.map)

    def feasible(self, xi: np.ndarray, w: np.ndarray) -> bool:
        """Whether a point meets every constraint of (6), well inside ``constraint_tol``."""
        coords = self.problem.map.expand(xi)
        return self.problem.violation(coords, w > 0) <= 0.1 * self.settings.constraint_tol

    def __call__(self, xi0: np.ndarray, w: np.ndarray) -> Projected:
        """Project from ``xi0`` (n,) with fixed-crease weights ``w`` (E,)."""
        s = self.settings
        xi = np.asarray(xi0, dtype=float).copy()
        w = np.asarray(w, dtype=float)
        r, J = self.residuals(xi, w)
        F = float(r @ r)
        if not self.feasible(xi, w):
            return Projected(xi, F, 0, False, "the start violates a constraint of (6)")
        scale = -1.0  # the largest diagonal entry of J J^T at the start
        lam, nu = s.projection_damping, 2.0
        for k in range(s.projection_max_iter):
            if F <= s.projection_tol:
                return Projected(xi, F, k, True, f"converged, F = {F:.3g} in {k} steps")
            assert J is not None
            JJ = (J @ J.T).tocsc()
            if scale < 0:
                scale = float(JJ.diagonal().max())
            step = -(J.T @ _solve(JJ, lam * scale * np.sqrt(F), r))
            predicted = F - float(np.sum((r + J @ step) ** 2))
            trial = xi + step
            r_trial, _ = self.residuals(trial, w, jacobian=False)
            F_trial = float(r_trial @ r_trial)
            gain = (F - F_trial) / predicted if predicted > 0 else -1.0
            if gain > _GAIN and self.feasible(trial, w):
                xi, F = trial, F_trial
                r, J = self.residuals(xi, w)
                lam *= 0.25 if gain > 0.75 else 1.0 if gain > 0.25 else 4.0
                nu = 2.0
            else:
                lam *= nu
                nu *= 2
        if F <= s.projection_tol:
            return Projected(xi, F, k + 1, True, f"converged, F = {F:.3g} in {k + 1} steps")
        return Projected(xi, F, k + 1, False, f"stopped at F = {F:.3g} after {k + 1} steps")


def _solve(JJ: sp.csc_matrix, mu: float, r: np.ndarray) -> np.ndarray:
    """(J J^T + mu I)^-1 r by SuperLU in a minimum-degree order of the symmetric matrix."""
    M = (JJ + mu * sp.identity(JJ.shape[0], format="csc")).tocsc()
    return spla.splu(M, permc_spec="MMD_AT_PLUS_A").solve(r)
