"""Mechanism analysis (Section 4.1): DOF, mechanism modes H, hinge rotations, locked creases.

Three methods give the same result:

* ``"kinematic"``: the kernel of the small vertex-velocity constraint matrix
  (:mod:`rigidfold.mechanism.kinematics`) by a dense pivoted QR, mapped onto the frame's
  displacement space and orthonormalised there. A dense factorisation of about
  (E + 9) x 3V: the reference, fast up to a few hundred vertices.
* ``"sparse"``: the same kernel without a dense factorisation of the whole matrix
  (:mod:`rigidfold.mechanism.sparse`): for large patterns.
* ``"frame"``: the paper's way, the right singular vectors of the frame compatibility matrix
  S (6m x (6n - 6 + h)) for zero singular values. Slow for large patterns; a check.

``"auto"`` (the default) takes ``"sparse"`` from ``Settings.mechanism.sparse_analysis_vertices``
vertices on and ``"kinematic"`` below. All return H with orthonormal columns spanning ker(S)
in the frame's v-space, so the pseudo stiffness matrix and everything derived from it
(Sections 4.2, 5) are the paper's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.errors import RigidfoldError
from rigidfold.frame import FrameModel
from rigidfold.mechanism import kinematics
from rigidfold.mechanism.sparse import row_scale, sparse_analysis_bytes, sparse_kernel
from rigidfold.mesh import CreasePattern

METHODS = ("auto", "kinematic", "sparse", "frame")


@dataclass(frozen=True, eq=False)
class Mechanism:
    """Infinitesimal mechanisms of a polyhedron's frame model.

    frame : FrameModel
    basis : (6n - 6 + h, d) float64 array, or a callable returning it: an orthonormal basis
        H of ker(S) (Eq. 17), built on first use
    H_phi : (h, d) float64, its hinge-rotation rows (Eq. 18); row j is free crease hinges[j]
    rank_values : (k,) singular values (or |R_ii| of a pivoted QR, or the Ritz values of the
        sparse method) of the matrix whose kernel was taken, decreasing
    rank_scale : float, the value the rank threshold multiplies (the largest of
        ``rank_values``; for the sparse method the matrix's largest row norm)
    rank : int
    locked : (h,) bool, per hinge (free crease): no rotation in any mode although folded
    settings : Settings
    """

    frame: FrameModel
    basis: np.ndarray | Callable[[], np.ndarray]
    H_phi: np.ndarray
    rank_values: np.ndarray
    rank_scale: float
    rank: int
    locked: np.ndarray
    settings: Settings

    @cached_property
    def H(self) -> np.ndarray:
        """(6n - 6 + h, d) orthonormal mechanism modes, H^T H = I (Eq. 17)."""
        return self.basis() if callable(self.basis) else self.basis

    @property
    def pattern(self) -> CreasePattern:
        return self.frame.pattern

    @property
    def dof(self) -> int:
        """d = 6n - s + h - rank(S) (Eq. 16)."""
        return self.H_phi.shape[1]

    @property
    def hinges(self) -> np.ndarray:
        """(h,) edge indices of the free creases, in the order of H_phi's rows."""
        return self.frame.hinges

    @property
    def H_u(self) -> np.ndarray:
        """(6n - 6, d) nodal displacement part of the modes (Eq. 18)."""
        return self.H[: self.H.shape[0] - self.frame.n_hinges]

    @cached_property
    def rotation_norms(self) -> np.ndarray:
        """(h,) norm of each hinge's rotations over all modes (0 for a locked hinge)."""
        return np.linalg.norm(self.H_phi, axis=1)

    def dof_at(self, rank_tol: float) -> int:
        """The DOF the same factorisation gives with the threshold ``rank_tol`` (at most the
        ``mechanism_rank_tol`` of :attr:`settings`): fewer by the values that lie between
        the two thresholds. With a gap count (``rank_tol`` times ``dof_gap``) this is the
        exact count, the paper's, without a second analysis."""
        tol = self.settings.mechanism.rank_tol
        if rank_tol > tol:
            raise ValueError(f"rank_tol {rank_tol!r} above the analysis's own {tol!r}")
        v = self.rank_values
        between = (v > rank_tol * self.rank_scale) & (v <= tol * self.rank_scale)
        return self.dof - int(np.count_nonzero(between))

    @property
    def locked_creases(self) -> np.ndarray:
        """Edge indices of locked free creases."""
        return self.hinges[self.locked]

    @property
    def has_lock(self) -> bool:
        return bool(self.locked.any())


@one_blas_thread()  # the same rank decisions on every machine, as in generate
def analyze(
    pattern: CreasePattern,
    *,
    method: str = "auto",
    support_face: int | None = None,
    settings: Settings = DEFAULTS,
) -> Mechanism:
    """Mechanism analysis of a polyhedron (Section 4.1).

    pattern : the shape, with its fixed creases; method : one of ``METHODS`` (see the
    module's text). A shape whose analysis would need more than
    ``settings.limits.max_analysis_bytes`` is refused (ValueError) before anything is built.
    """
    method = chosen_method(pattern, method, settings)
    check_analysis_size(pattern, settings, method)
    frame = FrameModel.from_pattern(pattern, support_face)
    h = frame.n_hinges
    basis: np.ndarray | Callable[[], np.ndarray]
    if method == "frame":
        H, values, rank = _svd_kernel(frame.compatibility_matrix().toarray(), settings)
        H_phi, basis = H[H.shape[0] - h :], H
        scale = float(values[0]) if len(values) else 0.0
    else:
        C = kinematics.constraint_matrix(pattern, frame.support_face)
        L = kinematics.frame_map(frame)
        # H = L N R^-1 with R^T R = N^T L^T L N: orthonormal in the frame's v-space
        if method == "kinematic":
            N, values, rank = _qr_kernel(C.toarray(), settings)
            gram = N.T @ (L.T @ (L @ N))
            scale = float(values[0]) if len(values) else 0.0
        else:  # L^T L is sparse (3V x 3V): no product of L with the modes
            N, values, rank = sparse_kernel(C, settings)
            gram = N.T @ ((L.T @ L) @ N)
            scale = row_scale(C)
        R = np.linalg.cholesky(gram).T if N.shape[1] else np.zeros((0, 0))
        Rinv = scipy.linalg.solve_triangular(R, np.eye(len(R))) if len(R) else R
        H_phi = L[L.shape[0] - h :] @ N @ Rinv

        def modes() -> np.ndarray:
            return L @ N @ Rinv

        basis = modes

    locked = _locked(frame, H_phi, settings)
    return Mechanism(frame, basis, H_phi, values, scale, rank, locked, settings)


def chosen_method(pattern: CreasePattern, method: str, settings: Settings = DEFAULTS) -> str:
    """The method :func:`analyze` runs for ``method`` (one of ``METHODS``): ``"auto"`` is
    ``"sparse"`` from ``settings.mechanism.sparse_analysis_vertices`` vertices on, else
    ``"kinematic"``."""
    if method not in METHODS:
        raise RigidfoldError(
            f"unknown mechanism method {method!r} (choose from {', '.join(METHODS)})"
        )
    if method != "auto":
        return method
    return (
        "sparse"
        if pattern.n_vertices >= settings.mechanism.sparse_analysis_vertices
        else "kinematic"
    )


def analysis_bytes(rows: int, cols: int) -> int:
    """Memory (bytes) of the dense kernel of a rows x cols matrix as :func:`analyze` computes
    it: the matrix and the full factorisation of its transpose (Q or Vt, cols x cols, and R or
    the singular values), float64."""
    return 8 * (cols * cols + 2 * rows * cols)


def analysis_memory(pattern: CreasePattern, method: str, settings: Settings = DEFAULTS) -> int:
    """Memory (bytes) that :func:`analyze` with ``method`` (one of ``METHODS``) would need for
    ``pattern``, estimated from its sizes alone: :func:`analysis_bytes` of the matrix that a
    dense method factorises, :func:`~rigidfold.mechanism.sparse.sparse_analysis_bytes` for
    the sparse one."""
    method = chosen_method(pattern, method, settings)
    rows = pattern.n_edges + int(pattern.fixed.sum()) + 9
    if method == "sparse":
        return sparse_analysis_bytes(pattern.n_vertices, rows, pattern.generic_dof, settings)
    if method == "kinematic":
        return analysis_bytes(rows, 3 * pattern.n_vertices)
    nodes = pattern.n_edges + pattern.n_faces  # frame: S is 6m x (6n - 6 + h), m = 3F
    return analysis_bytes(18 * pattern.n_faces, 6 * nodes - 6 + len(pattern.free_creases))


def check_analysis_size(
    pattern: CreasePattern, settings: Settings = DEFAULTS, method: str = "auto"
) -> None:
    """One-line ValueError when :func:`analyze` of ``pattern`` with ``method`` (by default
    the one ``generate`` uses) would need more than ``settings.limits.max_analysis_bytes``
    (:func:`analysis_memory`); ``generate`` calls it before its first solve."""
    need = analysis_memory(pattern, method, settings)
    if need > settings.limits.max_analysis_bytes:
        raise RigidfoldError(
            f"the mechanism analysis of {pattern.n_vertices} vertices and {pattern.n_edges} "
            f"edges needs about {need / 2**30:.3g} GiB, more than the limit of "
            f"{settings.limits.max_analysis_bytes / 2**30:.3g} GiB "
            "(Settings.limits.max_analysis_bytes): "
            "use a coarser pattern"
        )


def _svd_kernel(A: np.ndarray, settings: Settings) -> tuple[np.ndarray, np.ndarray, int]:
    """Orthonormal kernel basis of A by SVD, with rank relative to the largest singular value."""
    _, sv, vt = scipy.linalg.svd(A, full_matrices=True, lapack_driver="gesdd")
    rank = int(np.sum(sv > settings.mechanism.rank_tol * sv[0])) if len(sv) else 0
    return vt[rank:].T.copy(), sv, rank


def _qr_kernel(A: np.ndarray, settings: Settings) -> tuple[np.ndarray, np.ndarray, int]:
    """Kernel basis of A from a column-pivoted QR of A^T (rank-revealing).

    With A^T P = Q R, range(A^T) is spanned by the first r columns of Q and the kernel of A by
    the remaining ones. |R_ii| decreases; r counts those above ``mechanism_rank_tol`` times
    |R_00|.
    """
    q, r, _ = scipy.linalg.qr(A.T, pivoting=True, mode="full")
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > settings.mechanism.rank_tol * diag[0])) if len(diag) else 0
    return q[:, rank:], diag, rank


def _locked(frame: FrameModel, H_phi: np.ndarray, settings: Settings) -> np.ndarray:
    """Free creases that rotate in no mode while their two triangles are not coplanar."""
    folded = np.abs(frame.pattern.fold_angles[frame.hinges]) > settings.geometry.flat_angle
    if H_phi.shape[1] == 0:
        return folded
    norms = np.linalg.norm(H_phi, axis=1)
    still = norms <= settings.mechanism.lock_tol * max(norms.max(initial=0.0), np.finfo(float).tiny)
    return still & folded
