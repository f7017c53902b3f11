"""The rigid-folding constraints of a shape and the linear algebra of their continuation.

A triangulated shape folds rigidly while ``c(x) = 0``: every edge keeps its length, every
fixed crease its fold angle, and a support triangle stays where it is (six linear rows, the
gauge). :class:`RigidFoldingConstraints` evaluates c and its sparse Jacobian J on a sparsity
pattern built once, in coordinates scaled by the mean edge length; :class:`System` factors
(SuperLU) the one linear system a continuation step needs, in one of three forms:

* ``"augmented"``: ``A = [J; t^T]`` for a 1-DOF shape (J has 3V - 1 independent rows): its
  solve with ``e_n`` is the next tangent, with ``[-c; 0]`` a pseudo-arclength correction, and
  the sign of det A tells a bifurcation (Allgower & Georg, ch. 2 and 8); a self-stressed J
  takes this form too with its redundant rows dropped (:func:`independent_rows`), and then
  a Gauss-Newton correction (see :class:`System`);
* ``"projection"``: ``K = [[I, J^T], [J, -delta I]]`` for a 1-DOF shape whose constraints
  are self-stressed (redundant rows, as a Miura-ori's rigid quads): the tangent is the
  projection of the last one onto the null space of J, the correction of least norm;
* ``"descent"``: ``K = [[J_rho^T J_rho + mu I, J^T], [J, -delta I]]`` for more DOF: the
  Gauss-Newton direction that takes the free fold angles rho towards 0 within the
  mechanism, ``min |rho + J_rho d|^2 + mu |d|^2`` subject to ``J d = 0``, and corrections of
  least norm in that metric.

:func:`correct` is the corrector: chord steps on the factors of the latest iterate,
refactored where they stop contracting.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.config import Settings
from rigidfold.mechanism.sparse import largest_singular, smallest_singular
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import angle_change
from rigidfold.optimize.residuals import fold_angle_gradients


class RigidFoldingConstraints:
    """c(x) and its sparse Jacobian for one shape, in units of the mean edge length.

    Rows: the edge lengths (E), the fixed creases' fold angles (n_fix), and a gauge of six
    linear rows that hold the support triangle ``(a, b, c)`` still: a's three coordinates, b's
    two across the edge ab, c's one across the triangle's plane. x is the vertex coordinates
    over the mean edge length, (3V,). The sparsity pattern is built once; an evaluation fills
    in its values.
    """

    def __init__(self, pattern: CreasePattern, support_face: int) -> None:
        self.pattern = pattern
        self.scale = float(np.mean(pattern.edge_lengths))
        self.x0 = pattern.coords.ravel() / self.scale
        self.L0 = pattern.edge_lengths / self.scale
        fixed, free = pattern.fixed_creases, pattern.free_creases
        self.n_fixed, self.free = len(fixed), free
        self.rho_fixed0 = pattern.fold_angles[fixed]
        self.fixed_stencils = pattern.crease_stencils(fixed)
        self.free_stencils = pattern.crease_stencils(free)
        a, b, c = (int(v) for v in pattern.faces[support_face])
        p = pattern.coords
        e1 = (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])
        normal = np.cross(p[b] - p[a], p[c] - p[a])
        normal /= np.linalg.norm(normal)
        e2 = np.cross(normal, e1)
        c3 = np.arange(3)
        self.gauge_rows = np.concatenate([c3, [3, 3, 3, 4, 4, 4, 5, 5, 5]])
        self.gauge_cols = np.concatenate([3 * a + c3, 3 * b + c3, 3 * b + c3, 3 * c + c3])
        self.gauge_vals = np.concatenate([np.ones(3), e2, normal, normal])
        E, nf = len(pattern.edges), self.n_fixed
        self.n_rows = E + nf + 6
        e = pattern.edges
        rows = [
            np.repeat(np.arange(E), 6),
            E + np.repeat(np.arange(nf), 12),
            E + nf + self.gauge_rows,
        ]
        cols = [
            np.hstack([3 * e[:, :1] + c3, 3 * e[:, 1:] + c3]).ravel(),
            (3 * self.fixed_stencils[:, :, None] + c3).reshape(-1),
            self.gauge_cols,
        ]
        self._J = _Pattern(np.concatenate(rows), np.concatenate(cols), (self.n_rows, self.n))
        self._Jr = _Pattern(
            np.repeat(np.arange(len(free)), 12),
            (3 * self.free_stencils[:, :, None] + c3).reshape(-1),
            (len(free), self.n),
        )
        self.gauge0 = self._gauge(self.x0)

    @property
    def n(self) -> int:
        """Unknowns: 3V."""
        return len(self.x0)

    def _gauge(self, x: np.ndarray) -> np.ndarray:
        return np.bincount(self.gauge_rows, self.gauge_vals * x[self.gauge_cols], minlength=6)

    def residual(self, x: np.ndarray) -> np.ndarray:
        """c(x) (m,): length errors, fixed-crease angle changes (in (-pi, pi]), gauge (not
        finite where a triangle has collapsed)."""
        X = x.reshape(-1, 3)
        e = self.pattern.edges
        length = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            rho_fixed = fold_angle_gradients(X[self.fixed_stencils])[0]
        turn = angle_change(rho_fixed, self.rho_fixed0)  # continuous through 180 degrees
        return np.concatenate([length - self.L0, turn, self._gauge(x) - self.gauge0])

    def free_angles(self, x: np.ndarray) -> np.ndarray:
        """The free creases' fold angles (n_free,) at x, radians."""
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return fold_angle_gradients(x.reshape(-1, 3)[self.free_stencils])[0]

    def jacobian(self, x: np.ndarray) -> tuple[sp.csc_matrix, sp.csc_matrix]:
        """(J (m, n), J_rho (n_free, n)) at x, both sparse CSC: the constraints' Jacobian and
        the free fold angles' gradients, in the scaled coordinates x."""
        X = x.reshape(-1, 3)
        e = self.pattern.edges
        d = X[e[:, 1]] - X[e[:, 0]]
        u = d / np.linalg.norm(d, axis=1)[:, None]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            grad_fixed = fold_angle_gradients(X[self.fixed_stencils])[1]
            grad_free = fold_angle_gradients(X[self.free_stencils])[1]
        J = self._J.fill(
            np.concatenate([np.hstack([-u, u]).ravel(), grad_fixed.ravel(), self.gauge_vals])
        )
        return J, self._Jr.fill(grad_free.ravel())

    def length_error(self, x: np.ndarray) -> float:
        """Largest |l - l0| / l0 at x."""
        X = x.reshape(-1, 3)
        e = self.pattern.edges
        length = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
        return float(np.max(np.abs(length - self.L0) / self.L0))


