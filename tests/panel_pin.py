"""A small Panel-Pin model (after Hayakawa's Panel-Pin formulation, J. IASS 64(4), 2023),
written independently of rigidfold's frame model, for tests and benchmarks.

Every panel (triangles joined by fixed creases) is a rigid body with six displacements
q_p = (u_p, theta_p) of its centroid c_p. The panels meet at the vertices through pins: a
vertex v of panels p and r moves alike in both, ``u_p + theta_p x (x_v - c_p) = u_r +
theta_r x (x_v - c_r)`` (the pin rows P). A free crease between panels p and r with unit
axis t is a hinge of rotational stiffness k: its rotation is ``phi = (theta_r - theta_p) .
t`` (the hinge rows R), and the hinges' stiffness is ``R^T diag(k) R``. A pinned support at
vertex v holds that vertex's velocity at zero (three rows of one panel at v).

The mechanism modes are the kernel of P with one panel held (its six displacements zero);
with orthonormal modes M, ``K_pp = M^T R^T diag(k) R M`` is Panel-Pin's stiffness on the
mechanisms and its eigenvalues the stiffness eigenvalues (one for a DOF-1 design). With
supports instead of a held panel, the free motions (kernel of P: the rigid-body motions and
the mechanisms) meet the supports' unit springs: ``M^T B^T B M``, B the supports' rows.
"""

from __future__ import annotations

import numpy as np

from rigidfold.mesh import CreasePattern


class PanelPin:
    """Panel-Pin model of ``pattern``: panels, pins at the vertices, hinges at free creases."""

    def __init__(self, pattern: CreasePattern) -> None:
        self.pattern = pattern
        x = pattern.coords
        self.panel_of_face = pattern.facets
        n = int(self.panel_of_face.max()) + 1
        self.n_panels = n
        centroid = np.zeros((n, 3))
        np.add.at(centroid, self.panel_of_face, x[pattern.faces].mean(axis=1))
        centroid /= np.bincount(self.panel_of_face, minlength=n)[:, None]
        self.centroid = centroid
        # panels at each vertex
        self.vertex_panels: list[list[int]] = [[] for _ in range(pattern.n_vertices)]
        for f, tri in enumerate(pattern.faces):
            for v in tri:
                p = int(self.panel_of_face[f])
                if p not in self.vertex_panels[v]:
                    self.vertex_panels[v].append(p)

    def velocity_rows(self, vertex: int, panel: int) -> np.ndarray:
        """(3, 6n) velocity of ``vertex`` as a point of ``panel``: u_p + theta_p x r."""
        r = self.pattern.coords[vertex] - self.centroid[panel]
        rows = np.zeros((3, 6 * self.n_panels))
        rows[:, 6 * panel : 6 * panel + 3] = np.eye(3)
        rows[:, 6 * panel + 3 : 6 * panel + 6] = -np.array(
            [[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]
        )
        return rows

    def pin_rows(self) -> np.ndarray:
        """P: the pins' compatibility, (3 sum_v (panels at v - 1), 6n)."""
        rows = []
        for v, panels in enumerate(self.vertex_panels):
            for p in panels[1:]:
                rows.append(self.velocity_rows(v, p) - self.velocity_rows(v, panels[0]))
        return np.vstack(rows) if rows else np.zeros((0, 6 * self.n_panels))

    def hinge_rows(self) -> np.ndarray:
        """R: (h, 6n) hinge rotations of the free creases."""
        pat = self.pattern
        free = pat.free_creases
        R = np.zeros((len(free), 6 * self.n_panels))
        for j, e in enumerate(free):
            a, b = pat.edge_faces[e]
            pa, pb = int(self.panel_of_face[a]), int(self.panel_of_face[b])
            t = pat.coords[pat.edges[e, 1]] - pat.coords[pat.edges[e, 0]]
            t /= np.linalg.norm(t)
            R[j, 6 * pb + 3 : 6 * pb + 6] += t
            R[j, 6 * pa + 3 : 6 * pa + 6] -= t
        return R

    def free_motions(self, held_panel: int | None, tol: float = 1e-9) -> np.ndarray:
        """Orthonormal basis (6n, m) of the kernel of the pins, with ``held_panel`` still
        (the mechanisms), or with nothing held (the mechanisms and the rigid-body motions)."""
        P = self.pin_rows()
        if held_panel is not None:
            hold = np.zeros((6, 6 * self.n_panels))
            hold[:, 6 * held_panel : 6 * held_panel + 6] = np.eye(6)
            P = np.vstack([P, hold])
        _, s, vt = np.linalg.svd(P, full_matrices=True)
        sigma = np.zeros(P.shape[1])
        sigma[: len(s)] = s
        return vt[sigma <= tol * s[0]].T

    def mechanism_eigenvalues(self, held_panel: int, k: float = 1.0) -> np.ndarray:
        """Ascending eigenvalues of K_pp = M^T R^T k R M on the mechanisms."""
        M = self.free_motions(held_panel)
        RM = self.hinge_rows() @ M
        return np.linalg.eigvalsh(k * RM.T @ RM)

    def support_eigenvalues(self, pinned: np.ndarray) -> np.ndarray:
        """Ascending eigenvalues of the supports' unit springs on the free motions."""
        M = self.free_motions(None)
        B = np.vstack([self.velocity_rows(int(v), self.vertex_panels[int(v)][0]) for v in pinned])
        BM = B @ M
        return np.linalg.eigvalsh(BM.T @ BM)
