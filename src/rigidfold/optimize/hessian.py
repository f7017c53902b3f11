"""Closed-form Hessian of the Lagrangian of (6), assembled from element Hessians.

CasADi's symbolic Hessian of (6) is a graph of about 3e5 instructions for the Bezier patterns
and takes half of every IPOPT solve. The Lagrangian is a sum of small element functions, and
each has a short closed-form Hessian, so this module evaluates it directly with NumPy:

::

    L = s F1 + s F2 + lam_dz . (z - f(x, y)) + lam_theta . theta + lam_rho . rho

* sector angle theta = atan2(|u x v|, u . v) at corner a of a triangle, u = b - a,
  v = c - a: Hessian in (u, v) from q = |u|^2 |v|^2 - (u . v)^2 (below), 9 x 9 per angle;
* F1 = sum_v d_v^2, d_v = 2 pi - sum_k theta_k: a Gauss-Newton part
  2 s sum_v (grad d_v)(grad d_v)^T plus the angle Hessians weighted by -2 s d_v;
* F2 = sum_j w_j |n_a x n_b|^2 = sum_j w_j (1 - c_j^2) and (12) rho_j = (1 - w_j)(cos rho_max
  - c_j), with c = n_a . n_b of the unit normals of the two triangles at crease j:
  Hessian of c in (m_a, m_b) = (e1 x e2) of each triangle, chained through the bilinear m;
* dz: the 2 x 2 Hessian of the surface per vertex (``Surface.hessian``).

Element entries are mapped into the upper triangle of the Hessian in the independent
variables xi (``P = T xi + t``) by sparse matrices built once per problem. The result agrees
with CasADi's exact Hessian to round-off (``tests/test_optimize.py``) at a fraction of the
cost (``benchmarks/hessian_size.py``).
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sp

from rigidfold.mesh.geometry import skew
from rigidfold.optimize.solver import SolverProblem

B_ANGLE = np.zeros((6, 9))  # d(u, v) / d(a, b, c) for (u, v) = (b - a, c - a)
B_ANGLE[0:3, 0:3] = B_ANGLE[3:6, 0:3] = -np.eye(3)
B_ANGLE[0:3, 3:6] = B_ANGLE[3:6, 6:9] = np.eye(3)
_EYE = np.eye(3)


def angle_corners(faces: np.ndarray) -> np.ndarray:
    """Corners (a, b, c) of every sector angle, (3F, 3): row k*F + f is the angle at
    ``faces[f, k]``, between the edges to ``faces[f, k + 1]`` and ``faces[f, k + 2]``."""
    F = len(faces)
    k, f = np.repeat(np.arange(3), F), np.tile(np.arange(F), 3)
    return np.stack([faces[f, k], faces[f, (k + 1) % 3], faces[f, (k + 2) % 3]], 1)


def coordinate_rows(vertices: np.ndarray, n_vertices: int) -> np.ndarray:
    """Rows of P = (x_1..x_V, y_1..y_V, z_1..z_V) of the vertices' coordinates.

    vertices : (K, m) int  ->  (K, 3m), vertex by vertex, x, y, z of each.
    """
    return (vertices[:, :, None] + n_vertices * np.arange(3)).reshape(
        len(vertices), 3 * vertices.shape[1]
    )


def _outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, :, None] * b[:, None, :]


def row_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ki,ki->k", a, b)


def row_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.cross of (K, 3) rows, written out: the same bits, 1.6x faster at this size."""
    return np.stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ],
        axis=1,
    )


def angle_derivatives(u: np.ndarray, v: np.ndarray):
    """theta = atan2(s, c), s = |u x v|, c = u . v, with gradient and Hessian in (u, v).

    With q = s^2 = |u|^2 |v|^2 - c^2 and r2 = s^2 + c^2 = |u|^2 |v|^2 (so grad s = grad q / 2s):
    ``grad theta = (c grad s - s grad c) / r2`` and

    ``hess theta = c/(2 s r2) hess q - s/r2 hess c + (s^2 - c^2)/r2^2 (gs gc^T + gc gs^T)
    - c (2 s^2 + r2)/(s r2^2) gs gs^T + 2 c s/r2^2 gc gc^T``.

    u, v : (K, 3)  ->  theta (K,), grad (K, 6), hess (K, 6, 6)
    """
    uu, vv, c = row_dot(u, u), row_dot(v, v), row_dot(u, v)
    r2 = uu * vv
    cross = row_cross(u, v)
    s = np.sqrt(row_dot(cross, cross))
    gc = np.concatenate([v, u], axis=1)
    gs = np.concatenate([u * vv[:, None] - c[:, None] * v, v * uu[:, None] - c[:, None] * u], 1)
    gs /= s[:, None]  # grad q / (2 s)
    r4 = r2 * r2
    alpha = c / (s * r2)  # times hess q / 2
    hess = np.empty((len(u), 6, 6))
    hess[:, 0:3, 0:3] = alpha[:, None, None] * (vv[:, None, None] * _EYE - _outer(v, v))
    hess[:, 3:6, 3:6] = alpha[:, None, None] * (uu[:, None, None] * _EYE - _outer(u, u))
    off = (
        alpha[:, None, None] * (2 * _outer(u, v) - _outer(v, u))
        - (alpha * c + s / r2)[:, None, None] * _EYE
    )
    hess[:, 0:3, 3:6] = off
    hess[:, 3:6, 0:3] = np.swapaxes(off, 1, 2)
    sc = _outer(gs, gc)
    hess += ((s * s - c * c) / r4)[:, None, None] * (sc + np.swapaxes(sc, 1, 2))
    hess -= (c * (2 * s * s + r2) / (s * r4))[:, None, None] * _outer(gs, gs)
    hess += (2 * c * s / r4)[:, None, None] * _outer(gc, gc)
    grad = (c[:, None] * gs - s[:, None] * gc) / r2[:, None]
    return np.arctan2(s, c), grad, hess


