"""The objective of (6) as a sum of squares, ``F = |r|^2``, with the sparse Jacobian of r.

::

    r = ( 2 pi - sum_k theta_ik          for every interior vertex i      (F1 = sum r_i^2)
          sqrt(w_j) sin(rho_j)           for every interior crease j       (F2 = sum r_j^2) )

``sin^2 rho_j = |n_j1 x n_j2|^2`` for the unit normals of the two triangles at crease j, so
``|r|^2`` is exactly the F of ``rigidfold.optimize.nlp``; the signed ``sin rho`` is smooth where
the crease is flat, which ``|n_1 x n_2|`` is not. Everything is NumPy: the Jacobian in the
independent variables is the element gradients, chained through ``P = T xi + t``, as one
sparse matrix whose pattern is fixed per problem. It serves the projection solver
(``rigidfold.optimize.projection``), whose steps need J, not the Hessian.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from rigidfold.mesh import CreasePattern
from rigidfold.optimize.hessian import (
    B_ANGLE,
    angle_corners,
    coordinate_rows,
    row_cross,
    row_dot,
)
from rigidfold.optimize.variables import LinearMap


def angle_gradients(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sector angle at the first corner of triangles, and its gradient in the three corners.

    corners : (K, 3, 3) coordinates (a, b, c), the angle is the one at a, between b - a and
    c - a.  ->  theta (K,), grad (K, 9) in (a, b, c).
    """
    u, v = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    uu, vv, c = row_dot(u, u), row_dot(v, v), row_dot(u, v)
    s = np.sqrt(np.maximum(uu * vv - c * c, 0.0))  # |u x v|
    r2 = uu * vv
    # grad theta = (c grad s - s grad c) / r2, grad s = (u |v|^2 - c v, v |u|^2 - c u) / s
    gu = (c[:, None] * (u * vv[:, None] - c[:, None] * v) / s[:, None] - s[:, None] * v) / r2[
        :, None
    ]
    gv = (c[:, None] * (v * uu[:, None] - c[:, None] * u) / s[:, None] - s[:, None] * u) / r2[
        :, None
    ]
    return np.arctan2(s, c), np.concatenate([gu, gv], axis=1) @ B_ANGLE


def fold_angle_gradients(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed fold angles of creases and their gradients, in closed form.

    corners : (K, 4, 3) coordinates of each crease's stencil (u, v, a, b) (see
    ``CreasePattern.crease_stencils``).  ->  rho (K,) (valley positive, as
    ``CreasePattern.fold_angles``), grad (K, 12) in (u, v, a, b).

    The gradient is the classical one of a dihedral angle (e.g. Liu and Paulino's bar-and-hinge
    model): the wing vertices move along their triangles' normals, by the edge length over twice
    the triangle's area, and the ends take what keeps it invariant to rigid motions.
    """
    pu, pv, pa, pb = (corners[:, k] for k in range(4))
    e = pv - pu
    ee = row_dot(e, e)
    na = row_cross(e, pa - pu)  # left triangle (u, v, a)
    nb = row_cross(pu - pv, pb - pv)  # right triangle (v, u, b)
    t = e / np.sqrt(ee)[:, None]
    rho = np.arctan2(-row_dot(row_cross(na, nb), t), row_dot(na, nb))
    length = np.sqrt(ee)
    ga = (length / row_dot(na, na))[:, None] * na
    gb = (length / row_dot(nb, nb))[:, None] * nb
    sa = (row_dot(pa - pu, e) / ee)[:, None]  # where a projects onto the crease, 0 at u, 1 at v
    sb = (row_dot(pb - pu, e) / ee)[:, None]
    gu = -(1 - sa) * ga - (1 - sb) * gb
    gv = -sa * ga - sb * gb
    return rho, np.concatenate([gu, gv, ga, gb], axis=1)


class Residuals:
    """r(xi, w) of problem (6) for one pattern and linear map, with F = |r|^2.

    Rows ``0..I-1`` are the interior vertices (``pattern.interior_vertices``), then one row per
    interior crease with ``w > 0``, in crease order.
    """

    def __init__(self, pattern: CreasePattern, lmap: LinearMap) -> None:
        self.pattern, self.map = pattern, lmap
        self.T = lmap.T.tocsr()
        V = pattern.n_vertices
        corners = angle_corners(pattern.faces)
        inner = pattern.interior_vertices
        row_of = np.full(V, -1)
        row_of[inner] = np.arange(len(inner))
        at_inner = row_of[corners[:, 0]] >= 0
        self.n_inner = len(inner)
        self._angle_corners = corners[at_inner]  # (A, 3): angles that count in F1
        self._angle_row = row_of[corners[at_inner, 0]]
        # their rows and columns in the Jacobian in P = (x_1..x_V, y_1..y_V, z_1..z_V)
        self._angle_J_rows = np.repeat(self._angle_row, 9)
        self._angle_J_cols = coordinate_rows(self._angle_corners, V).ravel()
        self.interior = pattern.interior_edges
        self._stencils = pattern.crease_stencils(self.interior)  # (Ei, 4)

    def __call__(
        self, xi: np.ndarray, w: np.ndarray, jacobian: bool = True
    ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """r (m,) at xi (n,) with fixed-crease weights w (E,), and its Jacobian (m, n) in xi."""
        V = self.pattern.n_vertices
        X = (self.T @ xi + self.map.t).reshape(3, V).T
        theta, g_theta = angle_gradients(X[self._angle_corners])
        defect = 2 * np.pi - np.bincount(self._angle_row, weights=theta, minlength=self.n_inner)
        weight = np.asarray(w, dtype=float)[self.interior]
        on = np.flatnonzero(weight > 0)
        rho, g_rho = fold_angle_gradients(X[self._stencils[on]])
        root = np.sqrt(weight[on])
        r = np.concatenate([defect, root * np.sin(rho)])
        if not jacobian:
            return r, None
        cols_r = coordinate_rows(self._stencils[on], V).ravel()
        rows = np.concatenate(
            [self._angle_J_rows, self.n_inner + np.repeat(np.arange(len(on)), 12)]
        )
        cols = np.concatenate([self._angle_J_cols, cols_r])
        vals = np.concatenate([-g_theta.ravel(), ((root * np.cos(rho))[:, None] * g_rho).ravel()])
        J_P = sp.csr_matrix((vals, (rows, cols)), shape=(len(r), 3 * V))
        return r, (J_P @ self.T).tocsr()
