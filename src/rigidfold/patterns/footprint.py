"""Crease patterns over any simple polygon: a quality constrained Delaunay triangulation.

The footprint is a simple polygon in metres, given as text ``"x1,y1; x2,y2; ..."`` (read by
:mod:`rigidfold.generate.specs`) or as a file of one ``x,y`` (or ``x y``) pair per line
(:func:`read_footprint`). :func:`footprint_mesh` triangulates it with
Jonathan Shewchuk's Triangle (the ``triangle`` package): constrained to the polygon's sides,
no angle below the design's theta_min where the geometry allows, and no triangle larger than
the equilateral triangle of the target edge length. The points that Triangle adds on the
boundary lie on the polygon's sides, so every side stays straight and constraint (7) keeps
it straight.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.patterns.grids import check_extent, counter_clockwise

_PAIR = re.compile(r"^\s*(\S+?)\s*(?:,|\s)\s*(\S+)\s*$")


def read_footprint(path: str | os.PathLike, settings: Settings = DEFAULTS) -> np.ndarray:
    """Polygon vertices (N, 2) from a file of one ``x,y`` or ``x y`` pair per line (blank
    lines and lines starting with ``#`` skipped; :func:`footprint_points`), checked by
    :func:`check_footprint`."""
    given, path = os.fspath(path), Path(path).expanduser()
    if not path.is_file():
        raise RigidfoldError(
            f"mesh footprint {given!r} is neither 'x1,y1;x2,y2;...' nor an existing file"
        )
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise RigidfoldError(f"cannot read footprint file {os.fspath(path)!r}: {exc}") from None
    points = footprint_points(lines, f"footprint file {os.fspath(path)!r}: line")
    return check_footprint(points, settings)


def footprint_points(lines: list[str], where: str) -> np.ndarray:
    """The (N, 2) float64 points of ``lines``, one ``x,y`` or ``x y`` pair each (blank lines
    and lines starting with ``#`` skipped), unchecked but for being numbers; a last point
    equal to the first (a closed outline, as CAD and GIS tools write them) is dropped. A bad
    line is a one-line RigidfoldError ``"<where> <k> is not an 'x,y' pair of numbers"``."""
    points = []
    for k, line in enumerate(lines, 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        match = _PAIR.match(line)
        try:
            if match is None:
                raise ValueError
            points.append((float(match[1]), float(match[2])))
        except ValueError:
            raise RigidfoldError(
                f"{where} {k} is not an 'x,y' pair of numbers: {line.strip()!r}"
            ) from None
    xy = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(xy) > 3 and np.array_equal(xy[0], xy[-1]):
        xy = xy[:-1]
    return xy


def check_footprint(xy: np.ndarray, settings: Settings = DEFAULTS) -> np.ndarray:
    """The polygon (N, 2) counter-clockwise (a clockwise one reversed, its first point kept
    first), or a one-line ValueError saying what is wrong.

    Refused: fewer than 3 points, non-finite coordinates, a plan too small or too large
    (:func:`~rigidfold.patterns.grids.check_extent`), a repeated point, zero area, a
    self-intersecting outline (sides that cross or touch anywhere but at shared corners) and
    two points, or a point and a side, closer than ``settings.inputs.footprint_min_gap`` times the
    larger side of the bounding box (where Triangle's refinement runs away);
    zero area is a convex hull smaller than ``settings.geometry.degenerate_area`` times the squared
    larger side of the bounding box.
    """
    import shapely

    xy = np.asarray(xy, dtype=float)
    if xy.ndim != 2 or xy.shape[1] != 2 or len(xy) < 3:
        raise RigidfoldError(f"a footprint needs at least 3 (x, y) points, got {len(xy)}")
    if not np.isfinite(xy).all():
        bad = int(np.flatnonzero(~np.isfinite(xy).all(axis=1))[0])
        raise RigidfoldError(f"footprint point {bad + 1} is not finite: {_point(xy[bad])}")
    far = np.abs(xy).max(axis=1) > settings.limits.max_coordinate  # before any sum could overflow
    if far.any():
        bad = int(np.argmax(far))
        raise RigidfoldError(
            f"footprint point {bad + 1} {_point(xy[bad])} lies farther than "
            f"{settings.limits.max_coordinate:g} m from the origin (Settings.limits.max_coordinate)"
        )
    width, height = (float(v) for v in np.ptp(xy, axis=0))
    check_extent(width, height, f"the footprint {_points(xy)}", settings)
    unique, counts = np.unique(xy, axis=0, return_counts=True)
    if (counts > 1).any():
        again = unique[counts > 1][0]
        repeats = np.flatnonzero((xy == again).all(axis=1)) + 1
        raise RigidfoldError(
            f"footprint point {_point(again)} is repeated (points {', '.join(map(str, repeats))})"
        )
    hull = shapely.MultiPoint(xy).convex_hull.area
    if hull <= settings.geometry.degenerate_area * np.ptp(xy, axis=0).max() ** 2:
        raise RigidfoldError(
            f"the footprint {_points(xy)} has zero area (its points lie on a line)"
        )
    reason = shapely.is_valid_reason(shapely.Polygon(xy))
    if reason != "Valid Geometry":
        where = reason[reason.find("[") :] if "[" in reason else ""
        raise RigidfoldError(
            f"the footprint {_points(xy)} is not a simple polygon: its sides intersect "
            f"at {where or 'a point'}"
        )
    polygon = shapely.Polygon(xy)
    gap, size = float(shapely.minimum_clearance(polygon)), float(np.ptp(xy, axis=0).max())
    if gap < settings.inputs.footprint_min_gap * size:
        raise RigidfoldError(
            f"the footprint {_points(xy)} has two points, or a point and a side, {gap:.3g} m "
            f"apart, less than {settings.inputs.footprint_min_gap:g} of its size of {size:g} m "
            "(Settings.inputs.footprint_min_gap): merge them or move them apart"
        )
    return xy if _signed_area(xy) > 0 else np.concatenate([xy[:1], xy[:0:-1]])


def default_edge_length(xy: np.ndarray, settings: Settings = DEFAULTS) -> float:
    """sqrt(footprint area) / ``settings.inputs.mesh_divisions``: 0.5 m on the paper's 3 m
    square."""
    return (
        math.sqrt(abs(_signed_area(np.asarray(xy, dtype=float)))) / settings.inputs.mesh_divisions
    )


def footprint_mesh(
    xy: np.ndarray, edge_length: float, settings: Settings = DEFAULTS
) -> tuple[np.ndarray, np.ndarray]:
    """Quality triangulation of a checked counter-clockwise footprint (N, 2).

    Each side is first divided into ``round(length / edge_length)`` (at least 1) equal
    pieces; Triangle then adds points until no angle is below min(theta_min,
    ``settings.inputs.mesh_angle_cap``) (except at the footprint's own corners sharper than that)
    and no triangle is larger than the equilateral triangle of side ``edge_length``. The
    footprint's corners come first, in order, then the points on its sides, then the inner
    points. Returns the plan vertices (V, 2) and counter-clockwise triangles (F, 3). An edge
    length that is not a positive number up to ``settings.limits.max_coordinate`` is a ValueError.
    """
    import triangle

    if not (math.isfinite(edge_length) and edge_length > 0):
        raise RigidfoldError(
            f"the edge length must be a positive number of metres, got {edge_length}"
        )
    if edge_length > settings.limits.max_coordinate:  # its square would overflow
        raise RigidfoldError(
            f"the edge length must be at most {settings.limits.max_coordinate:g} m, "
            "the largest plan "
            f"(Settings.limits.max_coordinate), got {edge_length:g} m"
        )
    area = abs(_signed_area(xy))
    triangle_area = math.sqrt(3) / 4 * edge_length**2
    if area / triangle_area > settings.limits.max_pattern_faces:
        raise RigidfoldError(
            f"edge length {edge_length:g} m makes about {area / triangle_area:.0f} triangles on "
            f"a footprint of {area:g} m^2, more than {settings.limits.max_pattern_faces} "
            "(Settings.limits.max_pattern_faces)"
        )
    ends = np.roll(xy, -1, axis=0)
    pieces = np.maximum(1, np.rint(np.hypot(*(ends - xy).T) / edge_length).astype(int))
    if (
        int(pieces.sum()) - 2 > settings.limits.max_pattern_faces
    ):  # n points on the outline: >= n - 2
        raise RigidfoldError(
            f"the footprint of {len(xy)} corners, its sides divided at edge length "
            f"{edge_length:g} m, has {int(pieces.sum())} points on its outline: at least "
            f"{int(pieces.sum()) - 2} triangles, more than {settings.limits.max_pattern_faces} "
            "(Settings.limits.max_pattern_faces)"
        )
    points, outline = [xy], []
    for k, n in enumerate(pieces):  # corner k, then the inner points of its side
        first = sum(len(q) for q in points)
        points.append(xy[k] + (ends[k] - xy[k]) * (np.arange(1, n)[:, None] / n))
        outline += [k, *range(first, first + n - 1)]
    angle = min(settings.design.theta_min, settings.inputs.mesh_angle_cap)
    out = triangle.triangulate(
        {
            "vertices": np.concatenate(points),
            "segments": np.column_stack([outline, np.roll(outline, -1)]),
        },
        # Triangle reads no exponent: plain decimals (shortest round-tripping digits)
        f"pq{math.degrees(angle):.6f}a{np.format_float_positional(triangle_area)}Q",
    )
    vertices = np.asarray(out["vertices"], dtype=float)
    return vertices, counter_clockwise(vertices, np.asarray(out["triangles"], dtype=np.int64))


def _signed_area(xy: np.ndarray) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _point(p: np.ndarray) -> str:
    return f"({p[0]:g}, {p[1]:g})"


def _points(xy: np.ndarray) -> str:
    shown = "; ".join(f"{x:g},{y:g}" for x, y in xy[:6])
    return f"'{shown}{'; ...' if len(xy) > 6 else ''}'"
