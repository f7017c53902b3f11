"""Pseudo-stiffness matrix and its eigen-derivatives (Section 4, Appendix B).

With fictitious hinge stiffnesses K (h,), the pseudo stiffness matrix is
``K~ = H_phi^T diag(K) H_phi`` (Eq. 19). Its eigenpairs ``K~ alpha_i = lambda_i alpha_i``
(Eq. 21) give the rotation modes ``Phi = H_phi A`` (Eq. 23) with ``Phi^T K Phi = Lambda``
(Eq. 25), and, for distinct eigenvalues,

* d lambda_i / d K_j = phi_ij^2                                                      (27)
* d alpha_i / d K_j = -sum_{k != i} phi_kj phi_ij / (lambda_k - lambda_i) alpha_k     (28)
* d phi_i / d K_j  = H_phi d alpha_i / d K_j                                          (29)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rigidfold.config import DEFAULTS, Settings


def hinge_stiffness(h: int, seed: int | None = 0, settings: Settings = DEFAULTS) -> np.ndarray:
    """Random fictitious hinge stiffnesses, uniform in K0 +/- spread (paper: 1e-3 +/- 0.5e-6 Nm).

    The spread avoids repeated eigenvalues (Remark 3).  -> (h,) float64
    """
    rng = np.random.default_rng(seed)
    k0, dk = settings.generation.hinge_stiffness, settings.generation.hinge_stiffness_spread
    return rng.uniform(k0 - dk, k0 + dk, size=h)


@dataclass(frozen=True, eq=False)
class PseudoStiffness:
    """Eigen-analysis of K~ = H_phi^T K H_phi.

    H_phi : (h, d) hinge rotations of orthonormal mechanism modes
    K : (h,) hinge stiffnesses
    """

    H_phi: np.ndarray
    K: np.ndarray

    @cached_property
    def matrix(self) -> np.ndarray:
        """K~ (d, d), Eq. (19)."""
        return self.H_phi.T @ (self.K[:, None] * self.H_phi)

    @cached_property
    def _eig(self) -> tuple[np.ndarray, np.ndarray]:
        lam, A = np.linalg.eigh(self.matrix)
        return lam, A

    @property
    def eigenvalues(self) -> np.ndarray:
        """lambda (d,), ascending (Eq. 21)."""
        return self._eig[0]

    @property
    def eigenvectors(self) -> np.ndarray:
        """A (d, d), column i is alpha_i (Eq. 24)."""
        return self._eig[1]

    @cached_property
    def Phi(self) -> np.ndarray:
        """Rotation modes Phi = H_phi A (h, d); Phi[j, i] = phi_ij (Eq. 23)."""
        return self.H_phi @ self.eigenvectors

    def eigenvalue_derivatives(self) -> np.ndarray:
        """d lambda_i / d K_j = phi_ij^2 as an (h, d) array [j, i] (Eq. 27)."""
        return self.Phi**2

    def eigenvector_derivatives(self, j: int) -> np.ndarray:
        """d alpha_i / d K_j for all i as a (d, d) array, column i (Eq. 28)."""
        lam, A = self.eigenvalues, self.eigenvectors
        phi_j = self.Phi[j]  # (d,) phi_ij over modes i
        gap = lam[:, None] - lam[None, :]  # [k, i] = lambda_k - lambda_i
        np.fill_diagonal(gap, np.inf)
        coef = -(phi_j[:, None] * phi_j[None, :]) / gap  # [k, i]
        return A @ coef

    def rotation_derivatives(self, j: int) -> np.ndarray:
        """d phi_i / d K_j for all i as an (h, d) array, column i (Eq. 29)."""
        return self.H_phi @ self.eigenvector_derivatives(j)

    def normalised_modes(self, k_ref: float | None = None) -> np.ndarray:
        """Phi-hat (h, d): column i of Phi times sqrt(K / lambda_i), Eq. (35); K = mean K_j."""
        k = float(np.mean(self.K)) if k_ref is None else k_ref
        return self.Phi * np.sqrt(k / self.eigenvalues)

    def stiffened(self, j: int, factor: float = 1e14) -> PseudoStiffness:
        """The same modes with K_j multiplied by ``factor`` (Section 4.2, Tables 2-3)."""
        K = self.K.copy()
        K[j] *= factor
        return PseudoStiffness(self.H_phi, K)

    def residual_rotations(self) -> np.ndarray:
        """(h,) norm of each hinge's rotations outside the stiffest mode.

        After stiffening hinge j, hinge j rotates only in the mode of the largest eigenvalue
        (Eq. 26); a hinge p that also keeps no rotation in the other modes is locked once j is
        fixed (Property 2).
        """
        return np.linalg.norm(self.Phi[:, :-1], axis=1)

    def psi(self) -> np.ndarray:
        """Psi (h, d): rows of Phi normalised to unit length (Eq. 31)."""
        norms = np.linalg.norm(self.Phi, axis=1, keepdims=True)
        return self.Phi / np.where(norms > 0, norms, 1.0)
