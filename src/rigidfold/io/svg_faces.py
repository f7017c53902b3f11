"""The boundary and the faces of an SVG crease pattern's planar arrangement
(:func:`rigidfold.io.svg_read.read_svg`).

The black edges must form one closed outline (in a drawing without black lines, the
outline of the lines drawn is the boundary: :func:`outline_as_boundary`), every crease must
lie inside it and end on another line, and every face (a cycle of the plane graph,
counter-clockwise) must be a simple polygon: no holes, no crease loop hanging at one point.
Each problem is a one-line ValueError naming where it is.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.sparse.csgraph import connected_components

from rigidfold.errors import RigidfoldError
from rigidfold.io.svg_planar import adjacency, at


def check_boundary(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], snap: float = 0.0
) -> list[int]:
    """The black edges' one closed outline (counter-clockwise vertex indices); ValueError
    when it is open (naming ``snap``, the gap closed: :func:`rigidfold.io.svg_mend.mend`),
    branches, or is several outlines (a hole among them)."""
    black = edges[np.array(letters) == "B"]
    degree = np.bincount(black.ravel(), minlength=len(xy))
    if (degree == 1).any():
        ends = np.flatnonzero(degree == 1)
        gap = np.linalg.norm(xy[ends[1:]] - xy[ends[0]], axis=1)
        other = (
            f", {gap.min():.3g} drawing units from its end at {at(xy[ends[1 + np.argmin(gap)]])}"
            if len(gap)
            else ""
        )
        raise RigidfoldError(
            f"the boundary (black) is not closed: it ends at {at(xy[ends[0]])}{other} (a gap "
            f"of up to {snap:.3g} drawing units between two ends is closed; "
            "Settings.inputs.svg_snap_tol)"
        )
    if (degree > 2).any():
        w = int(np.argmax(degree))
        raise RigidfoldError(
            f"the boundary (black) is not one outline: {degree[w]} black lines meet at {at(xy[w])}"
        )
    loops = [cycle for cycle, area in _cycles(xy, black) if area > 0]
    if len(loops) == 1:
        return loops[0]
    if not loops:
        raise RigidfoldError("the boundary (black) encloses no area")
    outlines = [shapely.Polygon(xy[loop]) for loop in loops]
    for loop in loops:
        x, y = xy[loop[0]]
        if sum(shapely.contains_xy(outlines, x, y)) > 0:
            raise RigidfoldError(
                f"the black outline through {at(xy[loop[0]])} lies inside another: holes "
                "are not supported"
            )
    raise RigidfoldError(f"the boundary (black) is {len(loops)} separate outlines, not one sheet")


def outline_as_boundary(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], angles: list[float]
) -> tuple[list[str], list[float]]:
    """The letters and angles of a drawing without black lines, the edges of the outline of
    its lines (the outer face of each connected part) made boundary, as Origami Simulator
    takes an edge with a face on one side only for one; ValueError when the lines enclose
    no area or their outline passes twice through a point (a crease hanging out of it).
    xy (V, 2), edges (E, 2) -> E letters, E angles."""
    cycles = _cycles(xy, edges)
    if not any(area > 0 for _, area in cycles):
        raise RigidfoldError(
            "no boundary: no black lines (Origami Simulator draws it black), and the lines "
            "drawn enclose no area to take for the sheet"
        )
    number = {(min(u, v), max(u, v)): e for e, (u, v) in enumerate(edges.tolist())}
    letters, angles = list(letters), list(angles)
    for cycle, area in cycles:
        if area >= 0:
            continue
        seen: set[int] = set()
        for w in cycle:
            if w in seen:
                raise RigidfoldError(
                    f"no boundary: no black lines, and the outline of the lines drawn, taken "
                    f"for the sheet's, passes twice through {at(xy[w])} (a crease hanging "
                    "out of it)"
                )
            seen.add(w)
        for u, v in zip(cycle, cycle[1:] + cycle[:1], strict=True):
            e = number[(min(u, v), max(u, v))]
            letters[e], angles[e] = "B", 0.0
    return letters, angles


def inside_boundary(
    xy: np.ndarray, edges: np.ndarray, boundary: list[int], letters: list[str], snap: float
) -> np.ndarray:
    """(E,) bool: False for the creases outside the ``boundary`` (its vertex indices) whose
    ends both lie within ``snap`` of it (overshoots of creases that end on the boundary),
    True for every other edge."""
    outline = shapely.Polygon(xy[boundary])
    mid = xy[edges].mean(axis=1)
    outside = ~shapely.contains_xy(outline, mid[:, 0], mid[:, 1]) & (np.array(letters) != "B")
    if not outside.any():
        return ~outside
    gap = shapely.distance(outline.exterior, shapely.points(xy[edges[outside]]))  # (k, 2)
    outside[outside] = (gap <= snap).all(axis=1)
    return ~outside


def check_creases(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], boundary: list[int], tol: float
) -> None:
    """ValueError for a crease outside the ``boundary`` (its vertex indices), a crease end
    that touches no other line, or creases not connected to the boundary."""
    outline = shapely.Polygon(xy[boundary])
    mid = xy[edges].mean(axis=1)
    outside = ~shapely.contains_xy(outline, mid[:, 0], mid[:, 1]) & (np.array(letters) != "B")
    if outside.any():
        u, v = edges[np.argmax(outside)]
        raise RigidfoldError(
            f"the crease from {at(xy[u])} to {at(xy[v])} lies outside the boundary"
        )
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    if (degree == 1).any():
        raise RigidfoldError(
            f"a crease ends inside a face at {at(xy[degree == 1][0])}: creases must end on "
            f"another line (an end within {tol:.3g} drawing units of a line is joined to it; "
            "Settings.inputs.svg_snap_tol)"
        )
    n, component = connected_components(adjacency(edges, len(xy)), directed=False)
    if n > 1:
        raise RigidfoldError(
            f"creases around {at(xy[component != component[0]][0])} are not connected to the "
            "boundary: the face around them would have a hole"
        )


def simple_faces(xy: np.ndarray, edges: np.ndarray) -> list[list[int]]:
    """The bounded faces of the drawing's plane graph, counter-clockwise; ValueError for one
    that is not a simple polygon. xy (V, 2), edges (E, 2) -> F lists of vertex indices."""
    faces = [cycle for cycle, area in _cycles(xy, edges) if area > 0]
    for face in faces:
        seen: set[int] = set()
        for w in face:
            if w in seen:
                raise RigidfoldError(
                    f"a face is not a simple polygon: its outline passes twice through "
                    f"{at(xy[w])} (a crease with the same face on both sides, or crease "
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
    # the shoelace term of each directed edge: a cycle's area is half their sum along it
    term = xy[tail, 0] * xy[head, 1] - xy[head, 0] * xy[tail, 1]
    after, vertex = following.tolist(), tail.tolist()
    cycles, done = [], [False] * len(tail)
    for h in range(len(tail)):
        walk, g = [], h
        while not done[g]:
            done[g] = True
            walk.append(g)
            g = after[g]
        if walk:
            cycles.append(([vertex[g] for g in walk], 0.5 * float(np.sum(term[walk]))))
    return cycles
