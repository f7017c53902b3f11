"""Step 8: the development diagram of a polyhedron, problem (13) of the paper.

::

    min_Xd   D(Xd) = sum_j (l^d_j(Xd) - l_j)^2 / sum_j l_j^2      (every edge j)
    s.t.     n_k(Xd) . z >= 0                                     (every facet k)
             Xd in chi^d                                          (position fixed)

``Xd`` are the 2D vertex coordinates of the diagram, ``l_j`` the 3D edge lengths and
``l^d_j`` the diagram's. Following Wang et al., the diagram is found by least squares on the
edge lengths, from the xy projection of the 3D shape (the paper's start). A strongly folded
shape can project with facets flipped, and IPOPT then stops at a diagram with a facet of zero
area; in that case (status not "converged") problem (13) is solved again from the *unfolding*
of the facets along a spanning tree (:func:`unfold`), which is the exact development of a
developable shape up to rounding, and the better diagram is kept. ``n_k . z >= 0`` is imposed as the
doubled signed area of facet k (counter-clockwise order of ``pattern.faces``) divided by the
squared mean 3D edge length, so that every constraint is of order one.

The gauge chi^d: the reference edge ``k`` is the longest boundary edge; its first vertex
``a = edges[k, 0]`` sits at the origin and its second vertex ``b = edges[k, 1]`` on the +x
axis (``y_b = 0``, ``x_b >= 0``). These three coordinates are eliminated, so IPOPT sees
``2 V - 3`` variables. The model is built per call with CasADi SX (exact gradient and
Hessian) and solved by IPOPT.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np
import shapely

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern
from rigidfold.optimize.ipopt import ipopt_options
from rigidfold.outcomes import Outcome
from rigidfold.runtime.quiet import native_quiet

_IPOPT_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


class DevelopStatus(Outcome):
    """How a development diagram came out (problem (13) and the checks of the diagram)."""

    CONVERGED = "converged", "IPOPT succeeded; no facet is flipped and none overlap"
    FLIPPED = "flipped", "a facet of the diagram is flipped or degenerate"
    OVERLAP = "overlap", "two facets of the diagram overlap"
    FAILED = "failed", "IPOPT failed or returned non-finite numbers"


@dataclass(frozen=True, eq=False)
class Development:
    """The development diagram of a polyhedron (Step 8) and its quality.

    Attributes
    ----------
    coords2d : (V, 2) float64
        Vertex coordinates of the diagram (read-only); NaN where the solver produced NaN.
    D : float
        Objective of problem (13): relative sum of squared edge-length errors.
    max_length_error : float
        max_j |l^d_j - l_j| / l_j over all edges.
    flipped : int
        Facets whose signed area in the diagram is not positive (see :func:`count_flipped`);
        -1 when the coordinates are not finite.
    overlaps : int
        Pairs of facets whose interiors overlap (see :func:`count_overlaps`); -1 when the
        coordinates are not finite.
    status : DevelopStatus
        CONVERGED, FLIPPED, OVERLAP or FAILED (see the members' messages). The status does not
        judge D: a shape that is not developable converges to a valid diagram with a large D.
    message : str
        The detail: IPOPT's return status and a short verdict.
    iterations : int
        IPOPT iterations.
    wall_time : float
        Seconds spent building the model and solving it.
    reference_edge : int
        Edge k that fixes the position: ``edges[k, 0]`` at the origin, ``edges[k, 1]`` on +x.
    start : str
        Start of the kept solve: "projection" (the xy projection) or "unfolding".
    """

    coords2d: np.ndarray
    D: float
    max_length_error: float
    flipped: int
    overlaps: int
    status: DevelopStatus
    message: str
    iterations: int
    wall_time: float
    reference_edge: int
    start: str = "projection"

    def to_dict(self) -> dict:
        """JSON-serialisable figures of the diagram (not its coordinates)."""
        return {
            "D": self.D,
            "max_length_error": self.max_length_error,
            "flipped": self.flipped,
            "overlaps": self.overlaps,
            "status": self.status.value,
            "iterations": self.iterations,
            "start": self.start,
            "wall_time_s": self.wall_time,
            "message": self.message,
        }

    def as_pattern(self, pattern: CreasePattern) -> CreasePattern:
        """The crease pattern of the diagram: ``pattern``'s topology with z = 0.

        Parameters
        ----------
        pattern : CreasePattern
            The 3D shape this diagram was developed from (faces, edges and fixed mask).

        Raises
        ------
        ValueError
            If the diagram has flipped facets or non-finite coordinates (a CreasePattern
            needs counter-clockwise, non-degenerate faces), or the vertex counts differ.
        """
        if len(self.coords2d) != pattern.n_vertices:
            raise RigidfoldError(
                f"the diagram has {len(self.coords2d)} vertices, the pattern {pattern.n_vertices}"
            )
        if self.flipped != 0:
            raise RigidfoldError(
                f"the development diagram is invalid ({self.flipped} flipped facets, or "
                "non-finite coordinates); it is not a crease pattern"
            )
        coords = np.column_stack([self.coords2d, np.zeros(len(self.coords2d))])
        # a crease pattern built: the sheet's rule checked (not a state of ``pattern``)
        return CreasePattern(coords, pattern.faces, pattern.edges, pattern.fixed, pattern.settings)


def signed_areas(coords2d: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed areas (F,) of triangles (F, 3) in the plane; positive when counter-clockwise.

    coords2d : (V, 2); faces : (F, 3) int.
    """
    p = np.asarray(coords2d, dtype=np.float64)[np.asarray(faces)]
    u, v = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])


