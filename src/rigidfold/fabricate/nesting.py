"""True-outline nesting of flat parts onto stock sheets (bottom-left fill by no-fit polygons).

The parts of the cut sheets (:mod:`rigidfold.fabricate.cutsheets`) are placed by their own
outlines, not their boxes: largest first, each at a few turns (quarter turns of its frame,
and its convex hull's longest side along either edge), at the leftmost-then-lowest spot of
the first sheet where it fits, a new sheet opened where it fits on none. Parts are turned
and moved, never mirrored.

The spots where a part keeps ``gap`` from every part already on a sheet are found exactly by
no-fit polygons: each outline is cut into convex pieces (a polygon that is nearly convex is
taken as its convex hull, which only widens the gap; else it is cut into triangles), and the
shift ``t`` of a piece ``B`` keeps the gap from a placed piece ``A`` when ``t`` lies outside
the convex polygon ``A - B + K`` (Minkowski sums, :func:`minkowski`; ``K``: a regular
polygon of ``fabricate_nest_gap_sides`` sides whose inscribed circle has the gap plus
``2 fabricate_nest_margin`` as its radius, so ``A - B + K`` holds ``A - B`` grown by the
gap: the gap is kept, at most ``1 / cos(pi / sides) - 1`` of it wider). The free spots are
the rectangle of shifts that keep the gap from the sheet's edges less those polygons; the
lowest of its leftmost corners is taken. Every comparison is made on coordinates rounded to
``fabricate_nest_round`` mm, ties broken by the turn's and the sheet's order, so the result
does not depend on floating-point noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from rigidfold.config import DEFAULTS, Settings


@dataclass(frozen=True)
class Spot:
    """Where :func:`nest_outlines` put one part: ``item`` (its index in the list given) on
    stock sheet ``sheet`` (0, 1, ...), turned by ``angle`` radians counter-clockwise about
    the origin of its own frame, then moved by (``x``, ``y``) mm."""

    item: int
    sheet: int
    angle: float
    x: float
    y: float


def convex_pieces(cut: shapely.Geometry, concavity: float) -> list[np.ndarray]:
    """Convex polygons whose union holds ``cut`` (vertices (n, 2) float64 each, no repeat):
    each polygon of ``cut`` whose convex hull exceeds its area by at most ``concavity``
    of it (and that has no holes) as that hull, any other cut into triangles (constrained
    Delaunay)."""
    out = []
    for poly in getattr(cut, "geoms", [cut]):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        hull = shapely.convex_hull(poly)
        if hull.geom_type != "Polygon" or not hull.area > 0:
            continue
        if not poly.interiors and hull.area <= (1.0 + concavity) * poly.area:
            out.append(_ring(hull))
            continue
        for tri in shapely.get_parts(shapely.constrained_delaunay_triangles(poly)):
            if tri.area > 0:
                out.append(_ring(tri))
    return out


def _ring(polygon: shapely.Geometry) -> np.ndarray:
    return np.asarray(polygon.exterior.coords, dtype=np.float64)[:-1]


PAD = 10.0
"""The angle given to a padding edge (of length 0): past every true edge's (below 2 pi)."""


@dataclass(frozen=True)
class Convex:
    """A convex polygon as its edges in counter-clockwise order, from the vertex where the
    edge of the smallest direction angle starts: ``start`` (2,), ``edges`` (k, 2),
    ``angles`` (k,) each edge's direction in [0, 2 pi), increasing (:data:`PAD` for an edge
    of length 0). Two such polygons are added (Minkowski) by merging their edges by angle
    from the sum of their starts (:func:`minkowski`)."""

    start: np.ndarray
    edges: np.ndarray
    angles: np.ndarray

    @staticmethod
    def of(ring: np.ndarray) -> Convex:
        """From the vertices (n, 2) of a convex polygon, either way round, no repeat."""
        ring = np.asarray(ring, dtype=np.float64)
        x, y = ring[:, 0], ring[:, 1]
        if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) < 0:
            ring = ring[::-1]
        edges = np.roll(ring, -1, axis=0) - ring
        angles = np.arctan2(edges[:, 1], edges[:, 0]) % (2 * math.pi)
        angles[(edges[:, 0] == 0) & (edges[:, 1] == 0)] = PAD
        i = int(np.argmin(angles))
        return Convex(ring[i], np.roll(edges, -i, axis=0), np.roll(angles, -i))

    @property
    def ring(self) -> np.ndarray:
        """Its vertices (k, 2), from ``start``."""
        return self.start + np.vstack([[0.0, 0.0], np.cumsum(self.edges[:-1], axis=0)])