class _Pattern:
    """A sparse matrix's pattern (COO rows and columns, no duplicates), filled in CSC."""

    def __init__(self, rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]) -> None:
        order = sp.csc_matrix((np.arange(1, len(rows) + 1, dtype=float), (rows, cols)), shape=shape)
        self.order = order.data.astype(np.int64) - 1
        self.indices, self.indptr, self.shape = order.indices, order.indptr, shape

    def fill(self, values: np.ndarray) -> sp.csc_matrix:
        """The matrix with ``values`` given in the COO order of the pattern."""
        return sp.csc_matrix((values[self.order], self.indices, self.indptr), shape=self.shape)


class Factors:
    """Sparse LU of a square matrix, with the sign of its determinant."""

    def __init__(self, A: sp.spmatrix) -> None:
        self.lu = spla.splu(sp.csc_matrix(A), permc_spec="COLAMD")

    def solve(self, b: np.ndarray, trans: str = "N") -> np.ndarray:
        """A^-1 b (``trans`` "T": A^-T b); b (N,) or (N, k)."""
        return self.lu.solve(b, trans=trans)

    @cached_property
    def det_sign(self) -> int:
        diag = self.lu.U.diagonal()
        sign = int(np.prod(np.sign(diag)))
        return sign * _parity(self.lu.perm_r) * _parity(self.lu.perm_c)


def _parity(perm: np.ndarray) -> int:
    """+1 for an even permutation, -1 for an odd one."""
    seen = np.zeros(len(perm), bool)
    sign = 1
    for start in range(len(perm)):
        if seen[start]:
            continue
        length, k = 0, start
        while not seen[k]:
            seen[k] = True
            k = perm[k]
            length += 1
        if length % 2 == 0:
            sign = -sign
    return sign


