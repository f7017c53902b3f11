"""The crease-pattern model: a triangulated polyhedral disc with free and fixed creases."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import geometry, topology


@dataclass(frozen=True)
class BoundarySide:
    """A straight side of the plan boundary between two corners.

    start, end : int corner vertex indices; inner : (k,) int vertices strictly between them,
    in order. ``line`` gives (b1, b2, b3) with b1 x + b2 y + b3 = 0 and b1^2 + b2^2 = 1.
    """

    start: int
    end: int
    inner: np.ndarray
    line: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class CreasePattern:
    """A triangulated polyhedral disc (the paper's polyhedron) with its crease assignment.

    Attributes
    ----------
    coords : (V, 3) float64
        Vertex coordinates in metres.
    faces : (F, 3) int64
        Triangles, counter-clockwise seen from +z (normals point up).
    edges : (E, 2) int64
        Undirected edges; any order, any orientation (indices of FOLD ``edges_vertices``).
    fixed : (E,) bool
        True for fixed crease lines (the paper's dividing edges, FOLD "J"); their two
        triangles belong to one planar facet.
    settings : Settings
        Tolerances of the model: ``degenerate_area`` and ``plan_area_tol`` (checked on
        construction) and ``corner_angle`` (which boundary vertices are :attr:`corners`). Kept by
        :meth:`with_coords` and :meth:`with_fixed`; not shown in the repr.
    sheet : bool
        True (the default) for a crease pattern as it is built or read: the sheet's rule is
        checked, its faces counter-clockwise seen from +z over an area in plan. False for a
        folded state of a pattern already checked (:meth:`with_coords`, a solver's shape, a
        motion frame): its faces keep the pattern's orientation whatever the shape, so a
        state folded past vertical (negative or zero projected area) is still a state.

    Derived data are cached properties; the arrays are read-only. Construction validates
    the input once and raises ``ValueError`` naming the problem.
    """

    coords: np.ndarray
    faces: np.ndarray
    edges: np.ndarray
    fixed: np.ndarray
    settings: Settings = field(default=DEFAULTS, repr=False, compare=False)
    sheet: bool = field(default=True, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.settings, Settings):
            raise RigidfoldError(f"settings must be a Settings, got {type(self.settings).__name__}")
        coords = np.array(self.coords, dtype=np.float64)
        if coords.ndim != 2 or coords.shape[1] != 3:
            raise RigidfoldError(f"coords must be a (V, 3) array, got shape {coords.shape}")
        if not np.isfinite(coords).all():
            bad = int(np.flatnonzero(~np.isfinite(coords).all(axis=1))[0])
            raise RigidfoldError(f"vertex {bad} has a non-finite coordinate: {coords[bad]}")
        faces = _as_int_array(self.faces, "faces")
        edges = _as_int_array(self.edges, "edges")
        fixed = np.asarray(self.fixed)
        if fixed.shape != (len(edges),) or fixed.dtype != bool:
            raise RigidfoldError(
                f"fixed must be a boolean array of shape ({len(edges)},), got "
                f"{fixed.dtype} array of shape {fixed.shape}"
            )
        topology.validate_topology(faces, edges, len(coords))
        for name, value in (("coords", coords), ("faces", faces), ("edges", edges)):
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        fixed = fixed.copy()
        fixed.flags.writeable = False
        object.__setattr__(self, "fixed", fixed)
        if (fixed & self.is_boundary_edge).any():
            e = int(np.flatnonzero(fixed & self.is_boundary_edge)[0])
            raise RigidfoldError(f"edge {e} is on the boundary and cannot be a fixed crease")
        areas = geometry.face_areas(coords, faces)
        longest = geometry.edge_lengths(coords, edges).max()
        small = areas <= self.settings.geometry.degenerate_area * longest**2
        if small.any():
            f = int(np.flatnonzero(small)[0])
            raise RigidfoldError(
                f"face {f} {tuple(faces[f].tolist())} is degenerate (area {areas[f]:.3g} m^2)"
            )
        if not self.sheet:  # a folded state: the sheet's orientation rule is not its
            return
        plan, surface, zero = geometry.plan_area(
            coords, faces, self.settings.geometry.plan_area_tol
        )
        if zero:
            raise RigidfoldError(
                f"the faces' projection onto the xy plane has zero area ({plan:.3g} m^2 for "
                f"{surface:.3g} m^2 of faces): rigidfold needs a sheet with z up"
            )
        if plan < 0:
            raise RigidfoldError(
                "faces must be counter-clockwise seen from +z: the sheet's projected area is "
                f"negative ({plan:.3g} m^2; reverse the vertex order of every face)"
            )

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_faces(
        cls,
        coords: np.ndarray,
        faces: np.ndarray,
        fixed_edges: np.ndarray | None = None,
        *,
        settings: Settings = DEFAULTS,
    ) -> CreasePattern:
        """Build from vertices and triangles; edges are derived (sorted, ``u < v``).

        coords : (V, 3) or (V, 2) (z = 0); faces : (F, 3); fixed_edges : (k, 2) vertex pairs;
        settings : the pattern's tolerances (see the class).
        """
        coords = np.asarray(coords, dtype=np.float64)
        if coords.ndim == 2 and coords.shape[1] == 2:
            coords = np.column_stack([coords, np.zeros(len(coords))])
        faces = _as_int_array(faces, "faces")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise RigidfoldError(f"faces must be an (F, 3) array of triangles, got {faces.shape}")
        edges = topology.edges_from_faces(faces)
        fixed = np.zeros(len(edges), dtype=bool)
        if fixed_edges is not None and len(fixed_edges):
            n = max(len(coords), int(np.max(edges)) + 1)
            keys = topology.edge_keys(edges, n)
            want = topology.edge_keys(_as_int_array(fixed_edges, "fixed_edges"), n)
            missing = ~np.isin(want, keys)
            if missing.any():
                raise RigidfoldError(
                    f"fixed edge {fixed_edges[int(np.argmax(missing))]} is no edge"
                )
            fixed = np.isin(keys, want)
        return cls(coords=coords, faces=faces, edges=edges, fixed=fixed, settings=settings)

    def with_coords(self, coords: np.ndarray) -> CreasePattern:
        """A folded state of this pattern: same topology and assignment, new vertex
        coordinates (V, 3). Checked as coordinates (finite, no degenerate face), not as a
        crease pattern (``sheet=False``: it may be folded past vertical)."""
        return CreasePattern(
            coords=coords,
            faces=self.faces,
            edges=self.edges,
            fixed=self.fixed,
            settings=self.settings,
            sheet=False,
        )

    def with_fixed(self, fixed: np.ndarray) -> CreasePattern:
        """Same shape, a new fixed-crease mask (E,) bool."""
        return CreasePattern(
            coords=self.coords,
            faces=self.faces,
            edges=self.edges,
            fixed=np.asarray(fixed, bool),
            settings=self.settings,
            sheet=self.sheet,
        )

    # ------------------------------------------------------------------ sizes
    @property
    def n_vertices(self) -> int:
        return len(self.coords)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    # ------------------------------------------------------------------ topology
    @cached_property
    def edge_faces(self) -> np.ndarray:
        """(E, 2) int: face left of ``edges[e,0] -> edges[e,1]``, face right; -1 if none."""
        return topology.edge_faces(self.faces, self.edges, self.n_vertices)

    @cached_property
    def face_edges(self) -> np.ndarray:
        """(F, 3) int: edge of each face from corner k to corner k + 1."""
        he = topology.half_edge_edges(self.faces, self.edges, self.n_vertices)
        return he.reshape(-1, 3)

    @cached_property
    def is_boundary_edge(self) -> np.ndarray:
        """(E,) bool: True for outer edges."""
        return np.any(self.edge_faces < 0, axis=1)

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """(B,) int indices of outer edges."""
        return np.flatnonzero(self.is_boundary_edge)

    @cached_property
    def interior_edges(self) -> np.ndarray:
        """(E - B,) int indices of crease lines (fixed or free)."""
        return np.flatnonzero(~self.is_boundary_edge)

    @cached_property
    def free_creases(self) -> np.ndarray:
        """Indices of crease lines that are not fixed (the paper's E_free)."""
        return np.flatnonzero(~self.is_boundary_edge & ~self.fixed)

    @cached_property
    def fixed_creases(self) -> np.ndarray:
        """Indices of fixed crease lines (the paper's E_fix)."""
        return np.flatnonzero(self.fixed)

    @cached_property
    def boundary_loop(self) -> np.ndarray:
        """(B,) int boundary vertices in counter-clockwise order."""
        he = topology.boundary_half_edges(self.edges, self.edge_faces)
        return topology.boundary_loop(self.edges, he, self.n_vertices)

    @cached_property
    def is_boundary_vertex(self) -> np.ndarray:
        """(V,) bool."""
        mask = np.zeros(self.n_vertices, dtype=bool)
        mask[self.boundary_loop] = True
        return mask

    @cached_property
    def boundary_vertices(self) -> np.ndarray:
        """(B,) int, sorted."""
        return np.flatnonzero(self.is_boundary_vertex)

    @cached_property
    def interior_vertices(self) -> np.ndarray:
        """(V - B,) int, sorted (the paper's V_in)."""
        return np.flatnonzero(~self.is_boundary_vertex)

    @cached_property
    def corners(self) -> np.ndarray:
        """Boundary vertices where the plan boundary turns by more than
        ``settings.geometry.corner_angle`` (the paper's V_c), in loop order."""
        turn = geometry.plan_turning_angles(self.coords, self.boundary_loop)
        return self.boundary_loop[np.abs(turn) > self.settings.geometry.corner_angle]

    @cached_property
    def boundary_sides(self) -> tuple[BoundarySide, ...]:
        """Straight plan sides between consecutive corners, for constraint (7)."""
        loop = list(self.boundary_loop)
        corners = set(self.corners.tolist())
        if len(corners) < 3:
            return ()
        k0 = next(i for i, v in enumerate(loop) if v in corners)
        loop = loop[k0:] + loop[:k0] + [loop[k0]]
        sides: list[BoundarySide] = []
        inner: list[int] = []
        start = loop[0]
        for v in loop[1:]:
            if v in corners:
                sides.append(self._side(start, v, inner))
                start, inner = v, []
            else:
                inner.append(v)
        return tuple(sides)

    def _side(self, start: int, end: int, inner: list[int]) -> BoundarySide:
        (x0, y0), (x1, y1) = self.coords[start, :2], self.coords[end, :2]
        length = np.hypot(x1 - x0, y1 - y0)
        b1, b2 = (y1 - y0) / length, -(x1 - x0) / length
        line = (float(b1), float(b2), float(-(b1 * x0 + b2 * y0)))
        return BoundarySide(start, end, np.asarray(inner, dtype=np.int64), line)

    def crease_stencils(self, creases: np.ndarray) -> np.ndarray:
        """(n, 4) int vertices (u, v, a, b) that the fold angles of ``creases`` (n,) depend on:
        each crease's ends and the opposite corners of its left and right triangles."""
        creases = np.asarray(creases, dtype=np.int64)
        return topology.crease_stencils(self.faces, self.edges, self.edge_faces, creases)

    @cached_property
    def facets(self) -> np.ndarray:
        """(F,) int facet label of each triangle: triangles joined by fixed creases share one."""
        return topology.face_components(self.n_faces, self.edge_faces, self.fixed)

    @property
    def n_facets(self) -> int:
        return int(self.facets.max()) + 1

    @cached_property
    def vertex_degree(self) -> np.ndarray:
        """(V,) int number of edges at each vertex."""
        return np.bincount(self.edges.ravel(), minlength=self.n_vertices)

    @property
    def generic_dof(self) -> int:
        """Generic DOF count of a triangulated disc: free creases - 3 x interior vertices.

        Exact for generic all-triangle shapes with no fixed crease (e.g. Table 4's initial DOF);
        the mechanism analysis gives the true DOF of a particular shape.
        """
        return len(self.free_creases) - 3 * len(self.interior_vertices)

    # ------------------------------------------------------------------ geometry
    @cached_property
    def corner_angles(self) -> np.ndarray:
        """(F, 3) float: sector angle of triangle f at vertex ``faces[f, k]`` (radians)."""
        return geometry.corner_angles(self.coords, self.faces)

    @cached_property
    def angle_sums(self) -> np.ndarray:
        """(V,) float: sum of sector angles around each vertex (radians)."""
        return geometry.angle_sums(self.coords, self.faces)

    @cached_property
    def angle_defects(self) -> np.ndarray:
        """(V_in,) float: 2 pi - angle sum at each interior vertex (discrete Gaussian curvature)."""
        return 2 * np.pi - self.angle_sums[self.interior_vertices]

    def sector_angles(self, vertex: int) -> np.ndarray:
        """Sector angles around one vertex (radians), one per incident triangle."""
        rows, cols = np.nonzero(self.faces == vertex)
        return self.corner_angles[rows, cols]

    @cached_property
    def face_normals(self) -> np.ndarray:
        """(F, 3) float unit normals (CCW faces: pointing up)."""
        return geometry.face_normals(self.coords, self.faces)

    @cached_property
    def fold_angles(self) -> np.ndarray:
        """(E,) float signed fold angles in radians, valley positive, 0 on the boundary."""
        return geometry.fold_angles(self.coords, self.faces, self.edges, self.edge_faces)

    @cached_property
    def edge_lengths(self) -> np.ndarray:
        """(E,) float."""
        return geometry.edge_lengths(self.coords, self.edges)

    @cached_property
    def flatness_residuals(self) -> np.ndarray:
        """(E_fix,) |n_a x n_b|^2 of each fixed crease (the terms of F2)."""
        ef = self.edge_faces[self.fixed]
        n = self.face_normals
        return np.sum(np.cross(n[ef[:, 0]], n[ef[:, 1]]) ** 2, axis=1)

    def summary(self) -> dict:
        """Sizes and counts, JSON-serialisable."""
        return {
            "vertices": self.n_vertices,
            "edges": self.n_edges,
            "faces": self.n_faces,
            "facets": self.n_facets,
            "interior_vertices": len(self.interior_vertices),
            "free_creases": len(self.free_creases),
            "fixed_creases": len(self.fixed_creases),
        }

    def __repr__(self) -> str:
        return (
            f"CreasePattern(V={self.n_vertices}, E={self.n_edges}, F={self.n_faces}, "
            f"fixed={int(self.fixed.sum())})"
        )


def _as_int_array(value, name: str) -> np.ndarray:
    arr = np.asarray(value)
    if arr.size == 0:
        return arr.astype(np.int64).reshape(0, *arr.shape[1:]) if arr.ndim > 1 else arr
    if not np.issubdtype(arr.dtype, np.integer):
        if np.issubdtype(arr.dtype, np.floating) and np.all(np.isfinite(arr)):
            if np.all(arr == np.round(arr)):
                return arr.astype(np.int64)
        raise RigidfoldError(f"{name} must hold integer vertex indices, got dtype {arr.dtype}")
    return arr.astype(np.int64)