def minkowski(
    starts: np.ndarray, edges: np.ndarray, angles: np.ndarray, other: Convex
) -> np.ndarray:
    """The vertices (N, k + m, 2) of the sums of N convex polygons (``starts`` (N, 2),
    ``edges`` (N, k, 2), ``angles`` (N, k), padded with edges of length 0 at :data:`PAD`)
    and ``other`` (m edges): each sum's edges are both's, merged by angle (stable), from the
    sum of their starts; the vertices after the last true edge are the start itself (not
    the sum of the edges, a rounding away from it)."""
    n = len(starts)
    all_edges = np.concatenate([edges, np.broadcast_to(other.edges, (n, *other.edges.shape))], 1)
    all_angles = np.concatenate([angles, np.broadcast_to(other.angles, (n, len(other.angles)))], 1)
    order = np.argsort(all_angles, axis=1, kind="stable")
    merged = np.take_along_axis(all_edges, order[:, :, None], axis=1)
    steps = np.cumsum(merged, axis=1)
    steps = np.concatenate([np.zeros((n, 1, 2)), steps[:, :-1]], axis=1)
    real = (all_angles < PAD).sum(axis=1)
    steps[np.arange(all_angles.shape[1])[None, :] >= real[:, None]] = 0.0  # back at the start
    return (starts + other.start)[:, None, :] + steps


