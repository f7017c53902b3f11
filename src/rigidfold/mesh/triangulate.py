"""Triangulation of polygon faces: Mapbox's earcut (``mapbox_earcut``), checked, made Delaunay.

Pure functions on arrays. Each polygon is projected onto the plane normal to its Newell
normal, so faces of a folded sheet (planar or nearly so in 3D) are triangulated in their own
plane. Earcut (ear clipping on a linked list with z-order hashing: O(n log n) in practice,
where clipping the best ear of all took O(n^3)) gives the triangles; they are checked to tile
the polygon (n - 2 triangles of positive area, each side used once and each added diagonal
twice), since earcut returns what it can of a degenerate or self-intersecting polygon. Earcut
does not look at the triangles' shapes, so Lawson's flips then turn its diagonals into the
polygon's constrained Delaunay triangulation (which maximises the smallest angle; a
parallelogram is cut on its short diagonal). The added diagonals are returned so that
callers can mark them as fixed creases.
"""

from __future__ import annotations

import math

import mapbox_earcut
import numpy as np

from rigidfold.errors import RigidfoldError


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
        Relative tolerance of :func:`triangulate_polygon`.
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
            local_triangles, local_diagonals = triangulate_polygon(xy, area_tol=area_tol)
        except ValueError as exc:
            raise RigidfoldError(f"{name}[{k}]: {exc}") from None
        triangles += [[polygon[i] for i in tri] for tri in local_triangles]
        diagonals += [(polygon[a], polygon[b]) for a, b in local_diagonals]
    return np.asarray(triangles, dtype=np.int64).reshape(-1, 3), diagonals


