"""The planar arrangement of the lines of an SVG crease pattern: the pieces drawn split
where they cross or where one ends on another, points closer than the merge distance made one
vertex, repeats kept once (:func:`rigidfold.io.svg_read.read_svg`).

Pieces are ends (n, 2, 2) in drawing units, y up, with their FOLD letters and fold angles; the
arrangement is vertices xy (V, 2) and edges (E, 2) int64 with theirs. Also the helpers of the
geometry of the drawing's graph (:func:`compact`, :func:`adjacency`, :func:`cross`) and of its
messages (:func:`at`: a point in the file's coordinates).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.io.svg_lines import COLOURS


def node(
    ends: np.ndarray,
    letters: list[str],
    angles: list[float],
    tol: float,
    snap: float = 0.0,
    max_pairs: int = DEFAULTS.limits.max_svg_pairs,
) -> tuple[np.ndarray, np.ndarray, list[str], list[float]]:
    """The drawn pieces split where they meet, close points merged, repeats dropped.

    ends : (n, 2, 2) float; letters, angles : n each; tol : merge distance; snap : a piece
    no longer than this drawn in two crease colours (the ends of lines drawn to one point
    that miss it by more than ``tol``, or a crease that overshoots its end along another) is
    contracted, its ends made one vertex (:func:`_pieces`), instead of refused;
    max_pairs : ``Settings.limits.max_svg_pairs`` (:func:`_splits`). Pieces of one colour and
    angle drawn over each other along one line are first made one (:func:`_merge_overlaps`),
    so that a line drawn back and forth many times costs no more than once.
    Returns xy (V, 2), edges (E, 2) int64 (in drawing order), their letters and angles.
    """
    ends, letters, angles = _merge_overlaps(ends, letters, angles, tol)
    ends = _merge_ends(ends, tol)
    a, b = ends[:, 0], ends[:, 1]
    length = np.linalg.norm(b - a, axis=1)
    drawn = np.flatnonzero(length > tol)
    if not len(drawn):
        raise RigidfoldError("the lines drawn have no length")
    a, b, length = a[drawn], b[drawn], length[drawn]
    seg, t, points, near = _splits(a, b, length, tol, max_pairs)
    n = len(drawn)
    seg = np.concatenate([np.arange(n), np.arange(n), seg])
    t = np.concatenate([np.zeros(n), np.ones(n), t])
    points = np.concatenate([a, b, points])
    near = np.concatenate([np.zeros(2 * n, dtype=bool), near])
    order = np.lexsort((t, seg))
    seg, points, near = seg[order], points[order], near[order]
    distinct, same = np.unique(points, axis=0, return_inverse=True)  # ends drawn again
    pairs = cKDTree(distinct).query_pairs(tol, output_type="ndarray")
    vertex = connected_components(adjacency(pairs, len(distinct)), directed=False)[1]
    vertex = vertex[same.reshape(-1)]
    piece = np.flatnonzero(seg[:-1] == seg[1:])
    source = drawn[seg[piece]]
    while True:
        # each merged vertex at its first point (a crossing near an end only if it has no
        # other); a piece drawn in two crease colours (a slip) contracted, until none is left
        rank = np.lexsort((near, vertex))
        first = rank[np.unique(vertex[rank], return_index=True)[1]]
        xy = points[first]
        edges, out_letters, out_angles, twice = _pieces(
            vertex[piece], vertex[piece + 1], source, letters, angles, xy, snap
        )
        if not len(twice):
            break
        vertex = connected_components(adjacency(twice, len(xy)), directed=False)[1][vertex]
    return (*compact(xy, edges), out_letters, out_angles)


def _pieces(
    tail: np.ndarray,
    head: np.ndarray,
    source: np.ndarray,
    letters: list[str],
    angles: list[float],
    xy: np.ndarray,
    snap: float,
) -> tuple[np.ndarray, list[str], list[float], np.ndarray]:
    """The edges of the pieces from vertex ``tail`` to ``head`` (k each), drawn as piece
    ``source`` (k,) of ``letters`` and ``angles``, each edge once: one drawn black stays
    boundary, one drawn in two crease colours no longer than ``snap`` (the ends of lines
    drawn to one point that miss it, or a crease that runs on along another) is returned
    among the vertex pairs to contract, a longer one is refused. Returns edges (E, 2) int64,
    their letters and angles, and the pairs (m, 2) to contract."""
    kept: dict[tuple[int, int], int] = {}
    edges: list[tuple[int, int]] = []
    twice: set[int] = set()
    out_letters, out_angles = [], []
    for u, v, k in zip(tail.tolist(), head.tolist(), source.tolist(), strict=True):
        letter, key = letters[k], (min(u, v), max(u, v))
        if u == v:
            continue
        if key not in kept:
            kept[key] = len(edges)
            edges.append((u, v))
            out_letters.append(letter)
            out_angles.append(angles[k])
            continue
        e = kept[key]
        if letter == "B":
            out_letters[e], out_angles[e] = "B", 0.0
            twice.discard(e)
        elif out_letters[e] not in ("B", letter):
            if np.linalg.norm(xy[u] - xy[v]) > snap:
                raise RigidfoldError(
                    f"the line from {at(xy[u])} to {at(xy[v])} is "
                    f"drawn both {COLOURS[out_letters[e]]} and {COLOURS[letter]}"
                )
            twice.add(e)
    pairs = np.array(edges, dtype=np.int64).reshape(-1, 2)
    return pairs, out_letters, out_angles, pairs[sorted(twice)]


def _merge_ends(ends: np.ndarray, tol: float) -> np.ndarray:
    """The pieces' ends closer than ``tol`` to each other (or linked by such ends) moved onto
    one point, the first of them drawn, before the pieces are split where they cross: lines
    drawn to one point from ends that miss each other by less than ``tol`` then meet there,
    and do not cross each other near it, as Origami Simulator merges points before it looks
    for intersections. ends (n, 2, 2) -> the same, with the ends moved."""
    points = ends.reshape(-1, 2)
    distinct, same = np.unique(points, axis=0, return_inverse=True)
    pairs = cKDTree(distinct).query_pairs(tol, output_type="ndarray")
    if not len(pairs):
        return ends
    label = connected_components(adjacency(pairs, len(distinct)), directed=False)[1]
    label = label[same.reshape(-1)]
    first = np.full(label.max() + 1, len(points))
    np.minimum.at(first, label, np.arange(len(points)))
    return points[first[label]].reshape(ends.shape)


def _merge_overlaps(
    ends: np.ndarray, letters: list[str], angles: list[float], tol: float
) -> tuple[np.ndarray, list[str], list[float]]:
    """Pieces of one letter and angle that lie along one line (both ends within ``tol`` of
    the longest one's line) and overlap by more than ``tol`` made one piece, from the
    farthest end of them to the other, in the place of the first one drawn; the other
    pieces as drawn. What :func:`node` makes of the drawing is the same (the ends inside a
    merged piece would be vertices on a straight line of one letter, which
    :func:`join_straight` removes), without the pairs of :func:`_splits` that grow with the
    square of the number of pieces drawn over each other.

    Candidates are grouped by letter, angle, direction (bins of ``tol`` over the extent of
    the drawing) and distance of their line from the origin (bins of ``tol``), so the work
    is near-linear in the number of pieces; pieces that fall into neighbouring bins are
    left to :func:`_splits`. ends (n, 2, 2) -> ends (m, 2, 2), letters, angles, m <= n.
    """
    n = len(ends)
    if n < 2 or not tol > 0:
        return ends, letters, angles
    a, b = ends[:, 0], ends[:, 1]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    flip = (d[:, 0] < 0) | ((d[:, 0] == 0) & (d[:, 1] < 0))
    d[flip] *= -1
    across = float(np.linalg.norm(np.ptp(ends.reshape(-1, 2), axis=0)))
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / length[:, None]
        direction = np.floor(np.arctan2(u[:, 1], u[:, 0]) * across / tol)
        offset = np.floor(cross(u, a) / tol)
    groups: dict[tuple, list[int]] = {}
    for k in np.flatnonzero(length > tol).tolist():
        angle = angles[k]
        key = (letters[k], "nan" if math.isnan(angle) else angle, direction[k], offset[k])
        groups.setdefault(key, []).append(k)
    merged: dict[int, np.ndarray] = {}  # first piece of a run -> its ends
    gone = np.zeros(n, dtype=bool)
    for members in groups.values():
        if len(members) < 2:
            continue
        ref = members[int(np.argmax(length[members]))]
        start, axis = a[ref], u[ref]
        on = np.array(members)
        off = np.abs(cross(axis, np.stack([a[on], b[on]], axis=1) - start))  # (m, 2)
        on = on[(off <= tol).all(axis=1)]
        s = np.stack([(a[on] - start) @ axis, (b[on] - start) @ axis], axis=1)  # (m, 2)
        low, high = s.min(axis=1), s.max(axis=1)
        order = np.argsort(low, kind="stable").tolist()
        run, top = [order[0]], order[0]  # a run of overlapping pieces, the one reaching farthest
        for m in [*order[1:], None]:
            if m is not None and low[m] < high[top] - tol:
                run.append(m)
                top = m if high[m] > high[top] else top
                continue
            if len(run) > 1:
                bottom = run[0]  # sorted by low
                lo = ends[on[bottom], int(s[bottom, 1] < s[bottom, 0])]
                hi = ends[on[top], int(s[top, 1] > s[top, 0])]
                gone[on[run]] = True
                merged[int(on[run].min())] = np.array([lo, hi])
            if m is not None:
                run, top = [m], m
    if not merged:
        return ends, letters, angles
    ends = ends.copy()
    for k, piece in merged.items():
        gone[k] = False
        ends[k] = piece
    keep = np.flatnonzero(~gone)
    return ends[keep], [letters[k] for k in keep], [angles[k] for k in keep]


def _splits(
    a: np.ndarray,
    b: np.ndarray,
    length: np.ndarray,
    tol: float,
    max_pairs: int = DEFAULTS.limits.max_svg_pairs,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Where pieces must be split: where an end of another piece lies within ``tol`` of
    their interior (a T-junction: split at the foot of the perpendicular from that end) and
    where two pieces cross.

    Two pieces cross where each has its ends on both sides of the other's line, one of them
    farther than ``tol`` from it: pieces along one line (within ``tol``) do not cross, since
    the crossing of their lines is round-off (they meet at T-junctions instead). A crossing
    within ``tol`` of an end of either piece is a split too (lines drawn to one point from
    ends that miss each other, crossing each other on the way): merged with the ends near
    it, it makes them one vertex.

    a, b : (n, 2) float, the pieces' ends; length : (n,) float, all > tol.
    Returns the piece index (k,), the parameter along it (k,), the point (k, 2), and (k,)
    bool: True for a crossing within ``tol`` of an end.
    ValueError when more than ``max_pairs`` pairs of pieces come within ``tol`` of each
    other (``Settings.limits.max_svg_pairs``), counted in batches before the pairs are examined.
    """
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    tree = shapely.STRtree(lines)
    found, pairs, batch = [], 0, 256  # pieces per query: the pairs of a query stay small
    for first in range(0, len(lines), batch):
        i, j = tree.query(lines[first : first + batch], predicate="dwithin", distance=tol)
        i += first
        i, j = i[i < j], j[i < j]
        pairs += len(i)
        if pairs > max_pairs:
            raise RigidfoldError(
                f"more than {max_pairs} pairs of its {len(lines)} line pieces meet, cross or "
                "come within the merge distance of each other (Settings.limits.max_svg_pairs): too "
                "many lines cross or are drawn over each other"
            )
        found.append((i, j))
    i = np.concatenate([p[0] for p in found])
    j = np.concatenate([p[1] for p in found])
    seg, t, points, near = [], [], [], []

    def interior(s: np.ndarray, on: np.ndarray) -> np.ndarray:
        return (s * length[on] > tol) & ((1 - s) * length[on] > tol)

    chunk = 1 << 16  # pairs examined at once: the temporary arrays stay small
    for k in range(0, max(len(i), 1), chunk):  # once at least: the arrays returned
        ik, jk = i[k : k + chunk], j[k : k + chunk]
        for on, other in ((ik, jk), (jk, ik)):
            d = b[on] - a[on]
            for end in (a[other], b[other]):
                s = np.sum((end - a[on]) * d, axis=1) / length[on] ** 2
                foot = a[on] + s[:, None] * d
                hit = interior(s, on) & (np.linalg.norm(foot - end, axis=1) <= tol)
                seg.append(on[hit])
                t.append(s[hit])
                points.append(foot[hit])
                near.append(np.zeros(hit.sum(), dtype=bool))
        di, dj, r = b[ik] - a[ik], b[jk] - a[jk], a[jk] - a[ik]
        # signed distances times length: of j's ends from i's line, of i's ends from j's line
        pj = np.stack([cross(di, r), cross(di, r + dj)], axis=1)
        pi = np.stack([cross(dj, -r), cross(dj, di - r)], axis=1)
        proper = (
            (np.sign(pj[:, 0]) * np.sign(pj[:, 1]) < 0)
            & (np.sign(pi[:, 0]) * np.sign(pi[:, 1]) < 0)
            & (np.abs(pj).max(axis=1) > tol * length[ik])
            & (np.abs(pi).max(axis=1) > tol * length[jk])
        )
        denom = cross(di, dj)
        si = np.divide(cross(r, dj), denom, out=np.full(len(ik), np.nan), where=proper)
        sj = np.divide(cross(r, di), denom, out=np.full(len(ik), np.nan), where=proper)
        hit = (si > 0) & (si < 1) & (sj > 0) & (sj < 1)
        crossing = a[ik][hit] + si[hit, None] * di[hit]
        end = ~(interior(si, ik) & interior(sj, jk))[hit]
        seg += [ik[hit], jk[hit]]
        t += [si[hit], sj[hit]]
        points += [crossing, crossing]
        near += [end, end]
    return (
        np.concatenate(seg),
        np.concatenate(t),
        np.concatenate(points).reshape(-1, 2),
        np.concatenate(near),
    )


def join_straight(
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
        off = abs(cross(chord, xy[w] - xy[p])) / np.linalg.norm(chord)
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
    xy, edges = compact(xy, np.array(ends, dtype=np.int64)[keep])
    return xy, edges, [letters[e] for e in keep], [angles[e] for e in keep]


def compact(xy: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Only the vertices that edges use, numbered in order of first use.
    xy (V, 2), edges (E, 2) -> xy (V', 2), edges (E, 2)."""
    used, first = np.unique(edges.ravel(), return_index=True)
    order = used[np.argsort(first)]
    number = np.full(len(xy), -1)
    number[order] = np.arange(len(order))
    return xy[order], number[edges]


def adjacency(edges: np.ndarray, n: int) -> coo_matrix:
    """The (n, n) adjacency matrix of the edges (E, 2)."""
    return coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))


def cross(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """z component of p x q; p, q : (..., 2) float -> (...)."""
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def at(point: np.ndarray) -> str:
    """A point (2,) y up as the file's coordinates, for messages: ``(x, y)``, y down."""
    return f"({point[0]:.6g}, {-point[1] + 0.0:.6g})"