def count_flipped(
    coords2d: np.ndarray, faces: np.ndarray, *, tol: float = DEFAULTS.geometry.degenerate_area
) -> int:
    """Number of triangles that are flipped or degenerate in a planar diagram.

    Parameters
    ----------
    coords2d : (V, 2) float
        Planar vertex coordinates.
    faces : (F, 3) int
        Triangles, counter-clockwise when not flipped.
    tol : float
        A triangle counts when its signed area is <= ``tol * (its longest edge)**2``
        (default: ``Settings.geometry.degenerate_area``).
    """
    p = np.asarray(coords2d, dtype=np.float64)[np.asarray(faces)]
    longest2 = np.max(np.sum((p - np.roll(p, 1, axis=1)) ** 2, axis=2), axis=1)
    return int(np.count_nonzero(signed_areas(coords2d, faces) <= tol * longest2))


def count_overlaps(
    coords2d: np.ndarray, faces: np.ndarray, *, tol: float = DEFAULTS.geometry.overlap_area_tol
) -> int:
    """Number of pairs of triangles (i < j) whose interiors overlap in a planar diagram.

    Candidate pairs come from a ``shapely.STRtree`` query; a pair overlaps when the area of
    its intersection exceeds ``tol`` times the smaller triangle's area, so that
    neighbours sharing an edge or a vertex do not count.

    Parameters
    ----------
    coords2d : (V, 2) float
        Planar vertex coordinates (finite).
    faces : (F, 3) int
        Triangles, in either orientation.
    """
    faces = np.asarray(faces)
    if len(faces) < 2:
        return 0
    polys = shapely.polygons(np.asarray(coords2d, dtype=np.float64)[faces])
    tree = shapely.STRtree(polys)
    i, j = tree.query(polys, predicate="intersects")
    keep = i < j
    i, j = i[keep], j[keep]
    if len(i) == 0:
        return 0
    areas = shapely.area(polys)
    common = shapely.area(shapely.intersection(polys[i], polys[j]))
    return int(np.count_nonzero(common > tol * np.minimum(areas[i], areas[j])))


def _reference_edge(pattern: CreasePattern) -> int:
    """The longest boundary edge (the first one on ties)."""
    boundary = np.flatnonzero(pattern.is_boundary_edge)
    return int(boundary[np.argmax(pattern.edge_lengths[boundary])])


