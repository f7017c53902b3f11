"""Independent variables of problem (6): eliminating the linear constraints (7)-(9).

All vertex coordinates form ``P = (x_1..x_V, y_1..y_V, z_1..z_V)`` (3V,). The linear
constraints of the paper are assembled into one sparse system ``Gamma P = c`` (Eq. 10):

* (7) every non-corner boundary vertex stays on the straight plan side it lies on;
* (8) corners are fixed (x, y and z);
* (9) for each mirror plane, the mirror image of every vertex is the matching vertex.

A rank-revealing (column-pivoted) QR factorisation of Gamma picks ``r = rank(Gamma)``
dependent coordinates whose columns are well conditioned; the remaining ``3V - r``
coordinates are the independent variables ``xi`` (Eq. 11), and ``P = T xi + t`` with a sparse
``T``. Nothing is specific to a pattern: any disc with straight plan sides and any set of
vertical mirror planes works.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import mirror_pairs
from rigidfold.protocols import SymmetryPlane


@dataclass(frozen=True, eq=False)
class LinearMap:
    """Affine map from independent variables to all vertex coordinates, ``P = T xi + t``.

    T : (3V, n) scipy.sparse.csr_matrix
    t : (3V,) float64
    independent : (n,) int, positions in P of the independent coordinates (``P[independent]
        == xi``)
    gamma : (m, 3V) scipy.sparse.csr_matrix and c : (m,) -- the constraints Gamma P = c.
    """

    T: sp.csr_matrix
    t: np.ndarray
    independent: np.ndarray
    gamma: sp.csr_matrix
    c: np.ndarray

    @property
    def n_variables(self) -> int:
        return self.T.shape[1]

    @property
    def n_vertices(self) -> int:
        return self.T.shape[0] // 3

    def expand(self, xi: np.ndarray) -> np.ndarray:
        """Vertex coordinates (V, 3) from independent variables (n,)."""
        p = self.T @ np.asarray(xi, dtype=float) + self.t
        return p.reshape(3, -1).T.copy()

    def restrict(self, coords: np.ndarray) -> np.ndarray:
        """Independent variables (n,) taken from vertex coordinates (V, 3)."""
        return np.asarray(coords, dtype=float).T.ravel()[self.independent].copy()

    def residual(self, coords: np.ndarray) -> float:
        """max |Gamma P - c| of a shape: how far it is from satisfying (7)-(9)."""
        if self.gamma.shape[0] == 0:
            return 0.0
        p = np.asarray(coords, dtype=float).T.ravel()
        return float(np.abs(self.gamma @ p - self.c).max())


def assemble_constraints(
    pattern: CreasePattern, planes: Sequence[SymmetryPlane] = (), settings: Settings = DEFAULTS
) -> tuple[sp.csr_matrix, np.ndarray]:
    """Gamma (m, 3V) and c (m,) of constraints (7), (8) and (9) for the pattern's shape."""
    V = pattern.n_vertices
    X, Y, Z = 0, V, 2 * V  # offsets of x, y and z in P
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    rhs: list[float] = []

    def add(entries: list[tuple[int, float]], value: float) -> None:
        r = len(rhs)
        for col, val in entries:
            rows.append(r)
            cols.append(col)
            vals.append(val)
        rhs.append(value)

    for side in pattern.boundary_sides:  # (7)
        b1, b2, b3 = side.line
        for i in side.inner:
            add([(X + i, b1), (Y + i, b2)], -b3)
    for i in pattern.corners:  # (8)
        for off in (X, Y, Z):
            add([(off + i, 1.0)], float(pattern.coords[i, off // V]))
    for plane in planes:  # (9)
        norm = np.hypot(plane.a, plane.b)
        a, b, c = plane.a / norm, plane.b / norm, plane.c / norm
        mate = mirror_pairs(pattern.coords, plane, settings.symmetry_match_tol)
        for i, j in enumerate(mate):
            # reflection of vertex i is vertex j: p_j = p_i - 2 (a x_i + b y_i + c) (a, b, 0)
            add([(X + j, 1.0), (X + i, -(1 - 2 * a * a)), (Y + i, 2 * a * b)], -2 * a * c)
            add([(Y + j, 1.0), (Y + i, -(1 - 2 * b * b)), (X + i, 2 * a * b)], -2 * b * c)
            if i != j:
                add([(Z + j, 1.0), (Z + i, -1.0)], 0.0)
    gamma = sp.coo_matrix((vals, (rows, cols)), shape=(len(rhs), 3 * V)).tocsr()
    gamma.sum_duplicates()
    return gamma, np.asarray(rhs, dtype=float)


def build_linear_map(
    pattern: CreasePattern, planes: Sequence[SymmetryPlane] = (), settings: Settings = DEFAULTS
) -> LinearMap:
    """Eliminate (7)-(9) from the pattern's coordinates (Eqs. 10-11).

    Raises ValueError when the constraints contradict each other (e.g. a corner's height
    breaks the symmetry).
    """
    gamma, c = assemble_constraints(pattern, planes, settings)
    n = gamma.shape[1]
    if gamma.shape[0] == 0:
        return LinearMap(sp.identity(n, format="csr"), np.zeros(n), np.arange(n), gamma, c)
    with one_blas_thread():  # the basis of the free variables sets the optimiser's path
        q, r, piv = scipy.linalg.qr(gamma.toarray(), mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > settings.linear_rank_tol * diag[0]))
    qc = q.T @ c
    if np.abs(qc[rank:]).max(initial=0.0) > settings.constraint_tol:
        raise ValueError(
            "the boundary, corner and symmetry constraints (7)-(9) contradict each other for "
            "this shape (is the target surface symmetric about the chosen planes?)"
        )
    dep, ind = piv[:rank], np.sort(piv[rank:])
    r11 = r[:rank, :rank]
    # columns of r in pivot order; independent columns re-sorted to match `ind`
    col_of = np.empty(n, dtype=np.int64)
    col_of[piv] = np.arange(n)
    r12 = r[:rank, col_of[ind]]
    solve = scipy.linalg.solve_triangular
    dep_from_ind = -solve(r11, r12)  # (rank, n_ind)
    dep_const = solve(r11, qc[:rank])
    dep_from_ind[np.abs(dep_from_ind) < settings.map_prune_tol] = 0.0
    dep_const[np.abs(dep_const) < settings.map_prune_tol] = 0.0
    dr, dc = np.nonzero(dep_from_ind)
    T = sp.coo_matrix(
        (
            np.concatenate([np.ones(len(ind)), dep_from_ind[dr, dc]]),
            (np.concatenate([ind, dep[dr]]), np.concatenate([np.arange(len(ind)), dc])),
        ),
        shape=(n, len(ind)),
    )
    t = np.zeros(n)
    t[dep] = dep_const
    return LinearMap(T.tocsr(), t, ind.astype(np.int64), gamma, c)
