"""The cut sheet's geometry: the development diagram laid out flat in millimetres.

A :class:`Sheet` is what the cut-sheet writers (:mod:`rigidfold.exports.cutsheet`) and the
schedule (:mod:`rigidfold.exports.schedule`) draw from: the diagram turned to its
smallest-area bounding rectangle (landscape), placed with a margin at the origin, each edge's
kind, fold angle and the outlines of the panels.

A *panel* is a facet of the pattern: triangles joined by fixed creases
(:attr:`rigidfold.mesh.CreasePattern.facets`), one rigid piece of the built sheet. Its
outline is made of the boundary edges and free creases around it; the fixed creases inside it
are not folds and are not drawn as such.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely

from rigidfold.errors import RigidfoldError
from rigidfold.io.fold import edge_assignments
from rigidfold.mesh import CreasePattern

MM_PER_M = 1000.0
"""Millimetres per metre: the sheet is drawn in millimetres at 1:1."""

MARGIN_MM = 10.0
"""Default margin around the sheet, millimetres."""

LABEL_SIZE = 0.06
"""Height of the crease labels as a fraction of the median free-crease length."""


@dataclass(frozen=True, eq=False)
class Sheet:
    """The development diagram of a design laid out on a sheet, in millimetres, y up.

    Attributes
    ----------
    pattern : CreasePattern
        The folded form (topology, fold angles and fixed creases).
    xy : (V, 2) float64
        Vertex positions on the sheet in millimetres: the diagram (metres) times
        :data:`MM_PER_M`, turned by ``angle`` and moved so that its bounding box starts at
        ``(margin, margin)``. Read-only.
    width, height : float
        Size of the sheet with its margins, millimetres (``width >= height``).
    angle : float
        Counter-clockwise rotation applied to the diagram, radians.
    margin : float
        Margin on each side, millimetres.
    assignment : list of str, length E
        Letter of each edge (:func:`rigidfold.io.fold.edge_assignments`): ``"B"`` boundary
        (cut), ``"M"`` mountain, ``"V"`` valley, ``"F"`` free crease flat in this state,
        ``"J"`` fixed crease (inside a panel, not a fold).
    """

    pattern: CreasePattern
    xy: np.ndarray
    width: float
    height: float
    angle: float
    margin: float
    assignment: list[str]

    @cached_property
    def fold_angles_deg(self) -> np.ndarray:
        """(E,) float signed fold angles of the folded form in degrees, valley positive."""
        return np.degrees(self.pattern.fold_angles)

    @cached_property
    def lengths(self) -> np.ndarray:
        """(E,) float edge lengths on the sheet, millimetres."""
        d = self.xy[self.pattern.edges[:, 1]] - self.xy[self.pattern.edges[:, 0]]
        return np.hypot(d[:, 0], d[:, 1])

    @cached_property
    def panel_loops(self) -> tuple[tuple[np.ndarray, ...], ...]:
        """Outline of each panel: see :func:`panel_loops`."""
        return panel_loops(self.pattern)

    @property
    def boundary_loop(self) -> np.ndarray:
        """(B,) int vertices of the sheet's outline (the cut), counter-clockwise."""
        return self.pattern.boundary_loop

    @property
    def text_height(self) -> float:
        """Height of the crease labels, millimetres: :data:`LABEL_SIZE` times the median
        length of the free creases (of all edges when there is none)."""
        free = self.pattern.free_creases
        lengths = self.lengths[free] if len(free) else self.lengths
        return LABEL_SIZE * float(np.median(lengths))

    def edges_of(self, letter: str) -> np.ndarray:
        """(k,) int indices of the edges assigned ``letter`` (see ``assignment``)."""
        return np.flatnonzero(np.asarray(self.assignment) == letter)