def orient_up(coords: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Triangles reversed when their total signed area in plan is negative.

    coords : (V, 3) float; triangles : (T, 3) int  ->  (T, 3) int, counter-clockwise in total
    seen from +z (``triangles`` itself when it already is).
    """
    p = coords[triangles]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.ascontiguousarray(triangles[:, ::-1]) if area < 0 else triangles


def triangulate_polygon(
    xy: list[list[float]], *, area_tol: float
) -> tuple[list[list[int]], list[tuple[int, int]]]:
    """Constrained Delaunay triangulation of a simple polygon (earcut, checked, then flipped).

    Parameters
    ----------
    xy : (n, 2) list of float
        Polygon vertices in order, counter-clockwise, n >= 3.
    area_tol : float
        A triangle with twice its signed area below ``area_tol * size**2`` (size: the larger
        side of the polygon's bounding box) is degenerate; a diagonal is flipped when the
        incircle determinant exceeds ``area_tol * size**4`` (no flipping to and fro between
        the diagonals of four points on a circle).

    Returns
    -------
    triangles : list of n - 2 [i, j, k]
        Local vertex indices, counter-clockwise.
    diagonals : list of n - 3 (i, j)
        The added interior edges, i < j.

    Raises
    ------
    ValueError
        When the polygon is degenerate or self-intersecting: earcut's triangles are not
        n - 2 triangles of twice their area above the tolerance, each side of the polygon
        used once (in its direction) and each other edge twice (once each way).
    """
    n = len(xy)
    size = max(max(p[d] for p in xy) - min(p[d] for p in xy) for d in (0, 1))
    area_floor = area_tol * size**2
    tri: list[list[int]] | None = _earcut(xy)
    half = None if tri is None else _tiling(xy, tri, area_floor)
    if half is None:
        # earcut may cut an ear of three points on a line (a vertex on a straight side):
        # cut the polygon without its straight vertices, then the triangles with them
        tri = _earcut_without_straight(xy, area_floor)
        half = None if tri is None else _tiling(xy, tri, area_floor)
    if tri is None or half is None:
        raise RigidfoldError("the polygon is degenerate or self-intersecting")
    tri = delaunay_flips(xy, tri, half, area_floor=area_floor, circle_floor=area_tol * size**4)
    return tri, [(a, b) for a, b in half if a < b and (b - a) % n not in (1, n - 1)]


def _earcut(xy: list[list[float]]) -> list[list[int]]:
    """Earcut's triangles of the polygon ``xy`` (n, 2), counter-clockwise when their total
    area is positive."""
    n = len(xy)
    found = mapbox_earcut.triangulate_float64(
        np.asarray(xy, dtype=np.float64).reshape(n, 2), np.array([n], dtype=np.uint32)
    )
    tri = found.reshape(-1, 3).tolist()
    if sum(cross2d(xy[a], xy[b], xy[c]) for a, b, c in tri) < 0:  # earcut's own orientation
        tri = [t[::-1] for t in tri]
    return tri


def _tiling(
    xy: list[list[float]], tri: list[list[int]], area_floor: float
) -> dict[tuple[int, int], int] | None:
    """The triangle of each directed edge of ``tri`` when the triangles tile the polygon
    ``xy``: n - 2 triangles of twice their area above ``area_floor``, each side of the polygon
    used once (in its direction) and each other edge twice (once each way); else None."""
    n = len(xy)
    half = {(t[i], t[(i + 1) % 3]): k for k, t in enumerate(tri) for i in range(3)}
    turns = [(b - a) % n for a, b in half]
    tiles = (
        len(tri) == n - 2
        and min((cross2d(xy[a], xy[b], xy[c]) for a, b, c in tri), default=0.0) > area_floor
        and len(half) == 3 * len(tri)  # no half-edge twice
        and turns.count(1) == n  # every side once, in its direction
        and n - 1 not in turns  # no side the wrong way
        and all((b, a) in half for (a, b), turn in zip(half, turns, strict=True) if turn != 1)
    )
    return half if tiles else None


def _earcut_without_straight(xy: list[list[float]], area_floor: float) -> list[list[int]] | None:
    """Triangles of the polygon ``xy`` (n, 2) cut by earcut without its straight vertices
    (each between its neighbours, on their line within ``area_floor``), each of whose
    triangles is then cut again with the straight vertices on its sides
    (:func:`_clip_convex`); None when fewer than three vertices are left or what earcut
    gives does not tile (:func:`_tiling`)."""
    n = len(xy)
    straight = [
        abs(cross2d(xy[k - 1], xy[k], xy[(k + 1) % n])) <= area_floor
        and (xy[k - 1][0] - xy[k][0]) * (xy[(k + 1) % n][0] - xy[k][0])
        + (xy[k - 1][1] - xy[k][1]) * (xy[(k + 1) % n][1] - xy[k][1])
        < 0
        for k in range(n)
    ]
    kept = [k for k in range(n) if not straight[k]]
    if not any(straight) or len(kept) < 3:
        return None
    reduced = _earcut([xy[k] for k in kept])
    if _tiling([xy[k] for k in kept], reduced, area_floor) is None:
        return None
    tri: list[list[int]] = []
    for t in reduced:
        outline = []
        for i in range(3):  # the triangle's corners and the straight vertices between them
            a, b = kept[t[i]], kept[t[(i + 1) % 3]]
            run = [(a + j) % n for j in range(1, (b - a) % n)]
            outline += [a, *run] if run and all(straight[k] for k in run) else [a]
        clipped = _clip_convex(xy, outline, area_floor)
        if clipped is None:
            return None
        tri += clipped
    return tri


def _clip_convex(
    xy: list[list[float]], outline: list[int], area_floor: float
) -> list[list[int]] | None:
    """Triangles of a convex polygon (``outline``: indices into ``xy``, counter-clockwise)
    with straight vertices on its sides, by cutting off ears of twice their area above
    ``area_floor``, those next to a straight vertex first (so that three corners stay);
    None when no such ear is left."""
    outline, tri = list(outline), []

    def doubled(i: int) -> float:
        m = len(outline)
        return cross2d(xy[outline[i - 1]], xy[outline[i]], xy[outline[(i + 1) % m]])

    while len(outline) > 3:
        m = len(outline)
        ears = [i for i in range(m) if doubled(i) > area_floor]
        near = [i for i in ears if min(doubled(i - 1), doubled((i + 1) % m)) <= area_floor]
        if not ears:
            return None
        i = (near or ears)[0]
        tri.append([outline[i - 1], outline[i], outline[(i + 1) % m]])
        del outline[i]
    if doubled(1) <= area_floor:
        return None
    return [*tri, outline]


def delaunay_flips(
    xy: list[list[float]],
    tri: list[list[int]],
    owner: dict[tuple[int, int], int],
    *,
    area_floor: float,
    circle_floor: float,
) -> list[list[int]]:
    """Lawson's flips of the diagonals of a polygon's triangulation, towards Delaunay.

    A diagonal shared by (a, b, c) and (b, a, d) is replaced by (c, d) while d lies inside
    the circle through a, b, c (then the quadrilateral is convex); the polygon's sides stay.
    At most n log2 n flips are made (Lawson's algorithm needs about n on polygons, and is
    quadratic at worst): past that the triangulation stays valid, only less well shaped.

    Parameters
    ----------
    xy : (n, 2) list of float
        The polygon, counter-clockwise.
    tri : list of n - 2 [i, j, k]
        Counter-clockwise triangles tiling it; changed in place and returned.
    owner : dict (i, j) -> int
        The triangle of each of their directed edges; changed in place (its keys stay the
        directed edges of ``tri``).
    area_floor, circle_floor : float
        A flip makes no triangle of twice its area below ``area_floor``, and is made only
        when the incircle determinant exceeds ``circle_floor``.
    """
    n = len(xy)
    stack = [(a, b) for a, b in owner if a < b and (b - a) % n not in (1, n - 1)]
    budget = n * max(1, math.ceil(math.log2(n)))
    while stack and budget:
        a, b = stack.pop()
        t1, t2 = owner.get((a, b)), owner.get((b, a))
        if t1 is None or t2 is None:  # flipped away meanwhile
            continue
        c = next(v for v in tri[t1] if v not in (a, b))
        d = next(v for v in tri[t2] if v not in (a, b))
        if not (
            incircle(xy[a], xy[b], xy[c], xy[d]) > circle_floor
            and cross2d(xy[c], xy[a], xy[d]) > area_floor
            and cross2d(xy[d], xy[b], xy[c]) > area_floor
        ):
            continue
        tri[t1], tri[t2] = [c, a, d], [d, b, c]
        del owner[(a, b)], owner[(b, a)]
        owner.update({(a, d): t1, (d, c): t1, (b, c): t2, (c, d): t2})
        stack += [
            (u, v) for u, v in ((a, d), (d, b), (b, c), (c, a)) if (v - u) % n not in (1, n - 1)
        ]
        budget -= 1
    return tri


def cross2d(a: list[float], b: list[float], c: list[float]) -> float:
    """Twice the signed area of the 2D triangle (a, b, c), positive when counter-clockwise.

    a, b, c : (2,) float each (lists: faster than NumPy for single points).
    """
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def incircle(a: list[float], b: list[float], c: list[float], d: list[float]) -> float:
    """Positive when d lies inside the circle through the counter-clockwise a, b, c.

    a, b, c, d : (2,) float each; the determinant, of dimension length**4, taken relative to d.
    """
    ax, ay, bx, by, cx, cy = (
        a[0] - d[0],
        a[1] - d[1],
        b[0] - d[0],
        b[1] - d[1],
        c[0] - d[0],
        c[1] - d[1],
    )
    return (
        (ax * ax + ay * ay) * (bx * cy - cx * by)
        + (bx * bx + by * by) * (cx * ay - ax * cy)
        + (cx * cx + cy * cy) * (ax * by - bx * ay)
    )


def plane_coords(
    coords: np.ndarray, polygons: list[list[int]], *, name: str = "polygons"
) -> list[list[list[float]]]:
    """2D coordinates of each polygon's vertices in the plane normal to its Newell normal.

    The frame (u, w) of a polygon has u x w = its normal, so the polygon runs
    counter-clockwise in it; it need not be planar. Coordinates are taken relative to the
    polygon's first vertex.

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
        raise RigidfoldError(f"{name}[{k}]: the polygon is degenerate (zero area)")
    normal /= length[:, None]
    u = np.cross(normal, np.eye(3)[np.argmin(np.abs(normal), axis=1)])
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(normal, u)
    p = coords[flat] - first
    xy = np.column_stack([np.sum(p * u[owner], axis=1), np.sum(p * w[owner], axis=1)])
    return [part.tolist() for part in np.split(xy, starts[1:])]