def normal_cosine_derivatives(pa: np.ndarray, pb: np.ndarray):
    """c = n_a . n_b of two triangles' unit normals, with gradient and Hessian.

    pa, pb : (K, 3, 3) corner coordinates of the triangles (corner, xyz), in face order.
    returns : c (K,), grad (K, 18), hess (K, 18, 18) in (pa corners, pb corners).
    """
    K = len(pa)
    J = np.zeros((K, 6, 18))  # d(m_a, m_b) / d(pa, pb)
    parts = []
    for side, p in enumerate((pa, pb)):
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        m = row_cross(e1, e2)
        rows, cols = slice(3 * side, 3 * side + 3), 9 * side
        J[:, rows, cols : cols + 3] = skew(e2 - e1)
        J[:, rows, cols + 3 : cols + 6] = -skew(e2)
        J[:, rows, cols + 6 : cols + 9] = skew(e1)
        length = np.sqrt(row_dot(m, m))
        parts.append((m / length[:, None], length))
    (na, la), (nb, lb) = parts
    c = row_dot(na, nb)
    ga = (nb - c[:, None] * na) / la[:, None]
    gb = (na - c[:, None] * nb) / lb[:, None]
    proj_a = _EYE - _outer(na, na)
    proj_b = _EYE - _outer(nb, nb)
    H = np.empty((K, 6, 6))
    H[:, 0:3, 0:3] = (
        -(_outer(na, ga) + _outer(ga, na)) / la[:, None, None]
        - c[:, None, None] * proj_a / (la * la)[:, None, None]
    )
    H[:, 3:6, 3:6] = (
        -(_outer(nb, gb) + _outer(gb, nb)) / lb[:, None, None]
        - c[:, None, None] * proj_b / (lb * lb)[:, None, None]
    )
    ab = (proj_b / lb[:, None, None] - _outer(na, gb)) / la[:, None, None]
    H[:, 0:3, 3:6] = ab
    H[:, 3:6, 0:3] = np.swapaxes(ab, 1, 2)
    gm = np.concatenate([ga, gb], axis=1)  # dc / d(m_a, m_b)
    JT = np.swapaxes(J, 1, 2)
    grad = (JT @ gm[:, :, None])[:, :, 0]
    hess = JT @ H @ J
    # second derivative of the bilinear m = e1 x e2: g . m = -e1^T [g]x e2
    for side, g in enumerate((ga, gb)):
        o = 9 * side
        h6 = np.zeros((K, 6, 6))
        h6[:, 0:3, 3:6] = -skew(g)  # d2 (g . m) / de1 de2
        h6[:, 3:6, 0:3] = skew(g)
        hess[:, o : o + 9, o : o + 9] += B_ANGLE.T @ h6 @ B_ANGLE  # (e1, e2) like (u, v)
    return c, grad, hess


def expand_rows(T: sp.csr_matrix, rows: np.ndarray):
    """Nonzeros of T[rows]: (entry, column, value) for each listed P-row."""
    sub = T[rows]
    entry = np.repeat(np.arange(len(rows)), np.diff(sub.indptr))
    return entry, sub.indices, sub.data


def _pairs(T: sp.csr_matrix, I: np.ndarray, J: np.ndarray):
    """For local entries (I, J) in P: every (a, b, T[I, a] T[J, b]) with a <= b.

    returns : entry (N,), a (N,), b (N,), weight (N,)
    """
    count = np.diff(T.indptr)
    cI, cJ = count[I], count[J]
    total = cI * cJ
    entry = np.repeat(np.arange(len(I)), total)
    start = np.repeat(np.cumsum(total) - total, total)
    pos = np.arange(total.sum()) - start
    i_off, j_off = pos // cJ[entry], pos % cJ[entry]
    ka, kb = T.indptr[I][entry] + i_off, T.indptr[J][entry] + j_off
    a, b = T.indices[ka], T.indices[kb]
    weight = T.data[ka] * T.data[kb]
    keep = a <= b
    return entry[keep], a[keep], b[keep], weight[keep]


