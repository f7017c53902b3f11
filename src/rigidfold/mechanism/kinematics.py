"""Infinitesimal kinematics of a triangulated polyhedron in vertex velocities.

The mechanism of the frame model is computed through an equivalent, much smaller system:
vertex velocities ``xdot`` (3V,) that keep every edge length (the triangles are rigid), keep
every fixed crease flat (zero fold-angle rate) and keep one support triangle still. Its
kernel is mapped linearly onto the frame's displacement vector ``v = (u, theta, phi)``
(see :mod:`rigidfold.frame.model`); the map is injective, so the two kernels are the same
space of mechanisms.
"""

from __future__ import annotations

from functools import lru_cache

import casadi as ca
import numpy as np
import scipy.sparse as sp

from rigidfold.frame import FrameModel
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import skew


@lru_cache(maxsize=1)
def _fold_angle_function() -> ca.Function:
    """rho(p_u, p_v, p_a, p_b) and its gradient (12,), as one CasADi function.

    p_a is the third vertex of the triangle left of u -> v, p_b that of the right one.
    """
    q = ca.SX.sym("q", 12)
    pu, pv, pa, pb = q[0:3], q[3:6], q[6:9], q[9:12]
    na = ca.cross(pv - pu, pa - pu)
    nb = ca.cross(pu - pv, pb - pv)  # right triangle (v, u, b), counter-clockwise
    t = (pv - pu) / ca.norm_2(pv - pu)
    rho = ca.atan2(-ca.dot(ca.cross(na, nb), t), ca.dot(na, nb))
    return ca.Function("rho", [q], [rho, ca.gradient(rho, q)])


@lru_cache(maxsize=32)
def _fold_angle_map(n: int) -> ca.Function:
    """The fold-angle function evaluated on n creases at once (built once per n)."""
    return _fold_angle_function().map(n)


