"""Independent variables of problem (6): eliminating the linear constraints (7)-(9).

All vertex coordinates form ``P = (x_1..x_V, y_1..y_V, z_1..z_V)`` (3V,). The linear
constraints of the paper are assembled into one sparse system ``Gamma P = c`` (Eq. 10):

* (7) every non-corner boundary vertex stays on the straight plan side it lies on;
* (8) corners are fixed (x, y and z);
* (9) for each mirror plane, the mirror image of every vertex is the matching vertex.

A rank-revealing (column-pivoted) QR factorisation of Gamma picks ``r = rank(Gamma)``
dependent coordinates whose columns are well conditioned; the remaining ``3V - r``
coordinates are the independent variables ``xi`` (Eq. 11), and ``P = T xi + t`` with a sparse
``T``. Gamma couples only a vertex with its mirror images, so the QR is done block by block
(a few coordinates each) and the cost grows linearly with the number of vertices. Nothing
is specific to a pattern: any disc with straight plan sides and any set of vertical mirror
planes works.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.errors import RigidfoldError
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

    @cached_property
    def held_vertices(self) -> np.ndarray:
        """(k,) int64: the vertices that (7)-(9) hold completely (no coordinate depends on
        ``xi``: the corners, by (8))."""
        moves = np.diff(self.T.tocsr().indptr).reshape(3, -1).sum(axis=0) > 0
        return np.flatnonzero(~moves)

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
        mate = mirror_pairs(pattern.coords, plane, settings.geometry.symmetry_match_tol)
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

    Each constraint involves the coordinates of one vertex and its mirror images, so Gamma is
    block diagonal after permuting its rows and columns: one small block per set of
    coordinates the constraints couple (a corner, a boundary vertex, the orbit of a vertex
    under the mirror planes). Each block gets its own column-pivoted QR, with the rank
    threshold relative to the largest column norm of all of Gamma, as one QR of the whole
    Gamma would (the blocks are orthogonal to each other, so their pivot choices do not
    interact); no dense matrix larger than a block is formed. A coordinate in no constraint
    is independent.

    Raises ValueError when the constraints contradict each other (e.g. a corner's height
    breaks the symmetry).
    """
    gamma, c = assemble_constraints(pattern, planes, settings)
    m, n = gamma.shape
    if m == 0:
        return LinearMap(sp.identity(n, format="csr"), np.zeros(n), np.arange(n), gamma, c)
    largest = float(np.sqrt(np.asarray(gamma.multiply(gamma).sum(axis=0))).max())
    dep_rows, dep_cols, dep_vals = [], [], []
    t = np.zeros(n)
    independent = np.ones(n, dtype=bool)
    with one_blas_thread():  # the basis of the free variables sets the optimiser's path
        for rows, cols, block in _blocks(gamma):
            dep, const, ind, coef = _eliminate_block(block, c[rows], largest, settings)
            independent[cols[dep]] = False
            t[cols[dep]] = const
            dr, dc = np.nonzero(coef)
            dep_rows.append(cols[dep][dr])
            dep_cols.append(cols[ind][dc])
            dep_vals.append(coef[dr, dc])
    ind_all = np.flatnonzero(independent)
    column_of = np.full(n, -1)
    column_of[ind_all] = np.arange(len(ind_all))
    T = sp.coo_matrix(
        (
            np.concatenate([np.ones(len(ind_all)), *dep_vals]),
            (
                np.concatenate([ind_all, *dep_rows]),
                column_of[np.concatenate([ind_all, *dep_cols])],
            ),
        ),
        shape=(n, len(ind_all)),
    )
    return LinearMap(T.tocsr(), t, ind_all.astype(np.int64), gamma, c)


def _blocks(gamma: sp.csr_matrix) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The diagonal blocks of Gamma (m, 3V): the sets of rows and columns coupled by its entries.

    yields : rows (k,) and cols (l,), both ascending, and the dense block (k, l)
    ``Gamma[rows][:, cols]``, for every block with at least one row.
    """
    m, n = gamma.shape
    link = sp.bmat([[None, gamma], [gamma.T, None]], format="csr")  # rows, then columns
    n_blocks, label = connected_components(link, directed=False)
    row_label, col_label = label[:m], label[m:]
    row_order = np.argsort(row_label, kind="stable")
    col_order = np.argsort(col_label, kind="stable")
    row_start = np.searchsorted(row_label[row_order], np.arange(n_blocks + 1))
    col_start = np.searchsorted(col_label[col_order], np.arange(n_blocks + 1))
    local_row = np.empty(m, dtype=np.int64)
    local_row[row_order] = np.arange(m) - row_start[row_label[row_order]]
    local_col = np.empty(n, dtype=np.int64)
    local_col[col_order] = np.arange(n) - col_start[col_label[col_order]]
    coo = gamma.tocoo()
    entry_block = row_label[coo.row]
    entries = np.argsort(entry_block, kind="stable")
    entry_start = np.searchsorted(entry_block[entries], np.arange(n_blocks + 1))
    for b in np.flatnonzero(np.diff(row_start)):
        rows = row_order[row_start[b] : row_start[b + 1]]
        cols = col_order[col_start[b] : col_start[b + 1]]
        block = np.zeros((len(rows), len(cols)))
        e = entries[entry_start[b] : entry_start[b + 1]]
        block[local_row[coo.row[e]], local_col[coo.col[e]]] = coo.data[e]
        yield rows, cols, block


def _eliminate_block(
    block: np.ndarray, rhs: np.ndarray, largest: float, settings: Settings
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Dependent coordinates of one block of Gamma P = c from a column-pivoted QR.

    block : (k, l) dense block of Gamma; rhs : (k,) its part of c; largest : the largest
    column norm of Gamma (the rank threshold is relative to it).
    returns : dep (r,) and ind (l - r,) local columns, const (r,) and coef (r, l - r) with
    ``P[dep] = coef @ P[ind] + const``.
    """
    q, r, piv = scipy.linalg.qr(block, pivoting=True)  # full q: all of rhs is checked
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > settings.solver.linear_rank_tol * largest))
    qc = q.T @ rhs
    if np.abs(qc[rank:]).max(initial=0.0) > settings.solver.constraint_tol:
        raise RigidfoldError(
            "the boundary, corner and symmetry constraints (7)-(9) contradict each other for "
            "this shape (is the target surface symmetric about the chosen planes?)"
        )
    dep, ind = piv[:rank], np.sort(piv[rank:])
    col_of = np.empty(block.shape[1], dtype=np.int64)
    col_of[piv] = np.arange(block.shape[1])
    solve = scipy.linalg.solve_triangular
    coef = -solve(r[:rank, :rank], r[:rank, col_of[ind]])
    const = solve(r[:rank, :rank], qc[:rank])
    coef[np.abs(coef) < settings.solver.map_prune_tol] = 0.0
    const[np.abs(const) < settings.solver.map_prune_tol] = 0.0
    return dep, const, ind, coef
