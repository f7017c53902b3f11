"""Triangulation of polygon faces by ear clipping.

Pure functions on arrays and lists. Each polygon is projected onto the plane normal to its
Newell normal, so faces of a folded sheet (planar or nearly so in 3D) are triangulated in
their own plane; the added diagonals are returned so that callers can mark them as fixed
creases.
"""

from __future__ import annotations

import math

import numpy as np


def triangulate_polygons(
    coords: np.ndarray,
    polygons: list[list[int]],
    *,
    area_tol: float,
    name: str = "polygons",
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Triangles of all polygons, and the diagonals added inside them.

    Parameters
    ----------
    coords : (V, 3) float
        Vertex coordinates.
    polygons : F lists of int
        Vertex indices of each polygon (at least 3, distinct, in range), in order.
    area_tol : float
        Relative tolerance of :func:`ear_clip`.
    name : str
        What messages call the list of polygons, e.g. ``"faces_vertices"``.

    Returns
    -------
    triangles : (T, 3) int64
        Triangles, in polygon order; a triangle is kept as given, a polygon with n vertices
        gives n - 2 triangles oriented like the polygon.
    diagonals : list of (int, int)
        Vertex pairs of the added interior edges, n - 3 per polygon.

    Raises
    ------
    ValueError
        ``"<name>[k]: ..."`` for a polygon of zero area, a degenerate or a self-intersecting one.
    """
    triangles, diagonals = [], []
    planar = plane_coords(coords, polygons, name=name)
    for k, (polygon, xy) in enumerate(zip(polygons, planar, strict=True)):
        if len(polygon) == 3:
            triangles.append(polygon)
            continue
        try:
            local_triangles, local_diagonals = ear_clip(xy, area_tol=area_tol)
        except ValueError as exc:
            raise ValueError(f"{name}[{k}]: {exc}") from None
        triangles += [[polygon[i] for i in tri] for tri in local_triangles]
        diagonals += [(polygon[a], polygon[b]) for a, b in local_diagonals]
    return np.asarray(triangles, dtype=np.int64), diagonals


def orient_up(coords: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Triangles reversed when their total signed area in plan is negative.

    coords : (V, 3) float; triangles : (T, 3) int  ->  (T, 3) int, counter-clockwise in total
    seen from +z (``triangles`` itself when it already is).
    """
    p = coords[triangles]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.ascontiguousarray(triangles[:, ::-1]) if area < 0 else triangles


def ear_clip(
    xy: list[list[float]], *, area_tol: float
) -> tuple[list[tuple[int, ...]], list[tuple[int, int]]]:
    """Triangulate a simple polygon by ear clipping.

    Of all ears, the one with the largest smallest angle is clipped first.

    Parameters
    ----------
    xy : (n, 2) list of float
        Polygon vertices in order, counter-clockwise, n >= 3.
    area_tol : float
        A triangle with twice its signed area below ``area_tol * size**2`` (size: the larger
        side of the polygon's bounding box) is not counter-clockwise, and a point within that
        of a triangle's side lies on it.

    Returns
    -------
    triangles : list of n - 2 (i, j, k)
        Local vertex indices, counter-clockwise.
    diagonals : list of n - 3 (i, j)
        The added interior edges.

    Raises
    ------
    ValueError
        When the polygon is degenerate or self-intersecting.
    """
    size = max(max(p[d] for p in xy) - min(p[d] for p in xy) for d in (0, 1))
    tol = area_tol * size**2
    remaining = list(range(len(xy)))
    triangles: list[tuple[int, ...]] = []
    diagonals: list[tuple[int, int]] = []
    while len(remaining) > 3:
        m = len(remaining)
        best, best_quality = None, -1.0
        for k in range(m):
            a, b, c = remaining[k - 1], remaining[k], remaining[(k + 1) % m]
            if cross2d(xy[a], xy[b], xy[c]) <= tol:
                continue
            others = (i for i in remaining if i not in (a, b, c))
            if any(in_triangle(xy[i], xy[a], xy[b], xy[c], tol) for i in others):
                continue
            quality = min_angle(xy[a], xy[b], xy[c])
            if quality > best_quality:
                best, best_quality = k, quality
        if best is None:
            raise ValueError("the polygon is degenerate or self-intersecting")
        a, b, c = remaining[best - 1], remaining[best], remaining[(best + 1) % m]
        triangles.append((a, b, c))
        diagonals.append((a, c))
        remaining.pop(best)
    if cross2d(*(xy[i] for i in remaining)) <= tol:
        raise ValueError("the polygon is degenerate or self-intersecting")
    triangles.append(tuple(remaining))
    return triangles, diagonals


def plane_coords(
    coords: np.ndarray, polygons: list[list[int]], *, name: str = "polygons"
) -> list[list[list[float]]]:
    """2D coordinates of each polygon's vertices in the plane normal to its Newell normal.

    The frame (u, w) of a polygon has u x w = its normal, so the polygon runs
    counter-clockwise in it; it need not be planar.

    coords : (V, 3) float; polygons : F lists of vertex indices  ->  F lists of (n, 2) float
    Raises ValueError ``"<name>[k]: the polygon is degenerate (zero area)"``.
    """
    sizes = np.array([len(p) for p in polygons])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    owner = np.repeat(np.arange(len(polygons)), sizes)
    flat = np.concatenate(polygons)
    following = flat[starts[owner] + (np.arange(len(flat)) - starts[owner] + 1) % sizes[owner]]
    first = coords[flat[starts[owner]]]  # relative positions: no cancellation far from 0
    normal = np.add.reduceat(np.cross(coords[flat] - first, coords[following] - first), starts)
    length = np.linalg.norm(normal, axis=1)
    if (length == 0).any():
        k = int(np.argmin(length))
        raise ValueError(f"{name}[{k}]: the polygon is degenerate (zero area)")
    normal /= length[:, None]
    u = np.cross(normal, np.eye(3)[np.argmin(np.abs(normal), axis=1)])
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(normal, u)
    p = coords[flat]
    xy = np.column_stack([np.sum(p * u[owner], axis=1), np.sum(p * w[owner], axis=1)])
    return [part.tolist() for part in np.split(xy, starts[1:])]


def cross2d(a: list[float], b: list[float], c: list[float]) -> float:
    """Twice the signed area of the 2D triangle (a, b, c), positive when counter-clockwise.

    a, b, c : (2,) float each (lists: faster than NumPy for single points).
    """
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def in_triangle(p: list[float], a: list[float], b: list[float], c: list[float], tol: float) -> bool:
    """True when p lies in the counter-clockwise triangle (a, b, c) or on its sides.

    p, a, b, c : (2,) float each; tol : twice the area by which p may lie outside a side.
    """
    return cross2d(a, b, p) >= -tol and cross2d(b, c, p) >= -tol and cross2d(c, a, p) >= -tol


def min_angle(a: list[float], b: list[float], c: list[float]) -> float:
    """Smallest interior angle of the 2D triangle (a, b, c), radians.  a, b, c : (2,) float"""
    angles = []
    for p, q, r in ((a, b, c), (b, c, a), (c, a, b)):
        dot = (q[0] - p[0]) * (r[0] - p[0]) + (q[1] - p[1]) * (r[1] - p[1])
        angles.append(math.atan2(abs(cross2d(p, q, r)), dot))
    return min(angles)