class System:
    """The factored linear system of one point of the trace (see the module's text).

    mode "augmented": ``A = [J; t^T]`` (DOF 1); "projection": ``K = [[I, J^T], [J, -delta]]``
    (DOF 1, self-stressed rows); "descent": ``K = [[J_rho^T J_rho + mu I, J^T], [J, -delta]]``
    (DOF > 1). :meth:`direction` is the next tangent (or Gauss-Newton direction),
    :meth:`correction` one corrector step.

    ``rows`` (r,) int: the system is made of these rows of J (m, n) only, the independent
    ones of :func:`independent_rows` (r = n - 1: ``[J_rows; t^T]`` is square); ``frozen``
    (n, n - 1 - r): directions held in the augmented system besides t,
    ``[J_rows; frozen^T; t^T]`` (near flexes whose near self-stresses' rows are dropped). The rows
    dropped then give a basis W (m, k) of the self-stresses at this point (k solves with
    A^T: ``w^T J = 0`` with w = e_j on the j-th row dropped), and a correction is
    Gauss-Newton's: it leaves the residual's part in the self-stresses, W W^T c, which no
    step removes, and spreads it over the rows of W rather than into the dropped rows alone
    (the least-squares residual of the linearised constraints).
    """

    def __init__(
        self,
        J: sp.csc_matrix,
        J_rho: sp.csr_matrix,
        mode: str,
        t: np.ndarray | None,
        settings: Settings,
        rows: np.ndarray | None = None,
        frozen: np.ndarray | None = None,
    ) -> None:
        self.rows, self.stresses = rows, None
        full = J
        if rows is not None:
            J = sp.csc_matrix(full[rows])
        m, n = J.shape
        self.mode, self.n, self.m, self.J_rho = mode, n, m, J_rho
        if mode == "augmented":
            assert t is not None
            extra = t[None] if frozen is None else np.vstack([frozen.T, t[None]])
            self.factors = Factors(sp.vstack([J, sp.csr_matrix(extra)]))
            if rows is not None and len(rows) < full.shape[0]:
                dropped = np.setdiff1d(np.arange(full.shape[0]), rows)
                Z = self.factors.solve(-full[dropped].T.toarray(), trans="T")
                W = np.zeros((full.shape[0], len(dropped)))
                W[rows] = Z[: len(rows)]
                W[dropped, np.arange(len(dropped))] = 1.0
                self.stresses = np.linalg.qr(W)[0]
            return
        if mode == "projection":
            M = sp.identity(n, format="csc")
        else:
            M = (J_rho.T @ J_rho) + settings.path.damping * sp.identity(n)
        delta = settings.path.regularization
        self.factors = Factors(sp.bmat([[M, J.T], [J, -delta * sp.identity(m)]], format="csc"))

    def direction(self, t: np.ndarray | None, rho: np.ndarray) -> np.ndarray:
        """The unit tangent continuing ``t`` (DOF 1), or the Gauss-Newton step that takes the
        free fold angles ``rho`` towards 0 within the mechanism (not normalised)."""
        if self.mode == "augmented":
            rhs = np.zeros(self.n)
            rhs[-1] = 1.0
            d = self.factors.solve(rhs)
        else:
            top = t if self.mode == "projection" else -(self.J_rho.T @ rho)
            d = self.factors.solve(np.concatenate([top, np.zeros(self.m)]))[: self.n]
        return d if self.mode == "descent" else d / np.linalg.norm(d)

    def irreducible(self, c: np.ndarray) -> np.ndarray:
        """(m,): the part W W^T c of the residual c (m,) in the self-stresses W of the rows
        dropped (zeros without ``rows``): what no correction step removes."""
        if self.stresses is None:
            return np.zeros_like(c)
        return self.stresses @ (self.stresses.T @ c)

    def reducible_norm(self, c: np.ndarray) -> float:
        """max |c - W W^T c|: the size of the part of the residual c (m,) a correction
        removes (max |c| without ``rows``)."""
        return float(np.abs(c if self.stresses is None else c - self.irreducible(c)).max())

    def correction(self, c: np.ndarray) -> np.ndarray:
        """One corrector step for the residual ``c`` (m,) of every row: in the plane normal
        to the tangent (augmented), or of least norm in the system's metric; with ``rows``,
        Gauss-Newton's (see the class's text)."""
        if self.rows is not None:
            c = (c - self.irreducible(c))[self.rows]
        if self.mode == "augmented":
            return self.factors.solve(np.concatenate([-c, np.zeros(self.n - len(c))]))
        return self.factors.solve(np.concatenate([np.zeros(self.n), -c]))[: self.n]


