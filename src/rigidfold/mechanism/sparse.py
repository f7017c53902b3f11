"""Kernel of the kinematic constraints without a dense factorisation (large patterns).

The dense analysis factorises the whole constraint matrix C ((E + f + 9) x 3V, see
:func:`rigidfold.mechanism.kinematics.constraint_matrix`): its cost grows with the cube of
the pattern's size. The kernel has only d (the DOF, about the number of boundary vertices)
dimensions, so this module finds it in a space of about that size:

1. The support's nine rows pin nine coordinates: drop them with their columns and the rows
   left empty (the support triangle's edges). ``A`` (k x n) is what remains.
2. ``M = A^T A + delta I`` (n x n, a few non-zeros per row) is factorised once by SuperLU
   (symmetric mode, a minimum-degree order of the vertices). ``delta M^-1`` keeps a
   direction of singular value s of A with the factor ``delta / (s^2 + delta)``: 1 on the
   kernel and on every direction with s^2 << delta (all those near the rank threshold),
   about ``delta / s^2`` on the others (``Settings.mechanism.sparse_shift``).
3. Subspace iteration: ``W <- M^-1 W`` (``Settings.mechanism.sparse_iterations`` times) from m
   random columns (a fixed seed: the same basis on every run), m = n - k plus
   ``Settings.mechanism.sparse_oversampling``.
4. Rayleigh-Ritz: with Y a basis of the span of W (its left singular vectors, from a
   Householder R of W), the singular values of ``A Y`` are the Ritz values, each no smaller
   than the singular value of A it approximates; the right singular vectors of those at most
   ``Settings.mechanism.rank_tol`` times the largest row norm of C (the ``|R_00|`` of the
   dense pivoted QR) span the kernel.
5. The subspace must have had room: at least half the oversampling columns are directions
   damped below 1e-12 of the kernel's share (and so is every direction outside the
   subspace: the modes keep less than about 1e-12 of them, far below ``lock_tol``).
   Otherwise filtered random columns join W and 4 repeats: when the span of W is narrower
   than W (a few near-mechanisms, singular values just above the rank threshold, kept by
   the filter), as many as leave room for the span and ``sparse_oversampling`` more; when it
   is full (many directions of singular value below about ``1000 sqrt(delta)``, e.g. the
   out-of-plane modes of a flat sheet), as many again as W has.

Every rank decision is made on the small dense matrix of step 4, as the dense method makes
it on the whole matrix; ``tests/test_sparse_mechanism.py`` compares the two.

The same filtered subspace gives any sparse matrix's smallest singular values and vectors
(:func:`smallest_singular`, steps 2-5 on A itself, the count given): on A^T it gives the
left ones, the self-stresses, which the second-order test
(:mod:`rigidfold.mechanism.second_order`) and the redundant rows of a stalled path trace
(:func:`rigidfold.mechanism.rigid_folding.independent_rows`) need from 200 vertices on
(``tests/test_second_order.py``, ``tests/test_path.py`` compare them with the dense SVD;
``benchmarks/bench_second_order.py`` times both). Cost: one
sparse factorisation, ``sparse_iterations`` solves with m right-hand sides and two Householder
R factors of n x m matrices, about ``nnz(LU) m + n m^2``; memory about 10 n m floats.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.config import Settings

_SEED = 0
"""Seed of the random start of the subspace iteration (the same modes on every run)."""


def sparse_kernel(C: sp.csr_matrix, settings: Settings) -> tuple[np.ndarray, np.ndarray, int]:
    """Orthonormal basis of the kernel of the constraint matrix C, sparse.

    C : (k, 3V) sparse, rows of unit norm, as built by
        :func:`~rigidfold.mechanism.kinematics.constraint_matrix` (its last nine rows pin the
        support triangle's coordinates).
    returns : (N (3V, d) float64, columns orthonormal to about 1e-4 and zero on the support's
        coordinates; the Ritz values of step 4 (at most m), decreasing; rank of C = 3V - d).
    """
    C = sp.csr_matrix(C)
    pinned = np.unique(C[-9:].indices)
    free = np.setdiff1d(np.arange(C.shape[1]), pinned)
    A = C[:-9][:, free]
    A = A[np.diff(A.indptr) > 0]
    k, n = A.shape
    limit = settings.mechanism.rank_tol * row_scale(C)
    if n == 0:
        return np.zeros((C.shape[1], 0)), np.zeros(0), C.shape[1]
    order = _vertex_order(A, free // 3)
    free, A = free[order], A[:, order].tocsr()
    Y = _filtered_subspace(A, max(n - k, 0), "NATURAL", settings)
    _, s, vt = np.linalg.svd(np.linalg.qr(A @ Y, mode="r"))  # vt: (m', m')
    values = np.concatenate([s, np.zeros(Y.shape[1] - len(s))])  # k < m': zeros
    small = values <= limit
    N = np.zeros((C.shape[1], int(small.sum())))
    N[free] = Y @ vt[small].T
    return N, values, C.shape[1] - N.shape[1]


def _filtered_subspace(
    A: sp.csr_matrix, expected: int, order: str, settings: Settings
) -> np.ndarray:
    """Basis (n, m') of a subspace that holds the right singular vectors of A (k, n) of the
    smallest singular values (steps 2, 3 and 5 of the module's text): ``expected`` (the
    directions looked for) plus ``Settings.mechanism.sparse_oversampling`` random columns
    from a fixed seed, filtered by ``(A^T A + delta I)^-1`` (SuperLU's column order
    ``order``), grown while the filter keeps more directions than leave room."""
    n = A.shape[1]
    lu = spla.splu(
        (A.T @ A + settings.mechanism.sparse_shift * sp.identity(n)).tocsc(),
        permc_spec=order,
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    p = settings.mechanism.sparse_oversampling
    rng = np.random.default_rng(_SEED)

    def filtered(columns: int) -> np.ndarray:  # step 3, columns of unit norm
        W = rng.random((columns, n)).T - 0.5  # column-major, as SuperLU solves
        for _ in range(
            settings.mechanism.sparse_iterations
        ):  # rescaled only: the span is what counts
            W = lu.solve(W / np.sqrt(np.einsum("ij,ij->j", W, W)))
        return W / np.sqrt(np.einsum("ij,ij->j", W, W))

    W = filtered(min(expected + p, n))
    while True:
        Y = _span(W)
        m = W.shape[1]
        if m == n or Y.shape[1] <= m - p // 2:
            return Y
        # step 5: room for the directions the filter keeps, and p more; twice the columns
        # when the span is full (no sign of how many there are)
        grow = Y.shape[1] + p - m if Y.shape[1] < m else m
        W = np.hstack([W, filtered(min(grow, n - m))])


def smallest_singular(
    A: sp.spmatrix, count: int, settings: Settings
) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` smallest singular values of A (k, n) and their right singular vectors,
    without a dense factorisation: Rayleigh-Ritz (step 4) on the filtered subspace of
    :func:`_filtered_subspace` (SuperLU's minimum-degree order; A need not be a constraint
    matrix of vertices).

    returns : (values (count,) decreasing, the Ritz values, each no smaller than the singular
        value it approximates, 0 for the directions beyond A's rows; vectors (n, count) in
        the same order, columns orthonormal to about 1e-4 as those of :func:`_span`; fewer
        than ``count`` only where the subspace holds fewer directions)
    """
    A = sp.csr_matrix(A)
    n = A.shape[1]
    if count <= 0:
        return np.zeros(0), np.zeros((n, 0))
    Y = _filtered_subspace(A, count, "MMD_AT_PLUS_A", settings)
    _, s, vt = np.linalg.svd(np.linalg.qr(A @ Y, mode="r"))  # vt: (m', m')
    values = np.concatenate([s, np.zeros(Y.shape[1] - len(s))])
    count = min(count, Y.shape[1])
    return values[-count:], Y @ vt[-count:].T


def largest_singular(A: sp.spmatrix) -> float:
    """The largest singular value of A (Lanczos on A^T A from a fixed start: the same value
    on every run; should it not converge, its best estimate, or the largest absolute row sum
    of A^T A, a bound from above)."""
    M = sp.csr_matrix(A)
    n = M.shape[1]
    if n == 0 or M.nnz == 0:
        return 0.0
    if n < 3:
        return float(np.linalg.norm(M.toarray(), 2))
    G = (M.T @ M).tocsc()
    try:
        top = float(spla.eigsh(G, k=1, which="LA", v0=np.ones(n), return_eigenvectors=False)[0])
    except spla.ArpackNoConvergence as err:  # its best estimate, else a bound from above
        found = np.asarray(err.eigenvalues)
        top = float(found.max()) if found.size else float(abs(G).sum(axis=1).max())
    return float(np.sqrt(max(top, 0.0)))


def row_scale(C: sp.spmatrix) -> float:
    """The largest row norm of C, the scale of the sparse method's rank threshold."""
    return float(np.sqrt(C.multiply(C).sum(axis=1).max()))


def _vertex_order(A: sp.csr_matrix, vertex: np.ndarray) -> np.ndarray:
    """Fill-reducing order (n,) of the columns of A (k, n), whose column j is a coordinate of
    vertex ``vertex[j]``: SuperLU's minimum degree on the graph of the vertices that A^T A
    couples (a strictly diagonally dominant matrix of that graph, factorised for its order
    alone), each vertex's coordinates kept together. About a tenth less fill and a quarter
    less time per solve than the minimum degree of A^T A itself, for a hundredth of the
    factorisation's time."""
    V = int(vertex.max()) + 1
    # row r of ``touch`` marks the vertices of its coordinates
    touch = sp.csr_matrix((np.ones(A.nnz), vertex[A.indices], A.indptr), shape=(A.shape[0], V))
    graph = (touch.T @ touch).tocsr()
    graph.setdiag(0)
    graph.eliminate_zeros()
    graph.data[:] = -1.0
    degree = -np.asarray(graph.sum(axis=1)).ravel()
    lu = spla.splu(
        (graph + sp.diags(degree + 1.0)).tocsc(),
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    return np.lexsort((np.arange(len(vertex)), lu.perm_c[vertex]))


def _span(W: np.ndarray) -> np.ndarray:
    """Basis (n, m') of the span of W (n, m) with columns orthonormal to about 1e-4, m' <= m.

    With W = Q R (Householder, R alone) and R = U S V^T, ``W V S^-1 = Q U``: the columns are
    the left singular vectors of W, here kept down to 1e-12 of the largest singular value,
    each accurate to eps / (its share): the directions damped more than that by the filter
    are round-off (the kernel itself has shares near 1), and what they leave in the modes is
    below 1e-12 of them. Half the cost of forming Q.
    """
    _, s, vt = np.linalg.svd(np.linalg.qr(W, mode="r"))
    keep = s >= 1e-12 * s[0]
    return W @ (vt[keep].T / s[keep])


def sparse_analysis_bytes(n_vertices: int, n_rows: int, dof: int, settings: Settings) -> int:
    """Memory (bytes) that :func:`sparse_kernel` and the modes built from it need, estimated
    before any matrix is built.

    n_vertices : V; n_rows : rows of C (E + f + 9); dof : a guess of d (the generic DOF).
    About ten dense n x m arrays of floats at their peak (the random start, its solves, the
    span, the products with A and the frame map; n = 3V) and the sparse factor, about
    12 n log2 n non-zeros of 12 bytes for a minimum-degree ordering of a triangulated sheet:
    1.3 to 1.6 times the peak measured on the dome grids from 41 x 41 to 101 x 101
    (``benchmarks/bench_scale.py`` prints it).
    """
    n = 3 * n_vertices
    m = min(max(n - n_rows, dof, 0) + settings.mechanism.sparse_oversampling, n)
    return int(8 * 10 * n * m + 12 * 12 * n * np.log2(max(n, 2)))
