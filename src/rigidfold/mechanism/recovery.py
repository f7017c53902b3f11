"""The recover steps of the path tracer (:mod:`rigidfold.mechanism.path`): where the sparse
continuation of a rigid-folding path stalls (its step halved below ``path_min_step``), the
ways it goes on, each from one SVD of the constraint Jacobian J at the last point x:

* :func:`reduce_rows`: a 1-DOF trace in the projection form drops the redundant rows of
  self-stressed constraints and goes on by the square system ``[J_rows; t^T]``;
* :func:`hold_near_flexes`: where that stalls too, J's near flexes are held and the rows of
  their near self-stresses dropped as well;
* :func:`escape`: one dense step past a singular or bifurcation point, along the branch
  continued, a branch of the bifurcation equation (:func:`_branches`) or towards flat.

Each is limited to ``mechanism_second_order_vertices`` vertices (the dense SVD; that of
:func:`reduce_rows` is sparse from ``mechanism_sparse_analysis_vertices`` vertices on).
"""

from __future__ import annotations

import math
import time

import numpy as np

from rigidfold.config import Settings
from rigidfold.mechanism import rigid_folding
from rigidfold.mechanism.rigid_folding import (
    RigidFoldingConstraints,
    System,
    independent_rows,
    rows_without_stresses,
)


def may_reduce(cons: RigidFoldingConstraints, settings: Settings) -> bool:
    """The redundant rows of a 1-DOF shape are dropped where its projection continuation
    stalls (``path_reduce``), up to ``mechanism_second_order_vertices`` vertices (one
    SVD)."""
    return (
        settings.path.reduce and cons.pattern.n_vertices <= settings.mechanism.second_order_vertices
    )


def reduce_rows(
    cons: RigidFoldingConstraints, x: np.ndarray, t: np.ndarray, settings: Settings
) -> tuple[np.ndarray, System, float] | None:
    """(rows (n - 1,) int, the factored ``[J_rows; t^T]`` at x, J's smallest singular value
    over its largest there): the independent rows of the constraints of a 1-DOF shape at x
    (:func:`rigidfold.mechanism.rigid_folding.independent_rows`, sparse from
    ``mechanism_sparse_analysis_vertices`` vertices on) and the square augmented system
    they make with the tangent t (n,); None where it is exactly singular."""
    large = cons.pattern.n_vertices >= settings.mechanism.sparse_analysis_vertices
    rows, sigma = independent_rows(cons.jacobian(x)[0], 1, settings if large else None)
    try:
        return rows, System(*cons.jacobian(x), "augmented", t, settings, rows), sigma
    except RuntimeError:
        return None


def hold_near_flexes(
    cons: RigidFoldingConstraints, x: np.ndarray, t: np.ndarray, settings: Settings
) -> tuple[np.ndarray, np.ndarray, System, tuple[float, float]] | None:
    """Where the square system of the independent rows stalls too, at x: J's near flexes
    there (right singular vectors of singular values below ``path_escape_tol`` of the
    largest, but for the smallest, the path's own) are held, ``frozen`` (n, k), and the rows
    of their near self-stresses dropped as well (``[J_rows; frozen^T; t^T]`` square): their
    residual is then left to the Gauss-Newton corrector's least squares and checked
    against ``path_tol`` like that of the exact self-stresses, rather than removed by
    moves of residual / sigma along the near flexes, which Newton's method cannot make.
    Returns (rows, frozen, the factored system at x, (the smallest, the largest) of those
    singular values over the largest one), or None (no near flex, an exactly singular
    system, or more than ``mechanism_second_order_vertices`` vertices)."""
    if cons.pattern.n_vertices > settings.mechanism.second_order_vertices:
        return None
    J, J_rho = cons.jacobian(x)
    U, s, vt = np.linalg.svd(J.toarray(), full_matrices=True)
    values = np.zeros(cons.n)  # J's n singular values: zeros past the m of a J of m < n rows
    values[: min(len(s), cons.n)] = s[: cons.n]
    near = np.flatnonzero(values[:-1] <= settings.path.escape_tol * values[0])
    if not len(near):
        return None
    frozen = vt[near].T
    rows = rows_without_stresses(U, cons.n, 1 + len(near))
    try:
        system = System(J, J_rho, "augmented", t, settings, rows, frozen)
    except RuntimeError:
        return None
    return (
        rows,
        frozen,
        system,
        (float(values[near].min() / s[0]), float(values[near].max() / s[0])),
    )