def unique_inverse(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(keys, return_inverse=True) of int64 keys, by one sort.  -> (unique, slot)"""
    order = np.argsort(keys)
    ordered = keys[order]
    new = np.empty(len(keys), dtype=bool)
    new[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=new[1:])
    slot = np.empty(len(keys), dtype=np.int64)
    slot[order] = np.cumsum(new) - 1
    return ordered[new], slot


def _upper_pairs(sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every pair (p, q), p <= q, within consecutive groups of ``sizes`` items, in row-major
    order group by group (``np.triu_indices`` of each group, offset by its start)."""
    group_start = np.repeat(np.cumsum(sizes) - sizes, sizes)
    item = np.arange(sizes.sum())
    run = np.repeat(sizes, sizes) - (item - group_start)  # items from this one to group end
    p = np.repeat(item, run)
    q = p + np.arange(run.sum()) - np.repeat(np.cumsum(run) - run, run)
    return p, q


class ClosedFormHessian:
    """Upper triangle of the Hessian of the Lagrangian of (6) in xi, from element Hessians.

    ``sparsity`` is a CasADi Sparsity (n, n); ``values(xi, w, lam_f, lam_g)`` returns its
    nonzeros (nnz,) in CasADi's (column-major) order.
    """

    def __init__(self, problem: SolverProblem) -> None:
        pat, lin = problem.pattern, problem.map
        V, n = pat.n_vertices, lin.n_variables
        self.V, self.n, self.T, self.t = V, n, lin.T.tocsr(), lin.t
        faces = pat.faces
        F = len(faces)
        self.rho = problem.settings.design.rho_max
        self.angle_vertices = angle_corners(faces)  # (3F, 3): a, b, c
        inner = pat.interior_vertices
        row_of = np.full(V, -1)
        row_of[inner] = np.arange(len(inner))
        self.angle_row = row_of[self.angle_vertices[:, 0]]  # inner-vertex row or -1
        self.n_inner = len(inner)
        interior = pat.interior_edges
        ef = pat.edge_faces[interior]
        self.interior = interior
        self.edge_corners = np.concatenate([faces[ef[:, 0]], faces[ef[:, 1]]], axis=1)  # (Ei, 6)
        self.dz_vertices = problem.nlp.dz_vertices
        self.n_dz = len(self.dz_vertices)
        self.n_theta = 3 * F
        angle_P = coordinate_rows(self.angle_vertices, V)  # (3F, 9) P rows of (a, b, c)
        edge_P = coordinate_rows(self.edge_corners, V)  # (Ei, 18)
        dz_P = np.stack([self.dz_vertices, V + self.dz_vertices], 1)  # (n_dz, 2)
        blocks = []
        for idx in (angle_P, edge_P, dz_P):
            L = idx.shape[1]
            I = np.repeat(idx, L, axis=1).ravel()
            J = np.tile(idx, (1, L)).ravel()
            blocks.append(_pairs(self.T, I, J))
        # Gauss-Newton part of F1: rows of grad d_v in xi, from the angle gradients
        at_inner = np.flatnonzero(self.angle_row >= 0)
        gI = angle_P[at_inner].ravel()
        g_entry, g_col, g_w = expand_rows(self.T, gI)
        g_local = at_inner[g_entry // 9] * 9 + g_entry % 9  # index into (3F, 9) gradients
        g_row = self.angle_row[g_local // 9]
        key = g_row * n + g_col
        uniq, g_slot = np.unique(key, return_inverse=True)
        self.G = sp.csr_matrix(
            (g_w, (g_slot, g_local)), shape=(len(uniq), self.n_theta * 9)
        )  # G.data of grad d_v (inner rows, xi columns), up to sign
        G_row, G_col = uniq // n, uniq % n  # sorted by row, then column
        self.gn_p, self.gn_q = _upper_pairs(np.bincount(G_row, minlength=self.n_inner))
        gn_a, gn_b = G_col[self.gn_p], G_col[self.gn_q]
        # the fixed upper-triangle sparsity: union of everything, column-major
        keys, slots = unique_inverse(
            np.concatenate([b * n + a for _, a, b, _ in blocks] + [gn_b * n + gn_a])
        )
        cols, rows = keys // n, keys % n
        colptr = np.searchsorted(cols, np.arange(n + 1))
        self.sparsity = ca.Sparsity(n, n, colptr.tolist(), rows.tolist())
        nnz = len(keys)
        self.R = []
        ends = np.cumsum([len(a) for _, a, _, _ in blocks])
        for (entry, _, _, weight), idx, end in zip(
            blocks, (angle_P, edge_P, dz_P), ends, strict=True
        ):
            size = idx.shape[0] * idx.shape[1] ** 2
            slot = slots[end - len(entry) : end]
            self.R.append(sp.csr_matrix((weight, (slot, entry)), shape=(nnz, size)))
        self.gn_slot = slots[ends[-1] :]
        # angle Hessians and gradients are computed in (u, v); fold (a, b, c) -> (u, v) in
        eye = sp.identity(self.n_theta, format="csr")
        self.R[0] = (self.R[0] @ sp.kron(eye, np.kron(B_ANGLE.T, B_ANGLE.T))).tocsr()
        self.G = (self.G @ sp.kron(eye, B_ANGLE.T)).tocsr()
        self.surface = problem.surface

    def values(self, xi, w, lam_f: float, lam_g) -> np.ndarray:
        """Nonzeros of the upper triangle at a point.  -> (nnz,)"""
        xi, w, lam_g = (np.asarray(a, dtype=float).ravel() for a in (xi, w, lam_g))
        P = self.T @ xi + self.t
        X = P.reshape(3, self.V).T  # (V, 3)
        lam_dz = lam_g[: self.n_dz]
        lam_theta = lam_g[self.n_dz : self.n_dz + self.n_theta]
        # angles
        a, b, c = (X[self.angle_vertices[:, i]] for i in range(3))
        theta, g6, h6 = angle_derivatives(b - a, c - a)
        inner = self.angle_row >= 0
        defect = 2 * np.pi - np.bincount(
            self.angle_row[inner], weights=theta[inner], minlength=self.n_inner
        )
        coef = lam_theta.copy()
        coef[inner] -= 2 * lam_f * defect[self.angle_row[inner]]
        out = self.R[0] @ (coef[:, None, None] * h6).ravel()
        # Gauss-Newton part of F1
        gd = self.G @ g6.ravel()
        out += np.bincount(
            self.gn_slot, weights=2 * lam_f * gd[self.gn_p] * gd[self.gn_q], minlength=len(out)
        )
        # F2 and (12)
        w_int = w[self.interior]
        pts = X[self.edge_corners]  # (Ei, 6, 3)
        coef_f2 = lam_f * w_int
        coef_rho = np.zeros_like(w_int)
        if self.rho is not None:
            coef_rho = lam_g[self.n_dz + self.n_theta :] * (1 - w_int)
        active = (coef_f2 != 0) | (coef_rho != 0)
        if active.any():
            cos, gc, hc = normal_cosine_derivatives(pts[active, :3], pts[active, 3:])
            he = -2 * coef_f2[active, None, None] * (_outer(gc, gc) + cos[:, None, None] * hc)
            he -= coef_rho[active, None, None] * hc
            full = np.zeros((len(w_int), 18, 18))
            full[active] = he
            out += self.R[1] @ full.ravel()
        # dz: -lam * Hessian of the surface in (x, y)
        if self.n_dz:
            v = self.dz_vertices
            fxx, fxy, fyy = self.surface.hessian(X[v, 0], X[v, 1])
            h2 = -lam_dz[:, None] * np.stack([fxx, fxy, fxy, fyy], axis=1)
            out += self.R[2] @ h2.ravel()
        return out


class _HessianCallback(ca.Callback):
    """CasADi Function (x, p, lam_f, lam_g) -> upper triangle, for IPOPT's ``hess_lag``."""

    def __init__(self, hessian: ClosedFormHessian, n_p: int, n_g: int) -> None:
        ca.Callback.__init__(self)
        self.hessian, self.sizes = hessian, (hessian.n, n_p, 1, n_g)
        self.construct("nlp_hess_l", {})

    def get_n_in(self) -> int:
        return 4

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return ("x", "p", "lam_f", "lam_g")[i]

    def get_name_out(self, i: int) -> str:
        return "triu_hess_gamma_x_x"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self.sizes[i], 1)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return self.hessian.sparsity

    def has_eval_buffer(self) -> bool:  # NumPy views of CasADi's buffers: no copies
        return True

    def eval_buffer(self, arg, res) -> int:
        x, p, lam_f, lam_g = (np.frombuffer(a, dtype=np.float64) for a in arg)
        out = np.frombuffer(res[0], dtype=np.float64)
        out[:] = self.hessian.values(x, p, float(lam_f[0]), lam_g)
        return 0


def closed_form_hess_lag(problem: SolverProblem) -> ca.Function:
    """IPOPT's ``hess_lag`` Function for a SolverProblem (keep a reference to it)."""
    hessian = ClosedFormHessian(problem)
    return _HessianCallback(hessian, problem.nlp.p.shape[0], problem.nlp.g.shape[0])
