"""A target surface z = f(x, y) given as a triangle mesh (OBJ, STL, PLY or OFF file).

The mesh is sampled on a regular grid over its plan bounding box by vertical ray casting and
the samples are fitted by an interpolating bicubic spline (SciPy's ``RectBivariateSpline``),
evaluated for NumPy and for CasADi by one CasADi B-spline Function, so that ``height`` is
twice continuously differentiable with exact derivatives in problem (6).

* **Overhangs.** Where a vertical line meets the mesh more than once (a sheet that folds over
  itself), the highest point is taken: the surface as seen from above. Its jump is not a
  smooth surface; ``fit_error`` shows how far the spline is from it. A closed mesh (a solid)
  projects onto zero area and is refused.
* **Footprint.** The plan region the mesh covers; a plan point within
  ``Settings.inputs.surface_footprint_tol`` times the longer side of the plan box of it counts as
  inside. ``check_finite`` refuses plan points outside it. Grid nodes outside it get the
  smoothest continuation of the heights inside (least squares of third differences), so the
  spline continues the surface across the boundary; beyond the plan box the spline's end
  pieces continue for ``PAD`` cells.
* **Resolution.** ``Settings.inputs.surface_grid_nodes`` nodes along the longer side of the
  plan box, the same spacing along the other. A grid finer than the mesh's triangles makes the
  spline follow their facets; a coarser one smooths them. ``fit_error`` is measured either way.
* **Size.** A mesh of more than ``Settings.limits.max_mesh_triangles`` triangles is refused (a
  binary STL file before it is loaded). The heights are found through buckets of the plan
  points and the columns of them each triangle crosses (:func:`_candidates`), in batches:
  the memory is linear in the mesh and the points, also for the long thin triangles of a
  fan (a polygon face of an OBJ file), whose bounding boxes cover most of the plan.

``trimesh`` reads the files; it is imported when a file is read, not with ``rigidfold``.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

import casadi as ca
import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.surfaces.builtin import Surface

MESH_FORMATS = ("obj", "stl", "ply", "off")
"""File extensions :func:`read_mesh` reads."""
PAD = 3
"""Grid cells beyond the plan box on each side where the spline is continued (zero beyond)."""
_MEMBRANE = 1e-3
"""Weight of the first differences beside the third ones in the continuation outside the
footprint: makes it unique however few grid nodes the footprint covers."""


class SplineSurface(Surface):
    """The bicubic spline of a :class:`MeshSurface` through its grid heights, without the
    mesh: what a run stores of a mesh target (:meth:`grid`) and its report reads back
    (``target_surface.json``), the same heights and derivatives.

    gx (nx,), gy (ny,) : float64 strictly increasing grid nodes, 4 to
    :data:`MAX_GRID_NODES` each; z (nx, ny) float64 : finite heights there; source : the
    mesh's name. Raises ValueError naming what is wrong with them.
    """

    name = "mesh"

    def __init__(self, gx: Any, gy: Any, z: Any, *, source: str = "mesh") -> None:
        gx, gy, z = _grid_problem(gx, gy, z)
        self._grid = (gx, gy, z)
        self.source = source
        self._spline = _bspline(gx, gy, z)
        xy = ca.MX.sym("xy", 2)
        self._gradient = ca.Function("mesh_gradient", [xy], [ca.gradient(self._spline(xy), xy)])

    def grid(self) -> dict[str, Any]:
        """The spline's data as JSON: ``{"source", "x" (nx,), "y" (ny,), "z" (nx, ny)}``;
        ``SplineSurface(d["x"], d["y"], d["z"], source=d["source"])`` rebuilds it."""
        gx, gy, z = self._grid
        return {"source": self.source, "x": gx.tolist(), "y": gy.tolist(), "z": z.tolist()}

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        """z at plan points: NumPy x, y broadcast together (z has their shape), or CasADi
        symbols with ``xp=casadi`` (z has the shape of x)."""
        if xp is not np:
            z = self._spline(ca.horzcat(ca.vec(x), ca.vec(y)).T)  # one column per point
            return ca.reshape(z, x.shape[0], x.shape[1])
        return self._at(self._spline, x, y)[0]

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """(dz/dx, dz/dy) of the spline at plan points, each of the broadcast shape of x, y."""
        dx, dy = self._at(self._gradient, x, y)
        return dx, dy

    def metadata(self) -> dict[str, Any]:
        gx, gy, _ = self._grid
        return {"name": self.name, "source": self.source, "grid": [len(gx), len(gy)]}

    @staticmethod
    def _at(function: ca.Function, x: Any, y: Any) -> np.ndarray:
        """A Function of one plan point (2, 1) -> (k, 1) at the plan points x, y (broadcast
        together).  -> (k, *shape)"""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        k = function.size1_out(0)
        if x.size == 0:
            return np.zeros((k, *x.shape))
        # a (2, n) matrix evaluates the function at n points, one column each
        return np.asarray(function(np.vstack([x.ravel(), y.ravel()]))).reshape(k, *x.shape)


MAX_GRID_NODES = 513
"""Most grid nodes along one side of a mesh fit (``Settings.inputs.surface_grid_nodes`` at most)."""


def _grid_problem(gx: Any, gy: Any, z: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """gx, gy, z of a :class:`SplineSurface` as float64 arrays; ValueError naming the first
    thing wrong (not numbers, sizes, order, non-finite)."""
    try:
        gx, gy, z = (np.asarray(a, dtype=float) for a in (gx, gy, z))
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer like 10**400
        raise RigidfoldError("the grid of a mesh fit must hold numbers only") from None
    for axis, g in (("x", gx), ("y", gy)):
        if g.ndim != 1 or not 4 <= len(g) <= MAX_GRID_NODES:
            raise RigidfoldError(
                f"the grid's {axis} must be a list of 4 to {MAX_GRID_NODES} nodes, got shape "
                f"{g.shape}"
            )
        if not (np.isfinite(g).all() and (np.diff(g) > 0).all()):
            raise RigidfoldError(f"the grid's {axis} nodes must be finite and increasing")
    if z.shape != (len(gx), len(gy)) or not np.isfinite(z).all():
        raise RigidfoldError(
            f"the grid's heights must be finite numbers of shape ({len(gx)}, {len(gy)}), got "
            f"shape {z.shape}"
        )
    return gx, gy, z


class MeshSurface(SplineSurface):
    """z = f(x, y) fitted to a triangle mesh seen from above (see the module's notes).

    vertices : (N, 3) float64, metres, z up;  triangles : (M, 3) int64 indices into vertices;
    source : the mesh's name in messages and metadata (e.g. its file name).

    Attributes: ``bounds`` (2, 2) = [[x_min, y_min], [x_max, y_max]] of the mesh's plan;
    ``grid_shape`` (nodes along x, along y) over that box; ``fit_error``: the largest
    |spline - mesh| in metres at the mesh's vertices and at the centres of the grid's cells
    inside the footprint.
    """

    name = "mesh"

    def __init__(
        self,
        vertices: np.ndarray,
        triangles: np.ndarray,
        *,
        source: str = "mesh",
        settings: Settings = DEFAULTS,
    ) -> None:
        problem = _mesh_problem(vertices, triangles, settings)
        if problem:
            raise RigidfoldError(f"mesh {source}: {problem}")
        self.vertices = np.asarray(vertices, dtype=float)
        self.triangles = np.asarray(triangles, dtype=np.int64)
        self.source = source
        corners = self.vertices[self.triangles]  # (M, 3, 3)
        plan = corners[:, :, :2]
        self.bounds = np.array([plan.min(axis=(0, 1)), plan.max(axis=(0, 1))])
        size = float((self.bounds[1] - self.bounds[0]).max())
        self._tol = settings.inputs.surface_footprint_tol * size
        # triangles seen edge-on from above (zero plan area) give no height
        e1, e2 = plan[:, 1] - plan[:, 0], plan[:, 2] - plan[:, 0]
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        longest = np.linalg.norm(plan - np.roll(plan, 1, axis=1), axis=2).max(axis=1)
        seen = np.abs(det) / 2 > settings.geometry.degenerate_area * longest**2
        self._corners, self._det = corners[seen], det[seen]

        extent = self.bounds[1] - self.bounds[0]
        cells = np.maximum(np.round(extent * (settings.inputs.surface_grid_nodes - 1) / size), 3)
        gx, gy = (
            np.linspace(self.bounds[0, k], self.bounds[1, k], int(cells[k]) + 1) for k in (0, 1)
        )
        self.grid_shape = (len(gx), len(gy))
        nodes = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1).reshape(-1, 2)
        z = self._top(nodes).reshape(self.grid_shape)
        if np.isnan(z).all():
            raise RigidfoldError(
                f"mesh {source}: its footprint covers no node of the {len(gx)} x {len(gy)} grid "
                "over its plan box; raise surface_grid_nodes"
            )
        super().__init__(gx, gy, _continue(z), source=source)

        mid = ((gx[:-1] + gx[1:]) / 2, (gy[:-1] + gy[1:]) / 2)
        centres = np.stack(np.meshgrid(*mid, indexing="ij"), axis=-1).reshape(-1, 2)
        check = np.vstack([self.vertices[np.unique(self.triangles), :2], centres])
        mesh_z = self._top(check)
        found = ~np.isnan(mesh_z)
        gap = np.abs(self.height(check[found, 0], check[found, 1]) - mesh_z[found])
        self.fit_error = float(gap.max())

    def check_finite(self, x: Any, y: Any) -> None:
        """Raise ValueError naming the first plan point outside the mesh's footprint.  x, y (N,)"""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        points = np.column_stack([x.ravel(), y.ravel()])
        finite = np.isfinite(points).all(axis=1)
        inside = np.zeros(len(points), dtype=bool)
        inside[finite] = ~np.isnan(self._top(points[finite]))
        if not inside.all():
            i = int(np.flatnonzero(~inside)[0])
            (x0, y0), (x1, y1) = self.bounds
            raise RigidfoldError(
                f"plan point {i} at (x, y) = ({points[i, 0]:g}, {points[i, 1]:g}) lies outside "
                f"the footprint of mesh {self.source} (plan box x {x0:g}..{x1:g}, "
                f"y {y0:g}..{y1:g} m)"
            )

    def metadata(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "source": self.source,
            "vertices": len(self.vertices),
            "triangles": len(self.triangles),
            "grid": list(self.grid_shape),
            "fit_error_m": self.fit_error,
            "plan_bounds_m": self.bounds.ravel().tolist(),
        }

    def __repr__(self) -> str:
        return (
            f"MeshSurface(<{len(self.vertices)} vertices, {len(self.triangles)} triangles>, "
            f"source={self.source!r})"
        )

    def _top(self, points: np.ndarray) -> np.ndarray:
        """Height of the highest triangle within the footprint tolerance above or below each
        plan point, NaN where there is none.  points (P, 2) -> (P,)

        The candidate pairs of points and triangles come in batches of bounded size
        (:func:`_candidates`), so that the memory stays linear in the mesh and the points."""
        c, tol = self._corners, self._tol
        top = np.full(len(points), np.nan)
        for point, tri in _candidates(points, c[:, :, :2], tol):
            a, e1, e2 = c[tri, 0], c[tri, 1] - c[tri, 0], c[tri, 2] - c[tri, 0]
            d = points[point] - a[:, :2]
            u = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / self._det[tri]
            v = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / self._det[tri]
            hit = (u >= 0) & (v >= 0) & (u + v <= 1)
            near = np.flatnonzero(~hit)
            if tol > 0 and near.size:
                p, corners = points[point[near]], c[tri[near], :, :2]
                gaps = [_segment_distance(p, corners[:, k], corners[:, k - 1]) for k in range(3)]
                hit[near] = np.min(gaps, axis=0) <= tol
            np.fmax.at(top, point[hit], (a[:, 2] + u * e1[:, 2] + v * e2[:, 2])[hit])
        return top


def _mesh_problem(
    vertices: Any, triangles: Any, settings: Settings = DEFAULTS, hint: str = ""
) -> str:
    """What makes (vertices, triangles) no mesh surface, or "" (``hint`` ends the message about
    a zero plan area)."""
    v, t = np.asarray(vertices), np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3 or not np.issubdtype(v.dtype, np.number):
        return f"vertices must be an (N, 3) array of numbers, got shape {v.shape}"
    if t.ndim != 2 or t.shape[1] != 3 or not (t.size == 0 or np.issubdtype(t.dtype, np.integer)):
        return f"triangles must be an (M, 3) array of vertex indices, got shape {t.shape}"
    if len(t) == 0:
        return "no triangles"
    if len(t) > settings.limits.max_mesh_triangles:
        return _too_many(len(t), settings)
    outside = t[(t < 0) | (t >= len(v))]
    if outside.size:
        return f"a triangle refers to vertex {outside[0]}, but there are {len(v)} vertices"
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        return f"vertex {bad[0]} has non-finite coordinates {v[bad[0]].tolist()}"
    far = np.flatnonzero(np.abs(v).max(axis=1) > settings.limits.max_coordinate)
    if far.size:  # before the areas below overflow
        return (
            f"vertex {far[0]} at {v[far[0]].tolist()} lies farther than "
            f"{settings.limits.max_coordinate:g} m from the origin (Settings.limits.max_coordinate)"
        )
    c = v[t].astype(float)
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    plan = float((e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()) / 2
    surface = float(np.linalg.norm(np.cross(e1, e2), axis=1).sum()) / 2
    if abs(plan) <= settings.geometry.plan_area_tol * surface:
        return (
            "the triangles' projection onto the xy plane has zero area (faces turned down "
            "count negative): a target surface needs z up and an open sheet, not a vertical "
            f"or closed one{hint}"
        )
    return ""


def _too_many(count: int, settings: Settings) -> str:
    """The message about a mesh of ``count`` triangles, more than the limit."""
    return (
        f"{count} triangles, more than {settings.limits.max_mesh_triangles} "
        "(Settings.limits.max_mesh_triangles): decimate the mesh; the surface is sampled on at "
        "most "
        "513 x 513 grid nodes"
    )


def read_mesh(
    path: str | Path, *, up: str = "z", settings: Settings = DEFAULTS
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3) float64 and triangles (M, 3) int64 of an OBJ, STL, PLY or OFF file.

    up : the file's up axis, "z", or "y" for a file drawn y-up (Blender, Origami Simulator),
        whose (x, y, z) becomes (x, -z, y) as in :func:`rigidfold.io.read_fold`.
    A file holding several meshes (a scene) gives them concatenated. Raises a one-line
    ValueError naming the file when it cannot be read or is no mesh surface.
    """
    if up not in ("z", "y"):
        raise RigidfoldError(f"up must be z or y, got {up!r}")
    path = Path(path)
    kind = path.suffix.lower().lstrip(".")
    if kind not in MESH_FORMATS:
        raise RigidfoldError(
            f"mesh {path}: unknown extension {path.suffix!r} (read: "
            f"{', '.join('.' + k for k in MESH_FORMATS)})"
        )
    if not path.is_file():
        raise RigidfoldError(f"cannot read mesh {path}: no such file")
    if kind == "stl":
        count = _check_stl(path)
        if count is not None and count > settings.limits.max_mesh_triangles:
            raise RigidfoldError(f"mesh {path}: {_too_many(count, settings)}")
    import trimesh

    try:
        mesh = trimesh.load(str(path), file_type=kind, force="mesh", process=False)
    except Exception as exc:  # the parsers raise anything from KeyError to struct.error
        reason = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise RigidfoldError(f"cannot read mesh {path} as {kind.upper()} ({reason})") from None
    if not isinstance(mesh, trimesh.Trimesh):  # force="mesh" makes one of any scene
        raise RigidfoldError(f"mesh {path}: holds a {type(mesh).__name__}, not a triangle mesh")
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    triangles = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    if up == "y":
        vertices = vertices[:, [0, 2, 1]] * [1.0, -1.0, 1.0]
    hint = "; is the file y-up? (--up y)" if up == "z" else "; is the file z-up? (--up z)"
    problem = _mesh_problem(vertices, triangles, settings, hint)
    if problem:
        raise RigidfoldError(f"mesh {path}: {problem}")
    return vertices, triangles


def _check_stl(path: Path) -> int | None:
    """The triangle count of a binary STL file (None for ASCII STL), read from its header
    before the file is loaded. ValueError naming ``path`` for an STL file that is neither a
    binary STL of the size its header gives (84 bytes, then 50 per triangle counted at byte
    80) nor ASCII STL text (``solid`` ...): a damaged or cut binary file, which trimesh would
    try to read as text of an unknown encoding."""
    try:
        size = path.stat().st_size
        with path.open("rb") as file:
            head = file.read(84)
            if len(head) == 84 and 84 + 50 * int.from_bytes(head[80:], "little") == size:
                return int.from_bytes(head[80:], "little")
            if head.lstrip()[:5].lower() == b"solid":
                file.seek(0)
                file.read().decode("utf-8")
                return None
    except OSError as exc:
        raise RigidfoldError(f"cannot read mesh {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        pass
    if len(head) < 84:
        found = f"it has {size} bytes, fewer than the 84 of a binary STL header"
    else:
        count = int.from_bytes(head[80:], "little")
        found = f"its header counts {count} triangles, {84 + 50 * count} bytes, but it has {size}"
    raise RigidfoldError(
        f"mesh {path}: a damaged binary STL ({found}) and no ASCII STL (UTF-8 text starting "
        "with 'solid')"
    )


def sample_mesh(
    surface: Surface, n: int, box: tuple[float, float] = (3.0, 3.0)
) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh of ``surface`` on n x n vertices over [0, W] x [0, H] (e.g. to write a
    target surface as OBJ for CAD, or to test the mesh fit against its formula).

    Returns vertices (n*n, 3) float64, vertex (i, j) at index i n + j with x = i W / (n - 1),
    y = j H / (n - 1), and triangles (2 (n-1)^2, 3) int64, counter-clockwise seen from +z.
    """
    gx, gy = np.linspace(0.0, box[0], n), np.linspace(0.0, box[1], n)
    x, y = (a.ravel() for a in np.meshgrid(gx, gy, indexing="ij"))
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = (k.ravel() for k in (idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]))
    triangles = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return np.column_stack([x, y, surface.height(x, y)]), triangles


def mesh_surface(path: str | Path, *, up: str = "z", settings: Settings = DEFAULTS) -> MeshSurface:
    """:class:`MeshSurface` of a mesh file (see :func:`read_mesh`), named by its file name."""
    vertices, triangles = read_mesh(path, up=up, settings=settings)
    return MeshSurface(vertices, triangles, source=Path(path).name, settings=settings)


_BATCH = 1 << 18
"""Candidate pairs (and strips of triangles) :func:`_candidates` yields at most at once
(unless one strip alone has more): some 30 MB of temporary arrays in ``MeshSurface._top``."""


def _candidates(points: np.ndarray, plan: np.ndarray, tol: float, batch: int = _BATCH):
    """Batches (point index (K,), triangle index (K,)) of every plan point that may lie within
    ``tol`` of a triangle: a superset, each pair once.  points (P, 2), plan (M, 3, 2)

    The points are sorted into square buckets about one point apart; each triangle is cut
    into the columns of buckets it spans, and in each column only the buckets between its
    lowest and highest point there (widened by ``tol``) are candidates, one contiguous run
    of the sorted points. A long thin triangle (a fan's) thus meets the points along it,
    not all the points of its bounding box: the work is about the sum of the triangles'
    widths in bucket columns plus the pairs, in batches of about ``batch`` of each.
    """
    if not len(points) or not len(plan):
        return
    pmin, pmax = points.min(axis=0), points.max(axis=0)
    lo, hi = plan.min(axis=1) - tol, plan.max(axis=1) + tol
    tris = np.flatnonzero((hi >= pmin).all(axis=1) & (lo <= pmax).all(axis=1))
    if not tris.size:
        return
    extent = pmax - pmin
    cell = max(float(np.sqrt(extent.prod() / len(points))), float(extent.max()) / len(points))
    cell = cell if cell > 0 else 1.0  # all points at one place
    shape = (extent // cell).astype(np.int64) + 1
    key = np.minimum(((points - pmin) // cell).astype(np.int64), shape - 1)
    bucket = key[:, 0] * shape[1] + key[:, 1]
    order = np.argsort(bucket, kind="stable")
    start = np.searchsorted(bucket[order], np.arange(shape.prod() + 1))
    columns = np.clip(
        (np.stack([lo[tris, 0], hi[tris, 0]], axis=1) - pmin[0]) // cell, 0, shape[0] - 1
    )
    columns = columns.astype(np.int64)
    width = columns[:, 1] - columns[:, 0] + 1
    ends = np.searchsorted(np.cumsum(width), np.arange(batch, int(width.sum()), batch))
    for chunk in np.split(np.arange(len(tris)), ends + 1):
        if not chunk.size:
            continue
        owner, k = _ragged(width[chunk])
        tri, column = tris[chunk][owner], columns[chunk, 0][owner] + k
        ylo, yhi = _strip_span(
            plan[tri], pmin[0] + column * cell - tol, pmin[0] + (column + 1) * cell + tol
        )
        rows = np.clip((np.stack([ylo - tol, yhi + tol], axis=1) - pmin[1]) // cell, -1, shape[1])
        rows = rows.astype(np.int64)
        first = column * shape[1] + np.clip(rows[:, 0], 0, shape[1] - 1)
        last = column * shape[1] + np.clip(rows[:, 1], 0, shape[1] - 1)
        outside = (rows[:, 1] < 0) | (rows[:, 0] >= shape[1])
        s0, count = start[first], np.where(outside, 0, start[last + 1] - start[first])
        cuts = np.searchsorted(np.cumsum(count), np.arange(batch, int(count.sum()), batch))
        for piece in np.split(np.arange(len(tri)), cuts + 1):
            owner, j = _ragged(count[piece])
            if owner.size:
                yield order[s0[piece][owner] + j], tri[piece][owner]


def _strip_span(
    corners: np.ndarray, xa: np.ndarray, xb: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest y of triangles within the vertical strips xa <= x <= xb (each
    meeting its triangle): over the pieces of its three sides inside the strip.
    corners (K, 3, 2), xa, xb (K,) -> (K,), (K,)"""
    low, high = np.full(len(xa), np.inf), np.full(len(xa), -np.inf)
    for k in range(3):
        p, q = corners[:, k], corners[:, k - 1]
        x0, x1 = np.minimum(p[:, 0], q[:, 0]), np.maximum(p[:, 0], q[:, 0])
        a, b = np.maximum(xa, x0), np.minimum(xb, x1)
        on = a <= b
        dx = q[:, 0] - p[:, 0]
        slope = np.divide(q[:, 1] - p[:, 1], dx, out=np.zeros_like(dx), where=dx != 0)
        ya, yb = p[:, 1] + (a - p[:, 0]) * slope, p[:, 1] + (b - p[:, 0]) * slope
        flat = dx == 0  # a vertical side: both its ends
        ya, yb = np.where(flat, p[:, 1], ya), np.where(flat, q[:, 1], yb)
        low = np.where(on, np.minimum(low, np.minimum(ya, yb)), low)
        high = np.where(on, np.maximum(high, np.maximum(ya, yb)), high)
    missed = low > high  # round-off: the whole triangle
    low[missed], high[missed] = corners[missed, :, 1].min(axis=1), corners[missed, :, 1].max(axis=1)
    return low, high


def _ragged(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, index within its owner) of each item when owner i has counts[i] items.  (n,)"""
    owner = np.repeat(np.arange(len(counts)), counts)
    return owner, np.arange(len(owner)) - (np.cumsum(counts) - counts)[owner]


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of plan points from segments a-b (of positive length).  (K, 2) each -> (K,)"""
    ab = b - a
    t = np.clip(((p - a) * ab).sum(axis=1) / (ab * ab).sum(axis=1), 0.0, 1.0)
    return np.linalg.norm(p - a - t[:, None] * ab, axis=1)


def _continue(z: np.ndarray) -> np.ndarray:
    """Grid heights (nx, ny) with their NaN replaced by the smoothest continuation of the others:
    least squares of all third differences (and ``_MEMBRANE`` times the first ones).

    Third differences continue the curvature across the footprint's boundary, so that the
    spline through the grid bends there as the mesh does (second differences would continue
    it flat: ten times the fit error on a dome's disc)."""
    from math import comb

    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    unknown = np.isnan(z).ravel()
    if not unknown.any():
        return z
    stencils = [  # (weight, [(coefficient, node offset (along x, along y))])
        (
            np.sqrt(comb(3, i)),  # d3 / dx^i dy^(3 - i), weighted as in |D^3 z|^2
            [
                ((-1) ** (3 - a - b) * comb(i, a) * comb(3 - i, b), (a, b))
                for a in range(i + 1)
                for b in range(4 - i)
            ],
        )
        for i in range(4)
    ]
    stencils += [(_MEMBRANE, [(-1, (0, 0)), (1, d)]) for d in ((1, 0), (0, 1))]
    nx, ny = z.shape
    index = np.arange(z.size).reshape(z.shape)
    rows, cols, values, n_rows = [], [], [], 0
    for weight, terms in stencils:
        reach = np.max([offset for _, offset in terms], axis=0)
        anchors = index[: nx - reach[0], : ny - reach[1]].ravel()
        for coefficient, (a, b) in terms:
            rows.append(n_rows + np.arange(anchors.size))
            cols.append(anchors + a * ny + b)
            values.append(np.full(anchors.size, weight * coefficient))
        n_rows += anchors.size
    A = sparse.csc_array(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), (n_rows, z.size)
    )
    A_u, A_k = A[:, np.flatnonzero(unknown)], A[:, np.flatnonzero(~unknown)]
    filled = z.ravel().copy()
    filled[unknown] = spsolve((A_u.T @ A_u).tocsc(), -(A_u.T @ (A_k @ filled[~unknown])))
    return filled.reshape(z.shape)


def _bspline(gx: np.ndarray, gy: np.ndarray, z: np.ndarray) -> ca.Function:
    """The bicubic not-a-knot spline through heights z (nx, ny) at the grid gx (nx,) x gy (ny,),
    continued by its end pieces ``PAD`` cells beyond the grid: a CasADi Function (2, 1) -> (1, 1)
    that SX expressions call (and differentiate) as one node."""
    from scipy.interpolate import RectBivariateSpline, make_interp_spline

    pads = [g[0] + (g[1] - g[0]) * np.arange(-PAD, len(g) + PAD) for g in (gx, gy)]
    z = make_interp_spline(gx, z, k=3, axis=0)(pads[0])
    z = make_interp_spline(gy, z, k=3, axis=1)(pads[1])
    tx, ty, coefficients = RectBivariateSpline(*pads, z, kx=3, ky=3, s=0).tck
    grid = coefficients.reshape(len(tx) - 4, len(ty) - 4)
    spline = ca.Function.bspline(
        "mesh_spline", [tx.tolist(), ty.tolist()], grid.ravel(order="F").tolist(), [3, 3], 1, {}
    )
    xy = ca.MX.sym("xy", 2)
    return ca.Function("mesh_height", [xy], [spline(xy)], {"never_inline": True})