def escape(
    cons: RigidFoldingConstraints,
    x: np.ndarray,
    t: np.ndarray | None,
    rho: np.ndarray,
    first: float,
    mode: str,
    settings: Settings,
    rows: np.ndarray | None = None,
    frozen: np.ndarray | None = None,
    deadline: float | None = None,
) -> tuple[np.ndarray, np.ndarray, System, str] | None:
    """One step past the point x where the sparse continuation stalled (see
    ``Settings.path.escape_tol``): the null space N of J at x from a dense SVD; the
    directions tried are the last tangent's part in N (the branch continued), where N has
    two or more columns the branches of the bifurcation equation in the plane of J's two
    smallest singular vectors, the path's and its nearest flex (see :func:`_branches`:
    branch switching), and the part of the steepest descent of the folding measure (a branch
    towards flat); each step of ``first``, a quarter, a sixteenth. A 1-DOF trace corrects it
    by the square system ``[J_rows; d^T]`` of the independent rows (dropped here if the
    constraints are self-stressed and ``rows`` is None) with the Gauss-Newton corrector of
    :func:`rigidfold.mechanism.rigid_folding.correct`; a trace of more DOF by Gauss-Newton
    with the pseudo-inverse truncated at ``mechanism_rank_tol``; until every constraint
    holds to ``path_tol``. Returns (the point, its direction, the factored system there, the
    mode: "projection" where the augmented matrix is singular), or None (no step converged,
    or more than ``mechanism_second_order_vertices`` vertices, or ``deadline``, a time of
    ``time.monotonic()``, passed: each corrector iteration is a dense least-squares solve)."""

    def late() -> bool:
        return deadline is not None and time.monotonic() > deadline

    if cons.pattern.n_vertices > settings.mechanism.second_order_vertices:
        return None
    J, J_rho = cons.jacobian(x)
    U, s, vt = np.linalg.svd(J.toarray(), full_matrices=True)
    values = np.zeros(cons.n)
    values[: len(s)] = s
    small = values <= settings.path.escape_tol * values[0]
    N = vt[small].T
    if not N.shape[1]:
        return None
    square = mode != "descent"
    tries = [] if t is None else [N @ (N.T @ t)]
    if square and N.shape[1] >= 2:
        # the plane of the two smallest singular values (the path's and a near flex)
        plane = vt[cons.n - 2 :].T
        stresses = np.hstack([U[:, : len(s)][:, small[: len(s)]], U[:, len(s) :]])
        tries += _branches(cons, x, plane, stresses, rho, settings)
    tries.append(N @ (N.T @ -(J_rho.T @ rho)))
    if square and rows is None and cons.n_rows > cons.n - 1:
        rows = rows_without_stresses(U, cons.n, 1)
    wide = settings.with_(path_corrector_iter=3 * settings.path.corrector_iter)
    done: list[np.ndarray] = []
    for d in tries:
        size = float(np.linalg.norm(d))
        if not size > 0:
            continue
        d = d / size
        if any(float(d @ e) > math.cos(settings.path.max_turn) for e in done):
            continue  # tried already
        done.append(d)
        for h in (first, first / 4, first / 16):
            if late():
                return None
            if square:
                # the module's corrector (the continuation's, ``correct``, may be swapped)
                y, ok, _, system = rigid_folding.correct(
                    cons, x + h * d, "augmented", d, wide, rows, frozen
                )
                if ok and system is not None and float((y - x) @ d) > 0.5 * h:
                    return y, d, system, "augmented"
                continue
            y = x + h * d
            for _ in range(3 * settings.path.corrector_iter):
                if late():
                    return None
                c = cons.residual(y)
                if not np.isfinite(c).all():
                    break
                if float(np.abs(c).max()) <= settings.path.tol:
                    chord = y - x
                    if float(chord @ d) <= 0.5 * h:  # slid back towards x
                        break
                    Jy, Jy_rho = cons.jacobian(y)
                    for kind in (mode, "projection"):
                        try:
                            return y, d, System(Jy, Jy_rho, kind, d, settings, rows), kind
                        except RuntimeError:  # an exactly singular augmented matrix
                            continue
                    return None
                A = np.vstack([cons.jacobian(y)[0].toarray(), d])
                dy = np.linalg.lstsq(A, np.r_[-c, 0.0], rcond=settings.mechanism.rank_tol)[0]
                y = y + dy
    return None


def _branches(
    cons: RigidFoldingConstraints,
    x: np.ndarray,
    N: np.ndarray,
    W: np.ndarray,
    rho: np.ndarray,
    settings: Settings,
) -> list[np.ndarray]:
    """Branch directions (n,) at a simple bifurcation point x: N (n, 2) spans the null space
    of J there, W (m, k) its (near) self-stresses; a branch leaves x along d in N with
    ``w^T c''(d, d) = 0`` for every stress w (the algebraic bifurcation equation, Allgower &
    Georg ch. 8), c'' by central differences of J along N (step sqrt(``path_tol``), so that
    its error is of the order of the tolerance). The roots are the deepest minima of the sum
    of squares over half a circle of directions (a degree apart); each is returned with both
    signs, those that lower the folding measure first."""
    eps = math.sqrt(settings.path.tol)
    D = []
    for j in range(2):
        Jp = cons.jacobian(x + eps * N[:, j])[0]
        Jm = cons.jacobian(x - eps * N[:, j])[0]
        D.append(W.T @ ((Jp - Jm) @ N) / (2 * eps))  # (k, 2): w^T c''(n_i, n_j)
    Q = np.stack([np.column_stack([D[0][:, i], D[1][:, i]]) for i in range(2)], axis=1)
    Q = (Q + Q.transpose(0, 2, 1)) / 2  # (k, 2, 2)
    theta = np.radians(np.arange(180.0))
    a = np.stack([np.cos(theta), np.sin(theta)])  # (2, 180)
    f = (np.einsum("ia,kij,ja->ka", a, Q, a) ** 2).sum(axis=0)
    minima = np.flatnonzero((f <= np.roll(f, 1)) & (f <= np.roll(f, -1)))
    best = minima[np.argsort(f[minima])][:2]
    out = [sign * (N @ a[:, i]) for i in best for sign in (1.0, -1.0)]
    J_rho = cons.jacobian(x)[1]
    return sorted(out, key=lambda d: float(rho @ (J_rho @ d)))