def unfold(pattern: CreasePattern) -> np.ndarray:
    """A flat layout (V, 2) of the facets unfolded one by one, breadth first from facet 0.

    Each facet is placed across an edge already in the plane from its two other 3D edge
    lengths, on the side that keeps its corners counter-clockwise; a vertex keeps the place it
    got first. For a developable polyhedron this is its development up to rounding (every
    vertex closes up because its sector angles sum to 2 pi); otherwise the gaps show where it
    is not developable. Used as the second start of problem (13).
    """
    faces, ef, fe = pattern.faces, pattern.edge_faces, pattern.face_edges
    P = pattern.coords
    xy = np.full((pattern.n_vertices, 2), np.nan)

    def length(i: int, j: int) -> float:
        return float(np.linalg.norm(P[j] - P[i]))

    def apex(u: int, v: int, w: int) -> None:
        """Place w left of u -> v at its 3D distances from u and v."""
        d = xy[v] - xy[u]
        base = float(np.hypot(*d))
        r1, r2 = length(u, w), length(v, w)
        along = (r1**2 - r2**2 + base**2) / (2 * base)
        h = np.sqrt(max(r1**2 - along**2, 0.0))
        unit = d / base
        xy[w] = xy[u] + along * unit + h * np.array([-unit[1], unit[0]])

    a, b, c = (int(v) for v in faces[0])
    xy[a] = 0.0, 0.0
    xy[b] = length(a, b), 0.0
    apex(a, b, c)
    placed = np.zeros(len(faces), dtype=bool)
    placed[0] = True
    queue = deque([0])
    while queue:
        f = queue.popleft()
        for e in fe[f]:
            g = int(ef[e, 1] if ef[e, 0] == f else ef[e, 0])
            if g < 0 or placed[g]:
                continue
            placed[g] = True
            queue.append(g)
            corners = faces[g].tolist()
            i = next(
                k
                for k in range(3)
                if {corners[k], corners[(k + 1) % 3]} == set(pattern.edges[e].tolist())
            )
            u, v, w = corners[i], corners[(i + 1) % 3], corners[(i + 2) % 3]
            if np.isnan(xy[w, 0]):
                apex(u, v, w)
    return xy


def _initial_guess(pattern: CreasePattern, a: int, b: int, xy: np.ndarray) -> np.ndarray:
    """A layout (V, 2) moved rigidly so that a is at the origin and b on +x."""
    xy = xy - xy[a]
    dx, dy = xy[b]
    phi = np.arctan2(dy, dx)  # 0 when a and b project onto one point
    c, s = np.cos(phi), np.sin(phi)
    return xy @ np.array([[c, -s], [s, c]])  # rotation by -phi


def _diagram_error(coords2d: np.ndarray, pattern: CreasePattern) -> tuple[float, float]:
    """(D, max relative length error) of a diagram, with NumPy."""
    l3 = pattern.edge_lengths
    d = coords2d[pattern.edges[:, 1]] - coords2d[pattern.edges[:, 0]]
    l2 = np.hypot(d[:, 0], d[:, 1])
    return float(np.sum((l2 - l3) ** 2) / np.sum(l3**2)), float(np.max(np.abs(l2 - l3) / l3))


def develop(pattern: CreasePattern, *, settings: Settings = DEFAULTS) -> Development:
    """Generate the development diagram of a polyhedron by solving problem (13).

    Parameters
    ----------
    pattern : CreasePattern
        The 3D shape (V vertices, E edges, F facets); all its edges enter D.
    settings : Settings
        IPOPT tolerance, iteration limit and barrier strategy, ``constraint_tol`` (constraint
        violation and bound relaxation) and ``degenerate_area`` (flipped-facet threshold).

    Returns
    -------
    Development
        The diagram (V, 2) and its quality. Shapes that are not developable give a diagram
        with a large D; this function does not raise for them.
    """
    t0 = time.perf_counter()
    first = _solve(pattern, pattern.coords[:, :2], "projection", settings)
    if first.status is DevelopStatus.CONVERGED:
        return _timed(first, t0)
    second = _solve(pattern, unfold(pattern), "unfolding", settings)
    best = min(first, second, key=lambda d: (d.status is not DevelopStatus.CONVERGED, d.D))
    other = second if best is first else first
    return _timed(
        replace(
            best,
            message=f"{best.message} (start: {best.start}; from the {other.start}: "
            f"{other.status}, D = {other.D:.3g})",
        ),
        t0,
    )


