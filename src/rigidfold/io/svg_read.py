"""Reading crease patterns drawn as SVG in Origami Simulator's colour convention.

Origami Simulator (https://origamisimulator.org, ``js/pattern.js``) reads a crease pattern
from the stroke colours of an SVG drawing: black boundary, red mountain, blue valley, yellow
flat facet lines, magenta undriven creases, green cuts, and a crease's stroke opacity as the
fraction of 180 degrees it folds. :func:`read_svg` reads such a drawing into its planar
faces, in the drawing's own coordinates (user units, y flipped to point up).

What is read (svgelements parses the file: transforms, ``viewBox``, ``<use>``, styles):

* every ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>`` and ``<path>`` with a stroke;
  unstroked shapes, text and images are not drawn lines and are skipped. A curved piece
  (an arc, a Bezier curve, a circle, an ellipse, a rounded rect) is refused;
* colours by hue (:data:`COLOURS`), so ``#FF0000``, ``#f00``, ``rgb(255,0,0)`` and ``red``
  are all mountains; green cuts are refused;
* lines are split where they cross or where one ends on another, points closer than
  ``Settings.svg_merge_tol`` times the drawing's bounding-box diagonal are merged, and
  pieces shorter than that are dropped. A piece drawn twice is kept once: if one drawing
  is black it stays boundary, other differing colours are refused. Where just two pieces
  of the same colour and opacity meet in a straight line, they become one line;
* the black lines must form one closed outline, every crease must lie inside it and end
  on another line, and every face must be a simple polygon (no holes, no crease loop
  hanging at one point). Each problem is a one-line ``ValueError`` naming the file.

Units: when the root ``<svg>`` gives its ``width`` in mm, cm, in or pt, :attr:`SvgDrawing.unit`
is that unit and :attr:`SvgDrawing.scale` the metres per user unit (the width over the
``viewBox`` width, or one CSS pixel, 1/96 in, without a ``viewBox``); a width in px or none
is ``"unit"``, scale 1.
"""

from __future__ import annotations

import colorsys
import math
import os
import re
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path

import numpy as np
import shapely
import svgelements as se
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from rigidfold.config import DEFAULTS, Settings
from rigidfold.io.fold import UNITS

COLOURS = {"B": "black", "M": "red", "V": "blue", "F": "yellow", "U": "magenta", "C": "green"}
"""Origami Simulator's stroke colours by FOLD letter. A stroke whose brightest channel is
below 25 % is black; one with saturation and brightness of at least 50 % whose hue is less
than :data:`HUE_TOLERANCE` degrees from red (0), yellow (60), green (120), blue (240) or
magenta (300) is that colour; any other stroke is refused."""

HUE_TOLERANCE = 30.0
"""Largest hue difference (degrees) of a stroke from its colour in :data:`COLOURS`."""

_HUES = {"M": 0.0, "F": 60.0, "C": 120.0, "V": 240.0, "U": 300.0}
_SHAPES = (se.SimpleLine, se.Polyline, se.Polygon, se.Rect, se.Path, se.Circle, se.Ellipse)


@dataclass(frozen=True, eq=False)
class SvgDrawing:
    """A crease pattern drawn in SVG, read into its planar faces.

    Attributes
    ----------
    xy : (V, 2) float64
        Vertex positions in drawing (user) units, y up (SVG's y negated), not translated.
    polygons : list of F lists of int
        The faces (regions bounded by the lines inside the boundary), each counter-clockwise
        seen from +z, at least 3 vertices, none repeated; every consecutive pair is an edge.
    edges : (E, 2) int64
        Every line piece after splitting at intersections and merging vertices.
    assignment : list of E str
        ``"B"`` boundary (black), ``"M"`` mountain (red), ``"V"`` valley (blue), ``"F"``
        flat facet line (yellow), ``"U"`` undriven crease (magenta).
    unit : str
        ``"unit"`` when the drawing gives no physical unit, else a key of
        :data:`rigidfold.io.fold.UNITS` (``"mm"``, ``"cm"``, ``"in"``, ``"pt"``).
    scale : float
        Metres per drawing unit (1.0 for ``"unit"``).
    fold_angles : (E,) float64 or None
        Origami Simulator's target fold angles, degrees: stroke opacity times 180, valleys
        positive, mountains negative; 0 for boundary and facet lines, NaN for undriven ones.
    """

    xy: np.ndarray
    polygons: list[list[int]]
    edges: np.ndarray
    assignment: list[str]
    unit: str
    scale: float
    fold_angles: np.ndarray | None