def layout_sheet(
    pattern: CreasePattern, coords2d: np.ndarray, *, margin_mm: float = MARGIN_MM
) -> Sheet:
    """Lay out the development diagram ``coords2d`` (V, 2) metres of ``pattern`` on a sheet.

    The diagram is turned (never mirrored: it stays as seen from +z, so mountains and
    valleys keep their sides) to the smallest-area bounding rectangle of its convex hull
    (:func:`min_area_angle`), a quarter turn more if that rectangle is taller than wide, and
    moved so that it starts at ``(margin_mm, margin_mm)``. Raises ValueError for
    ``coords2d`` of another shape than (V, 2) or with non-finite values, and for a negative
    margin.
    """
    xy = np.asarray(coords2d, dtype=np.float64)
    if xy.shape != (pattern.n_vertices, 2):
        raise RigidfoldError(
            f"coords2d must be a ({pattern.n_vertices}, 2) array (the development diagram of "
            f"the pattern), got shape {xy.shape}"
        )
    if not np.isfinite(xy).all():
        raise RigidfoldError("the development diagram has non-finite coordinates")
    if not (np.isfinite(margin_mm) and margin_mm >= 0):
        raise RigidfoldError(f"margin_mm must be a finite number >= 0, got {margin_mm!r}")
    xy = xy * MM_PER_M
    angle = min_area_angle(xy)
    turned = _rotate(xy, angle)
    size = np.ptp(turned, axis=0)
    if size[1] > size[0]:
        angle = float(np.angle(np.exp(1j * (angle + np.pi / 2))))
        turned = _rotate(xy, angle)
        size = np.ptp(turned, axis=0)
    placed = turned - turned.min(axis=0) + margin_mm
    placed.flags.writeable = False
    return Sheet(
        pattern=pattern,
        xy=placed,
        width=float(size[0] + 2 * margin_mm),
        height=float(size[1] + 2 * margin_mm),
        angle=angle,
        margin=float(margin_mm),
        assignment=edge_assignments(pattern, pattern.settings.geometry.flat_angle),
    )


def min_area_angle(xy: np.ndarray) -> float:
    """Counter-clockwise turn (radians, in (-pi, pi]) that brings the points ``xy`` (n, 2)
    to their smallest-area bounding rectangle, axis-aligned.

    Rotating calipers: that rectangle has a side along an edge of the convex hull, so each
    hull edge direction is tried (the first of equal areas is kept).
    """
    hull = shapely.convex_hull(shapely.multipoints(np.asarray(xy, dtype=np.float64)))
    ring = np.asarray(shapely.get_coordinates(hull))
    sides = np.diff(ring, axis=0)
    sides = sides[np.hypot(sides[:, 0], sides[:, 1]) > 0]
    if len(sides) == 0:
        return 0.0
    turns = -np.arctan2(sides[:, 1], sides[:, 0])
    c, s = np.cos(turns)[:, None], np.sin(turns)[:, None]
    x = c * ring[:, 0] - s * ring[:, 1]
    y = s * ring[:, 0] + c * ring[:, 1]
    areas = np.ptp(x, axis=1) * np.ptp(y, axis=1)
    return float(np.angle(np.exp(1j * turns[int(np.argmin(areas))])))


def panel_loops(pattern: CreasePattern) -> tuple[tuple[np.ndarray, ...], ...]:
    """The outline of every panel (facet), as closed vertex loops.

    Returns one tuple per panel ``k = 0 .. n_facets - 1`` of (m,) int vertex loops, each
    closed implicitly (last vertex back to the first), in the order of the panel's
    counter-clockwise triangles: the outer outline counter-clockwise, a hole (a panel around
    another) clockwise. The outline is made of the half-edges of the panel's triangles whose
    other side is another panel or nothing (boundary).
    """
    faces, facets = pattern.faces, pattern.facets
    ef, fe = pattern.edge_faces, pattern.face_edges
    other = np.where(ef[fe, 0] == np.arange(len(faces))[:, None], ef[fe, 1], ef[fe, 0])
    outside = (other < 0) | (facets[np.maximum(other, 0)] != facets[:, None])
    loops: list[list[np.ndarray]] = [[] for _ in range(pattern.n_facets)]
    for k in range(pattern.n_facets):
        f, corner = np.nonzero(outside & (facets == k)[:, None])
        starts = faces[f, corner].tolist()
        ends = faces[f, (corner + 1) % 3].tolist()
        following: dict[int, list[int]] = {}
        for u, v in zip(starts, ends, strict=True):
            following.setdefault(u, []).append(v)
        for first in starts:
            if not following.get(first):
                continue
            loop = [first]
            v = following[first].pop(0)
            while v != first:
                loop.append(v)
                v = following[v].pop(0)
            loops[k].append(np.asarray(loop, dtype=np.int64))
    return tuple(tuple(panel) for panel in loops)


def polygon_area(xy: np.ndarray, loop: np.ndarray) -> float:
    """Signed area of the closed polygon ``xy[loop]`` (positive counter-clockwise).

    xy : (V, 2) float; loop : (m,) int.
    """
    p = np.asarray(xy, dtype=np.float64)[loop]
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def _rotate(xy: np.ndarray, angle: float) -> np.ndarray:
    """``xy`` (n, 2) turned counter-clockwise by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    return xy @ np.array([[c, s], [-s, c]])