def fold_angles_and_gradients(
    coords: np.ndarray, stencils: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fold angles of creases and their gradients in the vertex coordinates.

    Parameters
    ----------
    coords : (V, 3) float
        Vertex coordinates.
    stencils : (n, 4) int
        Vertices (u, v, a, b) of each crease, from :meth:`CreasePattern.crease_stencils`.

    Returns
    -------
    rho : (n,) float
        Signed fold angles, radians (valley positive, as :attr:`CreasePattern.fold_angles`).
    grad : (n, 12) float
        d rho_j / d (p_u, p_v, p_a, p_b), the nonzeros of d rho_j / d x.
    cols : (n, 12) int
        Their columns in x = (x_0, y_0, z_0, x_1, ...) (3V,).
    """
    stencils = np.asarray(stencils, dtype=np.int64)
    n = len(stencils)
    cols = (3 * stencils[:, :, None] + np.arange(3)).reshape(n, 12)
    if n == 0:  # CasADi cannot map over 0 creases
        return np.zeros(0), np.zeros((0, 12)), cols
    q = np.asarray(coords)[stencils].reshape(n, 12).T
    rho, grad = _fold_angle_map(n)(q)
    return np.asarray(rho).ravel(), np.asarray(grad).T, cols


def fold_angle_gradients(pattern: CreasePattern, creases: np.ndarray) -> sp.csr_matrix:
    """d rho_j / d x for the given interior edges.  -> (len(creases), 3V) sparse."""
    n, V = len(creases), pattern.n_vertices
    _, grad, cols = fold_angles_and_gradients(pattern.coords, pattern.crease_stencils(creases))
    rows = np.repeat(np.arange(n), 12)
    return sp.csr_matrix((grad.ravel(), (rows, cols.ravel())), shape=(n, 3 * V))


def constraint_matrix(pattern: CreasePattern, support_face: int) -> sp.csr_matrix:
    """All kinematic constraints: edge lengths, flat fixed creases, support.  (k, 3V) sparse

    Rows are scaled to unit norm; the kernel is the space of mechanisms with the support fixed.
    Rows ``0..E-1`` keep the edge lengths (2 vertices each), the next ``f`` keep the fixed
    creases flat (4 vertices each) and the last 9 pin the support triangle's coordinates:
    k = E + f + 9, a few non-zeros per row (``.toarray()`` for the dense analysis).
    """
    E, V = pattern.n_edges, pattern.n_vertices
    fixed = pattern.fixed_creases
    e = pattern.edges
    d = pattern.coords[e[:, 1]] - pattern.coords[e[:, 0]]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    c3 = np.arange(3)
    rows = [np.repeat(np.arange(E), 6)]
    cols = [np.hstack([3 * e[:, :1] + c3, 3 * e[:, 1:] + c3]).ravel()]
    vals = [np.hstack([-d, d]).ravel()]
    if len(fixed):
        _, grad, gcols = fold_angles_and_gradients(pattern.coords, pattern.crease_stencils(fixed))
        grad /= np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300)
        rows.append(E + np.repeat(np.arange(len(fixed)), 12))  # 4 distinct vertices per row
        cols.append(gcols.ravel())
        vals.append(grad.ravel())
    rows.append(E + len(fixed) + np.arange(9))
    cols.append((3 * pattern.faces[support_face][:, None] + c3).ravel())
    vals.append(np.ones(9))
    return sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(E + len(fixed) + 9, 3 * V),
    )


def angular_velocity_blocks(pattern: CreasePattern) -> np.ndarray:
    """Angular velocity of every triangle moving rigidly, as blocks of d omega / d xdot.

    With r_k = x_k - c (c the barycentre), a rigid motion gives
    ``sum_k r_k x xdot_k = J omega`` with ``J = sum_k (|r_k|^2 I - r_k r_k^T)``.

    returns : (F, 3, 3, 3); entry [f, i, k, l] is d omega_f[i] / d xdot[faces[f, k], l].
    """
    x = pattern.coords[pattern.faces]  # (F, 3, 3)
    r = x - x.mean(axis=1, keepdims=True)
    sq = np.einsum("fkd,fkd->f", r, r)
    J = sq[:, None, None] * np.eye(3) - np.einsum("fki,fkj->fij", r, r)
    return np.einsum("fij,fkjl->fikl", np.linalg.inv(J), skew(r))


def frame_map(frame: FrameModel) -> sp.csr_matrix:
    """Linear map from vertex velocities to the frame's v = (u, theta, phi).

    Edge node: u is the mean velocity of the edge's ends, theta the angular velocity of the
    triangle on the edge's left (the node's rigid side). Barycentre node: the triangle's mean
    velocity and angular velocity. phi_j: the fold-angle rate of free crease j.

    returns : (6n - 6 + h, 3V) sparse; rows of the support node removed.
    """
    pat = frame.pattern
    E, F = pat.n_edges, pat.n_faces
    W = angular_velocity_blocks(pat)  # (F, 3, 3, 3)
    c3 = np.arange(3)
    row_parts: list[np.ndarray] = []
    col_parts: list[np.ndarray] = []
    val_parts: list[np.ndarray] = []
    # translations: edge nodes (mean of 2 vertices), barycentre nodes (mean of 3)
    for node, verts in ((np.arange(E), pat.edges), (E + np.arange(F), pat.faces)):
        k = verts.shape[1]
        row_parts.append(np.broadcast_to(6 * node[:, None, None] + c3, (len(node), k, 3)).ravel())
        col_parts.append((3 * verts[:, :, None] + c3).ravel())
        val_parts.append(np.full(len(node) * k * 3, 1.0 / k))
    # rotations: W of the node's rigid triangle
    edge_face = np.where(pat.edge_faces[:, 0] >= 0, pat.edge_faces[:, 0], pat.edge_faces[:, 1])
    for node, face in ((np.arange(E), edge_face), (E + np.arange(F), np.arange(F))):
        shape = (len(node), 3, 3, 3)
        row_parts.append(
            np.broadcast_to(6 * node[:, None, None, None] + 3 + c3[:, None, None], shape).ravel()
        )
        col_parts.append(np.broadcast_to(3 * pat.faces[face][:, None, :, None] + c3, shape).ravel())
        val_parts.append(W[face].ravel())
    rows, cols = np.concatenate(row_parts), np.concatenate(col_parts)
    vals = np.concatenate(val_parts)
    # drop the support node's rows and close the gap
    s0 = 6 * frame.support_node
    keep = (rows < s0) | (rows >= s0 + 6)
    rows = np.where(rows[keep] >= s0 + 6, rows[keep] - 6, rows[keep])
    nodal = sp.csr_matrix(
        (vals[keep], (rows, cols[keep])), shape=(6 * frame.n_nodes - 6, 3 * pat.n_vertices)
    )
    phi = fold_angle_gradients(pat, frame.hinges)
    return sp.vstack([nodal, phi], format="csr")