def _padded(pieces: list[Convex]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``pieces`` as the arrays of :func:`minkowski`: starts, edges and angles padded."""
    k = max(len(p.edges) for p in pieces)
    edges = np.zeros((len(pieces), k, 2))
    angles = np.full((len(pieces), k), PAD)
    for i, p in enumerate(pieces):
        edges[i, : len(p.edges)] = p.edges
        angles[i, : len(p.angles)] = p.angles
    return np.array([p.start for p in pieces]), edges, angles


@dataclass(frozen=True)
class _Pose:
    """One part at one turn: its convex pieces grown by half the gap (``grown``) and the
    same turned half round about the origin (``negative``, for the no-fit polygons), moved
    so that its outline's box starts at (0, 0); the box's size (mm) and where that box
    started before (``low``)."""

    angle: float
    grown: tuple[Convex, ...]
    negative: tuple[Convex, ...]
    width: float
    height: float
    low: tuple[float, float]


def _poses(
    cut: shapely.Geometry, pieces: list[np.ndarray], half: Convex, angles: list[float]
) -> list[_Pose]:
    coords = np.asarray(shapely.get_coordinates(cut), dtype=np.float64)
    out = []
    for angle in angles:
        c, s = math.cos(angle), math.sin(angle)
        turn = np.array([[c, s], [-s, c]])  # row vectors: x @ turn turns x by angle
        ring = coords @ turn
        low, high = ring.min(axis=0), ring.max(axis=0)
        grown = []
        for p in pieces:
            q = Convex.of(p @ turn - low)
            grown.append(
                Convex.of(minkowski(q.start[None], q.edges[None], q.angles[None], half)[0])
            )
        size = high - low
        out.append(
            _Pose(
                angle,
                tuple(grown),
                tuple(Convex.of(-g.ring) for g in grown),
                float(size[0]),
                float(size[1]),
                (float(low[0]), float(low[1])),
            )
        )
    return out


def turns(cut: shapely.Geometry) -> list[float]:
    """The turns a part is tried at, radians: the four quarter turns of its frame, and the
    two that lay its convex hull's longest side along x (either way round), the repeats
    (within 1e-9) left out, in that order."""
    hull = shapely.convex_hull(cut)
    angles = [0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi]
    if hull.geom_type == "Polygon":
        ring = np.asarray(hull.exterior.coords)
        sides = np.diff(ring, axis=0)
        i = int(np.argmax(np.round(np.hypot(sides[:, 0], sides[:, 1]), 6)))
        along = -math.atan2(sides[i, 1], sides[i, 0]) % (2 * math.pi)
        angles += [along, (along + math.pi) % (2 * math.pi)]
    out: list[float] = []
    for a in angles:
        if all(min(abs(a - b), 2 * math.pi - abs(a - b)) > 1e-9 for b in out):
            out.append(a)
    return out


class _Sheet:
    """The grown convex pieces placed on one stock sheet so far (:func:`minkowski`'s arrays
    of them kept until the next is placed)."""

    def __init__(self) -> None:
        self.pieces: list[Convex] = []
        self._arrays: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def add(self, pieces: tuple[Convex, ...], x: float, y: float) -> None:
        shift = np.array([x, y])
        self.pieces += [Convex(p.start + shift, p.edges, p.angles) for p in pieces]
        self._arrays = None

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self._arrays is None:
            self._arrays = _padded(self.pieces)
        return self._arrays


def nest_outlines(
    cuts: list[shapely.Geometry],
    width: float,
    height: float,
    gap: float,
    *,
    settings: Settings = DEFAULTS,
) -> list[Spot] | None:
    """Place the outlines ``cuts`` (each in its own frame, mm) on stock sheets ``width`` x
    ``height`` mm, ``gap`` mm apart and from the edges (see the module's text). Returns one
    :class:`Spot` per cut, in the order of ``cuts``; ``None`` where a cut is empty or fits
    on no empty sheet (the caller nests them otherwise)."""
    f = settings.fabricate
    grain = f.nest_round
    sides = f.nest_gap_sides
    radius = (0.5 * gap + f.nest_margin) / math.cos(math.pi / sides)
    phi = 2 * math.pi * np.arange(sides) / sides
    half = Convex.of(radius * np.column_stack([np.cos(phi), np.sin(phi)]))
    edge = gap + f.nest_margin

    areas = [round(float(shapely.area(c)) / grain**2) for c in cuts]
    sheets: list[_Sheet] = []
    spots: dict[int, Spot] = {}
    for i in sorted(range(len(cuts)), key=lambda i: (-areas[i], i)):
        pieces = convex_pieces(cuts[i], f.nest_concavity)
        if not pieces:
            return None
        poses = _poses(cuts[i], pieces, half, turns(cuts[i]))
        for sheet in sheets:
            found = _best(poses, sheet, width, height, edge, grain)
            if found is not None:
                break
        else:
            sheet = _Sheet()
            found = _best(poses, sheet, width, height, edge, grain)
            if found is None:
                return None
            sheets.append(sheet)
        pose, x, y = found
        sheet.add(pose.grown, x, y)
        spots[i] = Spot(i, sheets.index(sheet), pose.angle, x - pose.low[0], y - pose.low[1])
    return [spots[i] for i in range(len(cuts))]


def _best(
    poses: list[_Pose], sheet: _Sheet, width: float, height: float, edge: float, grain: float
) -> tuple[_Pose, float, float] | None:
    """The pose and shift (of its box's corner) that put a part leftmost, then lowest, on
    ``sheet``, ``edge`` from its edges and clear of the parts on it: each pose at its
    leftmost-then-lowest spot (:func:`_leftmost`), the one whose box starts leftmost, then
    lowest, then the first; ``None`` where no pose fits."""
    best = None
    for k, pose in enumerate(poses):
        frame = (edge, edge, width - edge - pose.width, height - edge - pose.height)
        if frame[2] < frame[0] or frame[3] < frame[1]:
            continue
        spot = frame[:2] if not sheet.pieces else _leftmost(pose, sheet, frame, grain)
        if spot is None:
            continue
        key = (round(spot[0] / grain), round(spot[1] / grain), k)
        if best is None or key < best[0]:
            best = (key, pose, spot[0], spot[1])
    return None if best is None else best[1:]


def _leftmost(
    pose: _Pose, sheet: _Sheet, frame: tuple[float, float, float, float], grain: float
) -> tuple[float, float] | None:
    """The leftmost-then-lowest shift in ``frame`` (x0, y0, x1, y1) at which ``pose`` keeps
    clear of the grown pieces on ``sheet`` (outside every no-fit polygon), or ``None``: the
    lowest of the leftmost corners of the frame less the no-fit polygons (by coordinates
    rounded to ``grain``)."""
    starts, edges, angles = sheet.arrays()
    free = shapely.box(*frame)
    for b in pose.negative:  # the no-fit polygons taken off one by one: faster than their union
        for nfp in shapely.polygons(minkowski(starts, edges, angles, b)):
            free = shapely.difference(free, nfp)
            if free.is_empty:
                return None
    xy = np.asarray(shapely.get_coordinates(free), dtype=np.float64)
    keys = np.round(xy / grain)
    j = int(np.lexsort((keys[:, 1], keys[:, 0]))[0])
    return float(xy[j, 0]), float(xy[j, 1])
