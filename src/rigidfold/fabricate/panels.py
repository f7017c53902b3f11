"""The panels of a design and the hinges between them, for thick panels.

A *panel* is a facet of the pattern: triangles joined by fixed creases
(:attr:`rigidfold.mesh.CreasePattern.facets`), one rigid piece of the built structure, numbered
as in the design's exports (``panel_K`` of the 3D files, ``panel`` of the schedule). A
*hinge* is a free crease between two different panels: the axis about which they turn. Two
panels are *neighbours* when a hinge joins them; panels that meet at a vertex only are not.

Thick solids lie on one ``side`` of the design surface: ``"bottom"`` (against the faces'
normals, which point up, so the design surface is their top face) or ``"top"``. A hinge
*closes* the material side when it folds towards it: a valley (fold angle > 0, a trough
seen from +z) closes the top side, a mountain the bottom side. :meth:`Panels.closing` gives
that signed fold angle (> 0: the solids turn towards each other).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rigidfold.config import SIDES
from rigidfold.errors import RigidfoldError
from rigidfold.exports.sheet import panel_loops
from rigidfold.mesh import CreasePattern


@dataclass(frozen=True, eq=False)
class Panels:
    """The panels and hinges of a design, and the side its solids lie on.

    Attributes
    ----------
    pattern : CreasePattern
        The design (folded form, metres, z up).
    coords2d : (V, 2) float64
        Its development diagram, metres (the flat sheet that is cut).
    side : str
        ``"bottom"`` or ``"top"`` (:data:`rigidfold.config.SIDES`).
    """

    pattern: CreasePattern
    coords2d: np.ndarray
    side: str

    def __post_init__(self) -> None:
        if self.side not in SIDES:
            raise RigidfoldError(f"side must be one of {', '.join(SIDES)}, got {self.side!r}")
        xy = np.asarray(self.coords2d, dtype=np.float64)
        if xy.shape != (self.pattern.n_vertices, 2) or not np.isfinite(xy).all():
            raise RigidfoldError(
                f"coords2d must be a finite ({self.pattern.n_vertices}, 2) array (the "
                f"development diagram), got shape {xy.shape}"
            )
        xy = xy.copy()
        xy.flags.writeable = False
        object.__setattr__(self, "coords2d", xy)

    # ------------------------------------------------------------------ panels
    @property
    def label(self) -> np.ndarray:
        """(F,) int: the panel of each triangle."""
        return self.pattern.facets

    @property
    def n(self) -> int:
        """Number of panels."""
        return self.pattern.n_facets

    @cached_property
    def triangles(self) -> tuple[np.ndarray, ...]:
        """The triangles (face indices, (k,) int) of each panel."""
        order = np.argsort(self.label, kind="stable")
        bounds = np.searchsorted(self.label[order], np.arange(self.n + 1))
        return tuple(order[bounds[k] : bounds[k + 1]] for k in range(self.n))

    @cached_property
    def vertices(self) -> tuple[np.ndarray, ...]:
        """The vertices ((k,) int, sorted) of each panel."""
        faces = self.pattern.faces
        return tuple(np.unique(faces[t]) for t in self.triangles)

    @cached_property
    def normals(self) -> np.ndarray:
        """(P, 3) float64: unit normal of each panel in the design (area-weighted mean of its
        triangles' normals, which point up)."""
        p = self.pattern
        a, b, c = (p.coords[p.faces[:, k]] for k in range(3))
        weighted = np.cross(b - a, c - a)  # twice the area times the unit normal
        total = np.zeros((self.n, 3))
        np.add.at(total, self.label, weighted)
        return total / np.linalg.norm(total, axis=1, keepdims=True)

    @property
    def sign(self) -> float:
        """+1 for solids on the top side (along the normals), -1 for the bottom side."""
        return 1.0 if self.side == "top" else -1.0

    @cached_property
    def material(self) -> np.ndarray:
        """(P, 3) float64: the unit direction from each panel's surface into its solid."""
        return self.sign * self.normals

    @cached_property
    def areas(self) -> np.ndarray:
        """(P,) float64: area of each panel in the development diagram, m^2."""
        xy, faces = self.coords2d, self.pattern.faces
        d1 = xy[faces[:, 1]] - xy[faces[:, 0]]
        d2 = xy[faces[:, 2]] - xy[faces[:, 0]]
        tri = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
        return np.bincount(self.label, weights=tri, minlength=self.n)

    @cached_property
    def loops(self) -> tuple[tuple[np.ndarray, ...], ...]:
        """Outline loops of each panel (:func:`rigidfold.exports.sheet.panel_loops`)."""
        return panel_loops(self.pattern)

    @cached_property
    def corner_angles(self) -> tuple[dict[int, float], ...]:
        """{vertex: interior angle} of each panel's outline, radians, in the development
        (where the panel is flat); the largest where a vertex comes twice. Above pi: the
        panel wraps around that vertex (a reflex corner)."""
        xy = self.coords2d
        out = []
        for loops in self.loops:
            angles: dict[int, float] = {}
            for loop in loops:
                d_in = xy[loop] - xy[np.roll(loop, 1)]
                d_out = xy[np.roll(loop, -1)] - xy[loop]
                turn = np.arctan2(
                    d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
                    np.einsum("ij,ij->i", d_in, d_out),
                )
                for v, a in zip(loop.tolist(), (np.pi - turn).tolist(), strict=True):
                    angles[v] = max(angles.get(v, 0.0), a)
            out.append(angles)
        return tuple(out)

    # ------------------------------------------------------------------ hinges
    @cached_property
    def hinge_edges(self) -> np.ndarray:
        """(H,) int: the pattern edges that are hinges (free creases between two panels)."""
        p = self.pattern
        free = p.free_creases
        ef = p.edge_faces[free]
        return free[self.label[ef[:, 0]] != self.label[ef[:, 1]]]

    @property
    def n_hinges(self) -> int:
        return len(self.hinge_edges)

    @cached_property
    def hinge_panels(self) -> np.ndarray:
        """(H, 2) int: the panels on the left and on the right of each hinge (of
        ``edges[e, 0] -> edges[e, 1]``)."""
        return self.label[self.pattern.edge_faces[self.hinge_edges]]

    @cached_property
    def hinge_vertices(self) -> np.ndarray:
        """(H, 2) int: the two end vertices of each hinge (``edges[e]``)."""
        return self.pattern.edges[self.hinge_edges]

    @cached_property
    def hinges_of(self) -> tuple[np.ndarray, ...]:
        """The hinges ((k,) int indices into ``hinge_edges``) around each panel."""
        out: list[list[int]] = [[] for _ in range(self.n)]
        for h, (a, b) in enumerate(self.hinge_panels.tolist()):
            out[a].append(h)
            out[b].append(h)
        return tuple(np.asarray(x, dtype=np.int64) for x in out)

    def closing(self, fold_angles: np.ndarray) -> np.ndarray:
        """(..., H) float64: how far each hinge has folded towards the material side,
        radians, from fold angles (..., E) (valley positive) of the pattern's edges."""
        rho = np.asarray(fold_angles, dtype=np.float64)[..., self.hinge_edges]
        return self.sign * rho

    # ------------------------------------------------------------------ who meets whom
    @cached_property
    def neighbours(self) -> np.ndarray:
        """(N, 2) int, sorted pairs (a < b) of panels joined by at least one hinge."""
        pairs = np.sort(self.hinge_panels, axis=1)
        return np.unique(pairs, axis=0) if len(pairs) else np.zeros((0, 2), dtype=np.int64)

    @cached_property
    def vertex_panels(self) -> tuple[np.ndarray, ...]:
        """The panels ((k,) int, sorted) at each vertex."""
        faces = self.pattern.faces
        out: list[set[int]] = [set() for _ in range(self.pattern.n_vertices)]
        for f, k in enumerate(self.label.tolist()):
            for v in faces[f].tolist():
                out[v].add(k)
        return tuple(np.asarray(sorted(s), dtype=np.int64) for s in out)

    @cached_property
    def relief_vertices(self) -> np.ndarray:
        """(k,) int, sorted: vertices where two panels that are not neighbours meet, and the
        ends of hinges where a panel wraps around (a reflex corner: there it reaches around
        the hinge's axis line); their solids get a relief there
        (:mod:`rigidfold.fabricate.solids`)."""
        joined = {tuple(p) for p in self.neighbours.tolist()}
        ends = set(self.hinge_vertices.ravel().tolist())
        out = [
            v
            for corners in self.corner_angles
            for v, angle in corners.items()
            if angle > np.pi + 1e-9 and v in ends
        ]
        for v, ks in enumerate(self.vertex_panels):
            ks_ = ks.tolist()
            if any((a, b) not in joined for i, a in enumerate(ks_) for b in ks_[i + 1 :]):
                out.append(v)
        return np.unique(np.asarray(out, dtype=np.int64))

    def shared_vertices(self, a: int, b: int) -> np.ndarray:
        """(k,) int: the vertices that panels ``a`` and ``b`` both have."""
        return np.intersect1d(self.vertices[a], self.vertices[b])

    def to_dict(self) -> dict:
        """JSON-ready counts."""
        return {
            "panels": self.n,
            "hinges": self.n_hinges,
            "side": self.side,
            "relief_vertices": len(self.relief_vertices),
            "area_m2": float(self.areas.sum()),
        }