def read_svg(path: str | os.PathLike, *, settings: Settings = DEFAULTS) -> SvgDrawing:
    """Read a crease pattern drawn in SVG (Origami Simulator's colours); see the module.

    Parameters
    ----------
    path : str or path-like
        The SVG file.
    settings : Settings
        ``svg_merge_tol``: points closer than this times the bounding-box diagonal of all
        lines are one vertex.

    Raises
    ------
    ValueError
        One line naming the file: unreadable, not an SVG, no lines, a curve, an unknown or
        a cut (green) colour, no boundary, a boundary that is not one closed outline (open,
        branching, several pieces, holes), creases outside the boundary, a crease ending
        inside a face, a face that is not a simple polygon.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        svg = se.SVG.parse(BytesIO(data))
    except (ElementTree.ParseError, ValueError) as exc:
        raise ValueError(f"not an SVG file: {path}: {exc}") from None
    if not isinstance(svg, se.SVG):
        raise ValueError(f"not an SVG file: {path}: the root element is not <svg>")
    try:
        return _read(svg, settings)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def _read(svg: se.SVG, settings: Settings) -> SvgDrawing:
    unit, scale, to_user = _units(svg)
    ends, letters, angles = _lines(svg, to_user)
    tol = settings.svg_merge_tol * float(np.linalg.norm(np.ptp(ends.reshape(-1, 2), axis=0)))
    xy, edges, letters, angles = _node(ends, letters, angles, tol)
    xy, edges, letters, angles = _join_straight(xy, edges, letters, angles, tol)
    _check_creases(xy, edges, letters, _check_boundary(xy, edges, letters), tol)
    return SvgDrawing(
        xy=xy,
        polygons=_faces(xy, edges),
        edges=edges,
        assignment=letters,
        unit=unit,
        scale=scale,
        fold_angles=np.array(angles),
    )


# ------------------------------------------------------------------------- the drawing
def _units(svg: se.SVG) -> tuple[str, float, se.Matrix]:
    """(unit, metres per user unit, matrix from svgelements' pixels to user units)."""
    to_user = ~se.Matrix(svg.viewbox_transform) if svg.viewbox_transform else se.Matrix()
    width = str(svg.values.get("width", ""))
    match = re.fullmatch(r"\s*(\+?[\d.]+(?:[eE][-+]?\d+)?)\s*(mm|cm|in|pt)\s*", width)
    if match is None or not svg.width > 0:
        return "unit", 1.0, to_user
    unit = match.group(2)
    if not svg.viewbox_transform:
        return unit, UNITS["in"] / 96, to_user  # a user unit is a CSS pixel
    px_x, px_y = abs(1 / to_user.a), abs(1 / to_user.d)  # pixels per user unit
    if not math.isclose(px_x, px_y, rel_tol=1e-9):
        raise ValueError("the width, height and viewBox scale x and y differently")
    return unit, px_x * float(match.group(1)) * UNITS[unit] / svg.width, to_user


def _lines(svg: se.SVG, to_user: se.Matrix) -> tuple[np.ndarray, list[str], list[float]]:
    """Every straight piece drawn: ends (n, 2, 2) in user units y up, letters, fold angles."""
    ends, letters, angles = [], [], []
    shapes = [e for e in svg.elements() if isinstance(e, _SHAPES)]
    for k, shape in enumerate(shapes, start=1):
        tag = shape.values.get("tag", type(shape).__name__.lower())
        name = f'<{tag} id="{shape.id}">' if shape.id else f"<{tag}> (drawn element {k})"
        if shape.stroke is None or shape.stroke.value is None:
            continue
        letter = _letter(shape.stroke, shape.values.get("stroke"), name)
        opacity = _opacity(shape, name)
        angle = {"M": -180.0 * opacity, "V": 180.0 * opacity, "U": math.nan}.get(letter, 0.0)
        for piece in se.Path(shape).segments():
            if isinstance(piece, se.Move):
                continue
            if not isinstance(piece, se.Line | se.Close):
                raise ValueError(
                    f"{name} has a curved piece ({type(piece).__name__}): creases and the "
                    "boundary must be straight lines"
                )
            a, b = (
                to_user.point_in_matrix_space(piece.start),
                to_user.point_in_matrix_space(piece.end),
            )
            ends.append([[a.x, 0.0 - a.y], [b.x, 0.0 - b.y]])
            letters.append(letter)
            angles.append(angle)
    if not ends:
        raise ValueError(
            "no lines drawn: a crease pattern is <line>, <polyline>, <polygon>, <rect> or "
            "<path> elements with a stroke"
        )
    if "B" not in letters:
        raise ValueError("no boundary: no black lines (Origami Simulator draws it black)")
    return np.array(ends, dtype=float), letters, angles


def _opacity(shape: se.Shape, name: str) -> float:
    """Stroke opacity times opacity, in [0, 1], as written (svgelements' colour keeps 8 bits)."""
    values = shape.values
    try:
        opacity = float(values.get("stroke-opacity", shape.stroke.opacity))
        opacity *= float(values.get("opacity", 1.0))
    except ValueError:
        raise ValueError(f"{name} has an opacity that is not a number") from None
    return min(max(opacity, 0.0), 1.0)


def _letter(colour: se.Color, written: str | None, name: str) -> str:
    """The FOLD letter of a stroke colour (:data:`COLOURS`); ValueError for others."""
    hue, saturation, value = colorsys.rgb_to_hsv(
        colour.red / 255, colour.green / 255, colour.blue / 255
    )
    if value < 0.25:
        return "B"
    if saturation >= 0.5 and value >= 0.5:
        for letter, centre in _HUES.items():
            if abs((360 * hue - centre + 180) % 360 - 180) < HUE_TOLERANCE:
                if letter == "C":
                    raise ValueError(f"{name} is green, a cut: cuts are not supported")
                return letter
    shown = colour.hex[:7]
    if written and written.strip().lower() != shown:
        shown = f"{written.strip()} ({shown})"
    raise ValueError(
        f"{name} has stroke colour {shown}, none of Origami Simulator's: black boundary, red "
        "mountain, blue valley, yellow flat, magenta undriven"
    )


# ------------------------------------------------------------------------- the geometry
def _node(
    ends: np.ndarray, letters: list[str], angles: list[float], tol: float
) -> tuple[np.ndarray, np.ndarray, list[str], list[float]]:
    """The drawn pieces split where they meet, close points merged, repeats dropped.

    ends : (n, 2, 2) float; letters, angles : n each; tol : merge distance.
    Returns xy (V, 2), edges (E, 2) int64 (in drawing order), their letters and angles.
    """
    a, b = ends[:, 0], ends[:, 1]
    length = np.linalg.norm(b - a, axis=1)
    drawn = np.flatnonzero(length > tol)
    if not len(drawn):
        raise ValueError("the lines drawn have no length")
    a, b, length = a[drawn], b[drawn], length[drawn]
    seg, t, points = _splits(a, b, length, tol)
    n = len(drawn)
    seg = np.concatenate([np.arange(n), np.arange(n), seg])
    t = np.concatenate([np.zeros(n), np.ones(n), t])
    points = np.concatenate([a, b, points])
    order = np.lexsort((t, seg))
    seg, points = seg[order], points[order]
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray")
    vertex = connected_components(_graph(pairs, len(points)), directed=False)[1]
    first = np.unique(vertex, return_index=True)[1]  # first point of each merged vertex
    piece = np.flatnonzero(seg[:-1] == seg[1:])
    kept: dict[tuple[int, int], int] = {}
    edges: list[tuple[int, int]] = []
    out_letters, out_angles = [], []
    for k in piece:
        u, v, source = int(vertex[k]), int(vertex[k + 1]), drawn[seg[k]]
        letter, key = letters[source], (min(u, v), max(u, v))
        if u == v:
            continue
        if key not in kept:
            kept[key] = len(edges)
            edges.append((u, v))
            out_letters.append(letter)
            out_angles.append(angles[source])
            continue
        e = kept[key]
        if letter == "B":
            out_letters[e], out_angles[e] = "B", 0.0
        elif out_letters[e] not in ("B", letter):
            raise ValueError(
                f"the line from {_at(points[first[u]])} to {_at(points[first[v]])} is drawn "
                f"both {COLOURS[out_letters[e]]} and {COLOURS[letter]}"
            )
    return (*_compact(points[first], np.array(edges, dtype=np.int64)), out_letters, out_angles)


def _splits(
    a: np.ndarray, b: np.ndarray, length: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where pieces must be split: where an end of another piece lies within ``tol`` of
    their interior (a T-junction: split at the foot of the perpendicular from that end) and
    where two pieces cross.

    a, b : (n, 2) float, the pieces' ends; length : (n,) float, all > tol.
    Returns the piece index (k,), the parameter along it (k,) and the point (k, 2).
    """
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    i, j = shapely.STRtree(lines).query(lines, predicate="dwithin", distance=tol)
    i, j = i[i < j], j[i < j]
    seg, t, points = [], [], []

    def interior(s: np.ndarray, on: np.ndarray) -> np.ndarray:
        return (s * length[on] > tol) & ((1 - s) * length[on] > tol)

    for on, other in ((i, j), (j, i)):
        d = b[on] - a[on]
        for end in (a[other], b[other]):
            s = np.sum((end - a[on]) * d, axis=1) / length[on] ** 2
            foot = a[on] + s[:, None] * d
            hit = interior(s, on) & (np.linalg.norm(foot - end, axis=1) <= tol)
            seg.append(on[hit])
            t.append(s[hit])
            points.append(foot[hit])
    di, dj, r = b[i] - a[i], b[j] - a[j], a[j] - a[i]
    denom = _cross(di, dj)
    parallel = denom == 0
    si = np.divide(_cross(r, dj), denom, out=np.full(len(i), np.nan), where=~parallel)
    sj = np.divide(_cross(r, di), denom, out=np.full(len(i), np.nan), where=~parallel)
    hit = interior(si, i) & interior(sj, j)
    crossing = a[i][hit] + si[hit, None] * di[hit]
    seg += [i[hit], j[hit]]
    t += [si[hit], sj[hit]]
    points += [crossing, crossing]
    return np.concatenate(seg), np.concatenate(t), np.concatenate(points).reshape(-1, 2)


def _join_straight(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], angles: list[float], tol: float
) -> tuple[np.ndarray, np.ndarray, list[str], list[float]]:
    """Vertices where just two edges of one letter and angle meet in a straight line (within
    ``tol``) removed, the two edges made one. xy (V, 2), edges (E, 2) -> the same, fewer."""
    ends = edges.tolist()
    incident: list[set[int]] = [set() for _ in xy]
    for e, (u, v) in enumerate(ends):
        incident[u].add(e)
        incident[v].add(e)
    alive = np.ones(len(ends), dtype=bool)
    for w, around in enumerate(incident):
        if len(around) != 2:
            continue
        e, f = sorted(around)
        p, q = sum(ends[e]) - w, sum(ends[f]) - w  # the other ends: p - w - q
        same = letters[e] == letters[f] and (
            angles[e] == angles[f] or (math.isnan(angles[e]) and math.isnan(angles[f]))
        )
        chord = xy[q] - xy[p]
        off = abs(_cross(chord, xy[w] - xy[p])) / np.linalg.norm(chord)
        inside = np.dot(xy[p] - xy[w], xy[q] - xy[w]) < 0
        joined = any(q in ends[g] for g in incident[p])
        if not (same and off <= tol and inside) or joined:
            continue
        ends[e] = [q if x == w else x for x in ends[e]]
        alive[f] = False
        incident[q].remove(f)
        incident[q].add(e)
        around.clear()
    keep = np.flatnonzero(alive)
    xy, edges = _compact(xy, np.array(ends, dtype=np.int64)[keep])
    return xy, edges, [letters[e] for e in keep], [angles[e] for e in keep]


def _compact(xy: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Only the vertices that edges use, numbered in order of first use.
    xy (V, 2), edges (E, 2) -> xy (V', 2), edges (E, 2)."""
    used, first = np.unique(edges.ravel(), return_index=True)
    order = used[np.argsort(first)]
    number = np.full(len(xy), -1)
    number[order] = np.arange(len(order))
    return xy[order], number[edges]


# ------------------------------------------------------------------------- the faces
def _check_boundary(xy: np.ndarray, edges: np.ndarray, letters: list[str]) -> list[int]:
    """The black edges' one closed outline (counter-clockwise vertex indices); ValueError
    when it is open, branches, or is several outlines (a hole among them)."""
    black = edges[np.array(letters) == "B"]
    degree = np.bincount(black.ravel(), minlength=len(xy))
    if (degree == 1).any():
        raise ValueError(
            f"the boundary (black) is not closed: it ends at {_at(xy[degree == 1][0])}"
        )
    if (degree > 2).any():
        w = int(np.argmax(degree))
        raise ValueError(
            f"the boundary (black) is not one outline: {degree[w]} black lines meet at {_at(xy[w])}"
        )
    loops = [cycle for cycle, area in _cycles(xy, black) if area > 0]
    if len(loops) == 1:
        return loops[0]
    if not loops:
        raise ValueError("the boundary (black) encloses no area")
    outlines = [shapely.Polygon(xy[loop]) for loop in loops]
    for loop in loops:
        x, y = xy[loop[0]]
        if sum(shapely.contains_xy(outlines, x, y)) > 0:
            raise ValueError(
                f"the black outline through {_at(xy[loop[0]])} lies inside another: holes "
                "are not supported"
            )
    raise ValueError(f"the boundary (black) is {len(loops)} separate outlines, not one sheet")


def _check_creases(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], boundary: list[int], tol: float
) -> None:
    """ValueError for a crease outside the ``boundary`` (its vertex indices), a crease end
    that touches no other line, or creases not connected to the boundary."""
    outline = shapely.Polygon(xy[boundary])
    mid = xy[edges].mean(axis=1)
    outside = ~shapely.contains_xy(outline, mid[:, 0], mid[:, 1]) & (np.array(letters) != "B")
    if outside.any():
        u, v = edges[np.argmax(outside)]
        raise ValueError(f"the crease from {_at(xy[u])} to {_at(xy[v])} lies outside the boundary")
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    if (degree == 1).any():
        raise ValueError(
            f"a crease ends inside a face at {_at(xy[degree == 1][0])}: creases must end on "
            f"another line (an end within {tol:.3g} drawing units of a line is joined to it)"
        )
    n, component = connected_components(_graph(edges, len(xy)), directed=False)
    if n > 1:
        raise ValueError(
            f"creases around {_at(xy[component != component[0]][0])} are not connected to the "
            "boundary: the face around them would have a hole"
        )


def _faces(xy: np.ndarray, edges: np.ndarray) -> list[list[int]]:
    """The bounded faces of the drawing's plane graph, counter-clockwise; ValueError for one
    that is not a simple polygon. xy (V, 2), edges (E, 2) -> F lists of vertex indices."""
    faces = [cycle for cycle, area in _cycles(xy, edges) if area > 0]
    for face in faces:
        seen: set[int] = set()
        for w in face:
            if w in seen:
                raise ValueError(
                    f"a face is not a simple polygon: its outline passes twice through "
                    f"{_at(xy[w])} (a crease with the same face on both sides, or crease "
                    "loops touching at one point)"
                )
            seen.add(w)
    return faces


def _cycles(xy: np.ndarray, edges: np.ndarray) -> list[tuple[list[int], float]]:
    """Every face cycle of a plane graph, each with its signed area: bounded faces run
    counter-clockwise (area > 0), the outer face of each connected part clockwise.

    Each directed edge u -> v is followed by the edge out of v next clockwise from v -> u,
    which keeps the face on the left. xy (V, 2), edges (E, 2) -> list of (vertices, area).
    """
    tail = np.concatenate([edges[:, 0], edges[:, 1]])
    head = np.concatenate([edges[:, 1], edges[:, 0]])
    twin = np.roll(np.arange(len(tail)), len(edges))
    d = xy[head] - xy[tail]
    order = np.lexsort((np.arctan2(d[:, 1], d[:, 0]), tail))  # around each vertex, ccw
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    start = np.searchsorted(tail[order], tail)  # where each vertex's ring begins
    degree = np.bincount(tail, minlength=len(xy))[tail]
    following = order[start[twin] + (rank[twin] - start[twin] - 1) % degree[twin]]
    cycles, done = [], np.zeros(len(tail), dtype=bool)
    for h in range(len(tail)):
        cycle, g = [], h
        while not done[g]:
            done[g] = True
            cycle.append(int(tail[g]))
            g = following[g]
        if cycle:
            x, y = xy[cycle].T
            area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
            cycles.append((cycle, area))
    return cycles


def _graph(edges: np.ndarray, n: int) -> coo_matrix:
    """The (n, n) adjacency matrix of the edges (E, 2)."""
    return coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))


def _cross(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """z component of p x q; p, q : (..., 2) float -> (...)."""
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _at(point: np.ndarray) -> str:
    """A point (2,) y up as the file's coordinates, for messages: ``(x, y)``, y down."""
    return f"({point[0]:.6g}, {-point[1] + 0.0:.6g})"
