"""Slips of the pen in an SVG crease pattern, mended within ``Settings.inputs.svg_snap_tol``
(:func:`rigidfold.io.svg_read.read_svg`): where a line would otherwise end on nothing.

The boundary first (:func:`_close_boundary`): a black piece past a corner, or drawn over a
crease inside the sheet, is dropped (the crease stays), and a gap between two ends of the
boundary is closed halfway. Then the creases (:func:`mend`): an overshoot past the line a
crease crosses (the boundary among them) is cut off, and a crease that ends short of a line is
extended to it. Each returns the pieces to arrange again
(:func:`rigidfold.io.svg_planar.node`).
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import cKDTree

from rigidfold.io.svg_planar import cross

MENDS = 4
"""How many times the slips of a drawing are mended (:func:`mend`) and the drawing noded
again, at most: the boundary is closed first, and cutting off an overshoot can leave another
loose end."""


def mend(
    xy: np.ndarray,
    edges: np.ndarray,
    letters: list[str],
    angles: list[float],
    snap: float,
    tol: float = 0.0,
    drawn: tuple[np.ndarray, list[str], list[float]] | None = None,
) -> tuple[np.ndarray, list[str], list[float]] | None:
    """The drawing with its slips within ``snap`` mended, as pieces to node again (ends
    (n, 2, 2), letters, angles), or None when it has none. Gaps in the boundary are closed
    first (:func:`_close_boundary`, which needs the pieces as ``drawn`` and the merge
    distance ``tol``); when it closes any, the creases are mended on the next call. A loose
    crease end (one that touches no other line) is mended: the piece no longer than ``snap``
    that ends there (an overshoot past the line it crosses) is dropped; a longer crease is
    extended from there to the first line that it points at within ``snap``, or else to the
    nearest point within ``snap`` of a line that does not touch it.
    xy (V, 2), edges (E, 2) -> see above."""
    if drawn is not None:
        closed = _close_boundary(xy, edges, letters, angles, snap, tol, drawn)
        if closed is not None:
            return closed
    crease = np.array(letters) != "B"
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    loose = (degree[edges] == 1) & crease[:, None]  # (E, 2): a crease's loose ends
    if not loose.any():
        return None
    length = np.linalg.norm(xy[edges[:, 1]] - xy[edges[:, 0]], axis=1)
    keep = ~(loose.any(axis=1) & (length <= snap))
    edges, letters = edges[keep], [a for a, k in zip(letters, keep, strict=True) if k]
    angles = [a for a, k in zip(angles, keep, strict=True) if k]
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    e, side = np.nonzero((degree[edges] == 1) & (np.array(letters) != "B")[:, None])
    w, p = edges[e, side], edges[e, 1 - side]  # the loose end, the crease's other end
    lines = shapely.linestrings(xy[edges])
    near, other = shapely.STRtree(lines).query(
        shapely.points(xy[w]), predicate="dwithin", distance=snap
    )
    touching = (edges[other] == w[near, None]) | (edges[other] == p[near, None])
    near, other = near[~touching.any(axis=1)], other[~touching.any(axis=1)]
    pieces = [xy[edges]]
    for k in np.unique(near):
        f = other[near == k]
        a, r = xy[edges[f, 0]], xy[edges[f, 1]] - xy[edges[f, 0]]
        start = xy[w[k]]
        d = start - xy[p[k]]
        d = d / np.linalg.norm(d)
        denom = cross(np.broadcast_to(d, r.shape), r)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = cross(a - start, r) / denom  # along the crease's direction from its end
            t = cross(a - start, np.broadcast_to(d, r.shape)) / denom  # along the line
        ahead = (denom != 0) & (s >= 0) & (s <= snap) & (t >= 0) & (t <= 1)
        if ahead.any():
            target = start + s[ahead].min() * d
        else:
            t = np.clip(np.sum((start - a) * r, axis=1) / np.sum(r * r, axis=1), 0, 1)
            foot = a + t[:, None] * r
            target = foot[np.argmin(np.linalg.norm(foot - start, axis=1))]
        pieces.append(np.array([[start, target]]))
        letters.append(letters[e[k]])
        angles.append(angles[e[k]])
    return np.concatenate(pieces), letters, angles


def _close_boundary(
    xy: np.ndarray,
    edges: np.ndarray,
    letters: list[str],
    angles: list[float],
    snap: float,
    tol: float,
    drawn: tuple[np.ndarray, list[str], list[float]],
) -> tuple[np.ndarray, list[str], list[float]] | None:
    """The drawing with the gaps of its boundary within ``snap`` closed, as pieces to node
    again (ends (n, 2, 2), letters, angles), or None when the boundary has no loose end (a
    vertex where just one black line ends).

    A black piece no longer than ``snap`` from a loose end to a vertex where three or more
    black lines meet (an overshoot past a corner, or a black stroke drawn over a crease
    inside the sheet) is dropped; where a crease was drawn along all of it (within ``tol``,
    ``drawn``: the pieces as drawn, ends (n, 2, 2), letters, angles), that crease stays.
    Then two loose ends within ``snap`` of each other, each the other's nearest, become one
    vertex halfway between them (the lines that end there, creases among them, move with
    it), as Origami Simulator merges points within 3 px. Other loose ends are left for
    :func:`rigidfold.io.svg_faces.check_boundary` to refuse.
    xy (V, 2), edges (E, 2) -> see above."""
    black = np.array(letters) == "B"
    degree = np.bincount(edges[black].ravel(), minlength=len(xy))
    loose = (degree[edges] == 1) & black[:, None]  # (E, 2): the boundary's loose ends
    if not loose.any():
        return None
    length = np.linalg.norm(xy[edges[:, 1]] - xy[edges[:, 0]], axis=1)
    stub = loose.any(axis=1) & (degree[edges].max(axis=1) >= 3) & (length <= snap)
    pieces, out_letters, out_angles = [], [], []
    ends, kinds, folds = drawn
    crease = np.flatnonzero(np.array(kinds) != "B")
    lines = shapely.linestrings(ends[crease])
    for e in np.flatnonzero(stub):
        gap = shapely.distance(lines[:, None], shapely.points(xy[edges[e]])[None, :])
        along = np.flatnonzero((gap <= tol).all(axis=1))
        if len(along):
            k = int(crease[along[0]])
            pieces.append(xy[edges[e]])
            out_letters.append(kinds[k])
            out_angles.append(folds[k])
    keep = ~stub
    degree = np.bincount(edges[black & keep].ravel(), minlength=len(xy))
    free = np.flatnonzero(degree == 1)
    moved = xy.copy()
    if len(free) > 1:
        distance, nearest = cKDTree(xy[free]).query(xy[free], k=2)
        partner = nearest[:, 1]
        pair = np.flatnonzero(
            (partner[partner] == np.arange(len(free)))
            & (distance[:, 1] <= snap)
            & (np.arange(len(free)) < partner)
        )
        joined = {frozenset(e) for e in edges[black & keep].tolist()}
        for i in pair:
            u, v = int(free[i]), int(free[partner[i]])
            if frozenset((u, v)) not in joined:  # not both ends of one short black line
                moved[u] = moved[v] = (xy[u] + xy[v]) / 2
    if not stub.any() and np.array_equal(moved, xy):
        return None
    return (
        np.concatenate([moved[edges[keep]], np.reshape(pieces, (-1, 2, 2))]),
        [a for a, k in zip(letters, keep, strict=True) if k] + out_letters,
        [a for a, k in zip(angles, keep, strict=True) if k] + out_angles,
    )