def correct(
    cons: RigidFoldingConstraints,
    y: np.ndarray,
    mode: str,
    t: np.ndarray | None,
    settings: Settings,
    rows: np.ndarray | None = None,
    frozen: np.ndarray | None = None,
    most: int = 0,
) -> tuple[np.ndarray, bool, int, System | None]:
    """Corrector from the prediction y onto c = 0: chord steps on the factors of the latest
    iterate, refactored where they contract by less than ``path_contraction``; converged when
    every |c_i| <= ``path_tol`` (after at least one factorisation, which the next direction
    needs). ``rows`` (r,) int: the system is made of these rows of J only (the independent
    rows of :func:`independent_rows`, so that ``[J_rows; t^T]`` is square), but convergence
    is still every row of c to ``path_tol``; ``frozen``: see :class:`System`. ``most`` (0:
    no bound): without ``rows``, a correction that would need more factorisations than this
    fails there (``Settings.path.corrector_factorizations``: the prediction is beyond
    Newton's reach, and the caller halves the step).

    returns (y, converged, factorizations, the last system).
    """
    system, previous, factorizations = None, np.inf, 0
    for _ in range(settings.path.corrector_iter + 1):
        c = cons.residual(y)
        norm = float(np.abs(c).max())
        if not np.isfinite(norm):
            return y, False, factorizations, system
        # the contraction is that of the part of c a step removes (all of it without rows)
        size = norm if system is None else system.reducible_norm(c)
        if system is None or size > settings.path.contraction * previous:
            if most and rows is None and factorizations >= most:
                return y, False, factorizations, system
            try:
                system = System(*cons.jacobian(y), mode, t, settings, rows, frozen)
            except RuntimeError:  # an exactly singular factor
                return y, False, factorizations, system
            factorizations += 1
            size = system.reducible_norm(c)
        if norm <= settings.path.tol:
            return y, True, factorizations, system
        previous = size
        y = y + system.correction(c)
    return y, False, factorizations, system


def independent_rows(
    J: sp.spmatrix, dof: int, sparse: Settings | None = None
) -> tuple[np.ndarray, float]:
    """(rows (n - dof,) int sorted, J's smallest singular value over its largest): rows of
    the constraint Jacobian J (m, n) of a shape of ``dof`` DOF that are independent, the
    other m - (n - dof) (a basis of its self-stresses) dropped.

    The self-stresses are the left singular vectors W (m, k) of the k = m - (n - dof)
    smallest singular values of J (one dense SVD; with ``sparse``, the settings of the
    sparse method, the smallest singular values of J^T and J of
    :func:`rigidfold.mechanism.sparse.smallest_singular` instead, for shapes of
    ``mechanism_sparse_analysis_vertices`` vertices or more); the rows dropped are the k
    pivots of a QR of W^T with column pivoting, so that W's rows there form a
    well-conditioned k x k block and the rows kept span J's row space (rank n - dof). Where
    the constraints are redundant along the path (a rigid quad cut by a fixed crease), the
    rows kept imply the others near the path; the corrector still checks every row.
    """
    m, n = J.shape
    if sparse is None:
        U, s, _ = np.linalg.svd(J.toarray(), full_matrices=True)
        sigma = float(s[-1] / s[0]) if m >= n else 0.0
        return rows_without_stresses(U, n, dof), sigma
    top = largest_singular(J)
    sigma = 0.0
    if m >= n and top > 0:
        sigma = float(smallest_singular(J, 1, sparse)[0][-1] / top)
    k = m - (n - dof)
    if k <= 0:
        return np.arange(m), sigma
    return _rows_kept(smallest_singular(J.T, k, sparse)[1]), sigma


def rows_without_stresses(U: np.ndarray, n: int, dof: int) -> np.ndarray:
    """(n - dof,) int, sorted: the rows kept by :func:`independent_rows`, from the left
    singular vectors U (m, m) of J (m, n), in the order of decreasing singular values."""
    m = U.shape[0]
    k = m - (n - dof)
    if k <= 0:
        return np.arange(m)
    return _rows_kept(U[:, m - k :])


def _rows_kept(W: np.ndarray) -> np.ndarray:
    """The rows (m - k,) int, sorted, left where the k pivots of a QR of W^T (W (m, k), a
    basis of the self-stresses) with column pivoting are dropped."""
    m, k = W.shape
    _, _, pivots = scipy.linalg.qr(W.T, pivoting=True, mode="economic")
    return np.setdiff1d(np.arange(m), pivots[:k])