def _timed(d: Development, t0: float) -> Development:
    return replace(d, wall_time=time.perf_counter() - t0)


def _solve(pattern: CreasePattern, layout: np.ndarray, start: str, settings: Settings):
    """Problem (13) from a layout (V, 2): a Development (wall_time set by the caller)."""
    V = pattern.n_vertices
    edges, faces = pattern.edges, pattern.faces
    k = _reference_edge(pattern)
    a, b = (int(v) for v in edges[k])

    # chi^d: x_a = y_a = y_b = 0 are eliminated; layout of the full vector is [x (V), y (V)]
    free = np.setdiff1d(np.arange(2 * V), [a, V + a, V + b])
    xi = ca.SX.sym("xd", len(free))
    full = ca.SX.zeros(2 * V)
    full[free.tolist()] = xi
    x, y = full[:V], full[V:]

    l3 = pattern.edge_lengths
    e0, e1 = edges[:, 0].tolist(), edges[:, 1].tolist()
    dx, dy = x[e1] - x[e0], y[e1] - y[e0]
    D = ca.sumsqr(ca.sqrt(dx**2 + dy**2) - ca.DM(l3)) / float(np.sum(l3**2))

    f0, f1, f2 = (faces[:, m].tolist() for m in range(3))
    ux, uy = x[f1] - x[f0], y[f1] - y[f0]
    vx, vy = x[f2] - x[f0], y[f2] - y[f0]
    g = (ux * vy - uy * vx) / float(np.mean(l3) ** 2)  # doubled signed area / L^2

    lbx = np.full(len(free), -np.inf)
    lbx[np.searchsorted(free, b)] = 0.0  # b on the +x half-axis
    s = settings
    # a start with two vertices at one point (a crease folded 180 degrees) makes the gradient
    # of |dx| NaN there once; IPOPT steps away from it, so CasADi need not print a warning
    opts = {**ipopt_options(s, tol=s.solver.develop_tol), "show_eval_warnings": False}
    x0 = _initial_guess(pattern, a, b, layout).T.ravel()[free]
    with native_quiet():
        solver = ca.nlpsol("development", "ipopt", {"x": xi, "f": D, "g": g}, opts)
        sol = solver(x0=x0, lbx=lbx, lbg=0.0, ubg=np.inf)
    stats = solver.stats()

    ipopt_status = str(stats.get("return_status", "unknown"))
    X = np.zeros(2 * V)
    X[free] = np.asarray(sol["x"], dtype=np.float64).ravel()
    coords2d = X.reshape(2, V).T.copy()
    coords2d.flags.writeable = False
    D_val, max_err = _diagram_error(coords2d, pattern)

    if not np.isfinite(coords2d).all():
        flipped = overlaps = -1
        status, verdict = DevelopStatus.FAILED, "non-finite coordinates"
    else:
        flipped = count_flipped(coords2d, faces, tol=s.geometry.degenerate_area)
        overlaps = count_overlaps(coords2d, faces, tol=s.geometry.overlap_area_tol)
        if ipopt_status not in _IPOPT_SUCCESS or not np.isfinite(D_val):
            status, verdict = DevelopStatus.FAILED, f"solver failure, D = {D_val:.3g}"
        elif flipped:
            status, verdict = DevelopStatus.FLIPPED, f"{flipped} flipped facets, D = {D_val:.3g}"
        elif overlaps:
            status = DevelopStatus.OVERLAP
            verdict = f"{overlaps} overlapping facet pairs, D = {D_val:.3g}"
        else:
            status, verdict = DevelopStatus.CONVERGED, f"D = {D_val:.3g}"
    return Development(
        coords2d=coords2d,
        D=D_val,
        max_length_error=max_err,
        flipped=flipped,
        overlaps=overlaps,
        status=status,
        message=f"IPOPT: {ipopt_status}; {verdict}",
        iterations=int(stats.get("iter_count", 0)),
        wall_time=0.0,
        reference_edge=k,
        start=start,
    )
