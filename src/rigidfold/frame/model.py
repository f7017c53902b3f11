"""The partially rigid frame model of a crease pattern (Section 2, Appendix A).

Nodes sit at the midpoint of every edge (indices ``0..E-1``) and at the barycentre of every
triangle (indices ``E..E+F-1``). Each triangle has three members, from its barycentre node to
its three edge nodes, rigidly connected at the barycentre. At an edge node the members of
both triangles meet: rigidly at a fixed crease (the paper's dividing edge) and on the
boundary, through a revolute hinge about the crease direction at a free crease.

Hinge convention: at free crease j with unit direction ``t_j`` (from ``edges[j, 0]`` to
``edges[j, 1]``), the node rotates with the triangle on the left of ``t_j``; the member ends
of the triangle on the right rotate by ``theta_node - phi_j t_j``. With this sign, the hinge
rotation ``phi_j`` equals the rate of the FOLD fold angle (valley positive).

The compatibility equations (15) ``S v = 0`` say that no member deforms. Per member
``k`` from node a (barycentre) to node b (edge), with ``d = x_b - x_a``::

    theta_b (- phi_j t_j if hinged) - theta_a = 0          (3 rows: twist and bending)
    u_b - u_a + d x theta_a = 0                            (3 rows: elongation and shear)

These six rows span the same equations as the paper's six member deformations
(N, T, M_12, M_13, M_22, M_23) after an invertible change of variables per member, so the
kernel, the DOF and the mechanism modes are the paper's. ``v`` stacks the six displacement
components ``(u, theta)`` of every node except the support node (s = 6), then the h hinge
rotations.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import skew


@dataclass(frozen=True, eq=False)
class FrameModel:
    """Frame model of one crease pattern.

    pattern : CreasePattern
    support_face : int
        Triangle whose barycentre node has all six DOFs fixed (s = 6).
    """

    pattern: CreasePattern
    support_face: int

    @classmethod
    def from_pattern(cls, pattern: CreasePattern, support_face: int | None = None) -> FrameModel:
        """Frame of ``pattern``; the default support is the triangle nearest the centroid."""
        if support_face is None:
            support_face = default_support_face(pattern)
        if not 0 <= support_face < pattern.n_faces:
            raise RigidfoldError(
                f"support face {support_face} out of range 0..{pattern.n_faces - 1}"
            )
        return cls(pattern, int(support_face))

    # ------------------------------------------------------------------ sizes
    @property
    def n_nodes(self) -> int:
        """n = E + F."""
        return self.pattern.n_edges + self.pattern.n_faces

    @property
    def n_members(self) -> int:
        """m = 3F."""
        return 3 * self.pattern.n_faces

    @property
    def support_node(self) -> int:
        return self.pattern.n_edges + self.support_face

    @cached_property
    def hinges(self) -> np.ndarray:
        """(h,) edge indices of the hinges: the free creases."""
        return self.pattern.free_creases

    @property
    def n_hinges(self) -> int:
        return len(self.hinges)

    @property
    def n_dof(self) -> int:
        """Columns of S: 6n - s + h."""
        return 6 * self.n_nodes - 6 + self.n_hinges

    # ------------------------------------------------------------------ geometry
    @cached_property
    def nodes(self) -> np.ndarray:
        """(n, 3) node coordinates: edge midpoints, then triangle barycentres."""
        x = self.pattern.coords
        mid = 0.5 * (x[self.pattern.edges[:, 0]] + x[self.pattern.edges[:, 1]])
        return np.vstack([mid, x[self.pattern.faces].mean(axis=1)])

    @cached_property
    def members(self) -> np.ndarray:
        """(m, 2) node pairs (barycentre node, edge node); member 3f + k is in triangle f."""
        pat = self.pattern
        bary = pat.n_edges + np.repeat(np.arange(pat.n_faces), 3)
        return np.column_stack([bary, pat.face_edges.ravel()])

    @cached_property
    def hinge_axes(self) -> np.ndarray:
        """(h, 3) unit crease directions t_j."""
        x, e = self.pattern.coords, self.pattern.edges[self.hinges]
        t = x[e[:, 1]] - x[e[:, 0]]
        return t / np.linalg.norm(t, axis=1, keepdims=True)

    @cached_property
    def member_hinge(self) -> np.ndarray:
        """(m,) hinge index of each member's edge-node end, or -1 when rigidly connected."""
        pat = self.pattern
        hinge_of_edge = np.full(pat.n_edges, -1)
        hinge_of_edge[self.hinges] = np.arange(self.n_hinges)
        face = np.repeat(np.arange(pat.n_faces), 3)
        edge = self.members[:, 1]
        right = pat.edge_faces[edge, 1] == face
        return np.where(right & ~pat.is_boundary_edge[edge], hinge_of_edge[edge], -1)

    # ------------------------------------------------------------------ compatibility
    def compatibility_matrix(self) -> sp.csr_matrix:
        """S = [S_N^T S_R^T] (6m, 6n - 6 + h), sparse, built without a loop over entries."""
        m = self.n_members
        a, b = self.members[:, 0], self.members[:, 1]
        d = self.nodes[b] - self.nodes[a]
        rows, cols, vals = [], [], []

        def put(r, c, v):
            rows.append(np.asarray(r).ravel())
            cols.append(np.asarray(c).ravel())
            vals.append(np.broadcast_to(v, np.shape(r)).ravel())

        k = np.arange(m)
        for axis in range(3):
            rot, tra = 6 * k + axis, 6 * k + 3 + axis
            put(rot, 6 * b + 3 + axis, 1.0)  # theta_b
            put(rot, 6 * a + 3 + axis, -1.0)  # -theta_a
            put(tra, 6 * b + axis, 1.0)  # u_b
            put(tra, 6 * a + axis, -1.0)  # -u_a
        # d x theta_a = [d]x theta_a
        cross = skew(d)
        for i in range(3):
            for j in range(3):
                put(6 * k + 3 + i, 6 * a + 3 + j, cross[:, i, j])
        hinged = np.flatnonzero(self.member_hinge >= 0)
        hinge = self.member_hinge[hinged]
        for axis in range(3):
            put(6 * hinged + axis, 6 * self.n_nodes + hinge, -self.hinge_axes[hinge, axis])
        S = sp.coo_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
            shape=(6 * m, 6 * self.n_nodes + self.n_hinges),
        ).tocsc()
        keep = np.ones(S.shape[1], dtype=bool)
        keep[6 * self.support_node : 6 * self.support_node + 6] = False
        S = S[:, keep].tocsr()
        S.eliminate_zeros()
        return S


def default_support_face(pattern: CreasePattern) -> int:
    """The triangle whose barycentre is nearest the centroid of the vertices."""
    bary = pattern.coords[pattern.faces].mean(axis=1)
    return int(np.argmin(np.linalg.norm(bary - pattern.coords.mean(axis=0), axis=1)))
