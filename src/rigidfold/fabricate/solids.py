"""Thick solids of the panels: tapered along the hinges, relieved at the vertices.

Each panel becomes a solid of thickness ``t`` on one side of the design surface (Tachi's
rigid-foldable thick origami: the design surface is one face of every solid and the hinge
axes stay on the crease lines, so the mechanism and its motion are those of the
zero-thickness design).

**Bevel of a hinge.** Cut the two solids of a hinge by the plane through the axis
perpendicular to the axis. In that section each solid is a strip of depth ``t`` that starts
at the axis, and the two strips' surface lines make the dihedral angle ``pi - rho`` on the
material side, where ``rho`` is how far the hinge has folded towards the material
(:meth:`rigidfold.fabricate.panels.Panels.closing`; 0 flat). Square-edged strips overlap as
soon as ``rho > 0``, and even flat they touch over the whole depth. Trim each solid by the
plane through the axis at the angle ``alpha`` to its own surface (a *bevel*: the far face
is set back from the axis by ``t / tan(alpha)``). Each trimmed section is a wedge of angle
``alpha`` with its apex on the axis, and the two wedges sit at the two ends of the dihedral
angle ``pi - rho``, so they meet only on the axis while ``2 alpha <= pi - rho``. With
``rho_max``, the largest closing fold of the hinge from flat to the design over the traced
motion (never below 0), and the clearance angle ``c``,

    alpha = (pi - rho_max - c) / 2,

the bisector plane of the dihedral angle at the fold ``rho_max + c``: the solids meet only
along the axis for every fold from opening fully flat to ``rho_max + c``, with the angle ``c``
to spare (a hinge that folds away from the material gets ``alpha = (pi - c) / 2``, a bevel
of ``c / 2``, so that neighbours touch only along the axis even flat). A hinge that folds to
``rho_max + c >= pi`` would need ``alpha <= 0``: its panels are trimmed away. Seen around
the axis line, every point of either solid stays within its wedge, whatever its distance
along the axis, so :attr:`Solids.fold_limit` (the fold at which the wedges of the built
solids meet, measured on their vertices) proves that neighbours do not interpenetrate for
the whole motion: :mod:`rigidfold.fabricate.collision` compares it with the fold at every
frame.

**Relief at a vertex.** Panels that meet at a vertex without a common hinge would touch at
that vertex all the way. At each such vertex (:attr:`Panels.relief_vertices`) every corner
is cut off by the plane perpendicular to the surface and to the corner's bisector at the
distance ``r`` from the vertex (:data:`rigidfold.config.Settings.fabricate.vertex_relief`
thicknesses; doubled where the check finds the solids too close), so no solid comes
nearer than ``r`` to the vertex's normal line and the hinges end there.

**Construction.** A panel is a union of triangles, so each solid is the union of one convex
piece per triangle: the triangle's prism of depth ``t`` (along the panel's normal, to the
material side), trimmed by the bevel planes of the panel's hinges whose line leaves the
whole triangle on the panel's side (all of them for a convex panel, whose solid is then
exactly the prism trimmed by every bevel) and by the reliefs at its corners. The pieces
are convex hulls and plane cuts of manifold3d, their union its exact boolean: each solid is
a closed, oriented, watertight mesh. The convex pieces themselves go to the collision check
(GJK distances of python-fcl).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rigidfold.fabricate.panels import Panels
from rigidfold.runtime.interrupts import held_import

_ON_LINE = 1e-9
"""A triangle vertex within this many edge lengths of a hinge's line counts as on it."""


@dataclass(frozen=True, eq=False)
class Piece:
    """One convex piece of a solid (a trimmed triangle prism), in the design.

    panel : int; face : the triangle it is built on; vertices : (n, 3) float64, metres;
    triangles : (m, 3) int, its hull's triangles (outward).
    """

    panel: int
    face: int
    vertices: np.ndarray
    triangles: np.ndarray

    @cached_property
    def centre(self) -> np.ndarray:
        """(3,) float64: mean of the vertices."""
        return self.vertices.mean(axis=0)

    @cached_property
    def radius(self) -> float:
        """Largest distance of a vertex from :attr:`centre`."""
        return float(np.linalg.norm(self.vertices - self.centre, axis=1).max())


@dataclass(frozen=True, eq=False)
class Solids:
    """The thick solids of the panels in the design.

    Attributes
    ----------
    panels : Panels
    thickness : float, metres
    bevel : (H,) float64
        Angle between each hinge's bevel face and the surface, radians (the same on both
        panels of the hinge); pi/2 would be a square edge.
    relief : (V,) float64
        Relief radius at each vertex, metres (0: none).
    pieces : tuple of Piece
        The convex pieces, every panel's in face order.
    bevels_of_face : tuple of (k,) int arrays
        The hinges whose bevel trims each triangle's piece (see the module's text).
    meshes : tuple of (vertices (n, 3) float64, triangles (m, 3) int64)
        Each panel's solid, watertight (empty arrays when nothing is left).
    volumes : (P,) float64, m^3
    depth : (P,) float64
        How deep each solid reaches below (or above, for the top side) its surface, metres:
        the thickness, unless its bevels meet first.
    empty_faces : (k,) int
        Triangles whose piece was trimmed away completely.
    """

    panels: Panels
    thickness: float
    bevel: np.ndarray
    relief: np.ndarray
    pieces: tuple[Piece, ...]
    bevels_of_face: tuple[np.ndarray, ...]
    meshes: tuple[tuple[np.ndarray, np.ndarray], ...]
    volumes: np.ndarray
    depth: np.ndarray
    empty_faces: np.ndarray

    @cached_property
    def pieces_of(self) -> tuple[tuple[Piece, ...], ...]:
        """The pieces of each panel."""
        out: list[list[Piece]] = [[] for _ in range(self.panels.n)]
        for piece in self.pieces:
            out[piece.panel].append(piece)
        return tuple(tuple(x) for x in out)

    @cached_property
    def centres(self) -> np.ndarray:
        """(P, 3) float64: centre of each solid's bounding sphere (its vertices' mean)."""
        out = np.zeros((self.panels.n, 3))
        for k, (verts, _) in enumerate(self.meshes):
            out[k] = (
                verts.mean(axis=0)
                if len(verts)
                else self.panels.pattern.coords[self.panels.vertices[k]].mean(axis=0)
            )
        return out

    @cached_property
    def radii(self) -> np.ndarray:
        """(P,) float64: radius of each solid's bounding sphere about :attr:`centres`."""
        out = np.zeros(self.panels.n)
        for k, (verts, _) in enumerate(self.meshes):
            if len(verts):
                out[k] = np.linalg.norm(verts - self.centres[k], axis=1).max()
        return out

    @cached_property
    def inset(self) -> np.ndarray:
        """(H,) float64: how far each hinge's far face is set back from the axis, metres
        (``t / tan(bevel)``)."""
        return self.thickness / np.tan(np.maximum(self.bevel, 1e-12))

    @cached_property
    def hinge_limits(self) -> tuple[np.ndarray, tuple[tuple[frozenset, frozenset], ...]]:
        """(fold_limit (H,), around (H,)): per hinge, the closing fold (radians) up to which
        its two solids meet only along its axis, and the pieces (indices into ``pieces``) of
        either solid that reach around the axis line.

        Seen around the axis line, a piece lies within the angles [0, a] from its panel's
        surface into the material, ``a`` its largest angle (the bevel, for a piece the bevel
        trims); two pieces on the two sides then meet only on the axis while the fold stays
        at most ``pi - a - b``. The limit is the least over the pairs of pieces of the two
        solids. A piece with a point on the far side of the surface or of the axis (a panel
        that wraps around a hinge's end) has no such angle: it is in ``around``, and its
        distance to every piece of the other solid is checked like that of two panels that
        are not neighbours (:mod:`rigidfold.fabricate.collision`)."""
        p = self.panels
        limits = np.full(p.n_hinges, math.pi)
        around = []
        of_panel: list[list[int]] = [[] for _ in range(p.n)]
        for i, piece in enumerate(self.pieces):
            of_panel[piece.panel].append(i)
        for h in range(p.n_hinges):
            spans, wraps = [], []
            for k in p.hinge_panels[h].tolist():
                origin, _, inward = _hinge_frame(p, h, k)
                best, wrap = 0.0, set()
                for i in of_panel[k]:
                    span = _span(
                        self.pieces[i].vertices, origin, inward, p.material[k], self.thickness
                    )
                    if span is None:
                        wrap.add(i)
                    else:
                        best = max(best, span)
                spans.append(best)
                wraps.append(frozenset(wrap))
            limits[h] = math.pi - spans[0] - spans[1]
            around.append((wraps[0], wraps[1]))
        return limits, tuple(around)

    @property
    def fold_limit(self) -> np.ndarray:
        """(H,) float64: the closing fold of each hinge up to which its solids meet only along
        its axis, radians (:attr:`hinge_limits`)."""
        return self.hinge_limits[0]

    @property
    def total_volume(self) -> float:
        return float(self.volumes.sum())

    @property
    def trimming_loss(self) -> float:
        """Share of the untrimmed volume (area x thickness) that the bevels and reliefs
        remove."""
        full = float(self.panels.areas.sum()) * self.thickness
        return 1.0 - self.total_volume / full if full > 0 else 0.0


def _span(
    verts: np.ndarray, origin: np.ndarray, inward: np.ndarray, material: np.ndarray, t: float
) -> float | None:
    """Largest angle around an axis (through ``origin``, square to ``inward`` and
    ``material``) between a panel's surface and the points ``verts`` (n, 3) of one convex
    piece of its solid, into the material; None when one lies outside [0, pi/2] (on the far
    side of the surface or of the axis). Points on the axis itself are skipped."""
    d = verts - origin
    s = d @ inward
    w = d @ material
    keep = np.hypot(s, w) > 1e-9 * max(t, 1e-12)
    phi = np.arctan2(w[keep], s[keep])
    tol = 1e-7
    if phi.size and (phi.min() < -tol or phi.max() > math.pi / 2 + tol):
        return None
    return float(max(phi.max(initial=0.0), 0.0))


def bevel_angles(fold_max: np.ndarray, clearance_angle: float) -> np.ndarray:
    """(H,) float64: the bevel ``(pi - max(rho_max, 0) - c) / 2`` of each hinge from its largest
    closing fold ``fold_max`` (H,) over the motion and the clearance angle ``c``, radians
    (see the module's text); <= 0 where the hinge folds too far for any bevel."""
    return (math.pi - np.maximum(np.asarray(fold_max, dtype=np.float64), 0.0) - clearance_angle) / 2


def _hinge_frame(panels: Panels, h: int, panel: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin, e, inward): a point of hinge h's axis (its first vertex), its unit direction
    and the unit direction in ``panel``'s surface, perpendicular to the axis, into the
    panel."""
    p = panels.pattern
    u, v = panels.hinge_vertices[h]
    origin = p.coords[u]
    e = p.coords[v] - origin
    e = e / np.linalg.norm(e)
    inward = np.cross(panels.normals[panel], e)
    inward -= (inward @ e) * e
    inward /= np.linalg.norm(inward)
    edge = panels.hinge_edges[h]
    faces = p.edge_faces[edge]
    face = faces[0] if panels.label[faces[0]] == panel else faces[1]
    if (p.coords[p.faces[face]].mean(axis=0) - origin) @ inward < 0:
        inward = -inward
    return origin, e, inward


@dataclass(frozen=True)
class _Bevel:
    """The material that one hinge's bevel removes from one panel: points at depth w below
    the surface within ``w / tan(alpha)`` of the axis line, along the axis from ``start``
    to ``stop`` (metres from the hinge's first vertex; unbounded past an end where the
    panel's corner is not reflex)."""

    hinge: int
    origin: np.ndarray
    e: np.ndarray
    inward: np.ndarray
    alpha: float
    start: float
    stop: float


def _bevels(panels: Panels, panel: int, bevel: np.ndarray) -> list[_Bevel]:
    p = panels.pattern
    corners = panels.corner_angles[panel]
    span = float(np.ptp(panels.coords2d[panels.vertices[panel]], axis=0).max()) * 4
    out = []
    for h in panels.hinges_of[panel].tolist():
        origin, e, inward = _hinge_frame(panels, h, panel)
        u, v = panels.hinge_vertices[h].tolist()
        length = float(np.linalg.norm(p.coords[v] - p.coords[u]))
        reflex = 1e-9
        start = 0.0 if corners.get(u, 0.0) > math.pi + reflex else -span
        stop = length if corners.get(v, 0.0) > math.pi + reflex else length + span
        out.append(_Bevel(h, origin, e, inward, float(bevel[h]), start, stop))
    return out


def _prism(panels: Panels, panel: int, thickness: float):
    """The panel's untrimmed prism (manifold3d), exact: its triangles on the surface, the
    same moved ``thickness`` to the material side, and a quad along each outline edge."""
    p = panels.pattern
    verts = panels.vertices[panel]
    index = {v: i for i, v in enumerate(verts.tolist())}
    n = len(verts)
    d = panels.material[panel]
    top = p.coords[verts]
    points = np.vstack([top, top + thickness * d])
    tris = np.vectorize(index.__getitem__)(p.faces[panels.triangles[panel]]).reshape(-1, 3)
    faces = [tris, tris[:, ::-1] + n]
    for loop in panels.loops[panel]:
        a = np.vectorize(index.__getitem__)(loop)
        b = np.roll(a, -1)
        faces += [np.column_stack([b, a, a + n]), np.column_stack([b, a + n, b + n])]
    return _closed_manifold(points, np.vstack(faces))


def _wedge(b: _Bevel, d: np.ndarray, thickness: float):
    """The bevel's removal region as a convex solid (a little past the surface and the far
    face, so that no face of it lies on one of the prism's)."""
    mf = held_import("manifold3d")

    eps = 1e-3 * thickness
    tan = math.tan(b.alpha)
    section = [
        (-eps / tan, -eps),
        (-10 * eps - eps / tan, -eps),
        (-10 * eps - eps / tan, thickness + eps),
        ((thickness + eps) / tan, thickness + eps),
    ]
    pts = [
        b.origin + along * b.e + s * b.inward + w * d
        for along in (b.start, b.stop)
        for s, w in section
    ]
    return mf.Manifold.hull_points(np.asarray(pts))


def _reliefs(panels: Panels, panel: int, relief: np.ndarray) -> dict[int, dict[int, float]]:
    """{vertex: {neighbour: reach}}: at each relief vertex of the panel, how far from it along
    each of the panel's edges there (outline and fixed creases) the relief reaches: the
    radius over cos(half the corner angle of a triangle on either side), so that every chord
    between two consecutive edges keeps at least the radius from the vertex."""
    p = panels.pattern
    out: dict[int, dict[int, float]] = {}
    for f in panels.triangles[panel].tolist():
        tri = p.faces[f].tolist()
        for j, w in enumerate(tri):
            if relief[w] <= 0:
                continue
            b, c = tri[(j + 1) % 3], tri[(j + 2) % 3]
            half = 0.5 * float(p.corner_angles[f, j])
            reach = float(relief[w]) / math.cos(half)
            edges = out.setdefault(w, {})
            for x in (b, c):
                edges[x] = max(edges.get(x, 0.0), reach)
    return out


def _chord(coords: np.ndarray, face: np.ndarray, j: int, reach: dict[int, float]):
    """(q1, q2): the ends of the relief's chord across corner j of the triangle ``face``."""
    w = coords[face[j]]
    ends = []
    for x in (face[(j + 1) % 3], face[(j + 2) % 3]):
        direction = coords[x] - w
        ends.append(w + reach[int(x)] * direction / np.linalg.norm(direction))
    return ends[0], ends[1]


def _relief_tool(panels: Panels, panel: int, w: int, reach: dict[int, float], thickness: float):
    """The relief at vertex w of the panel as one solid: the fan of the chords between the
    panel's consecutive edges at w (at ``reach`` along each), closed through a point just
    outside the corner, through the thickness and a little past both faces."""

    p = panels.pattern
    coords = p.coords
    d = panels.material[panel]
    nxt: dict[int, int] = {}
    for f in panels.triangles[panel].tolist():
        tri = p.faces[f].tolist()
        if w in tri:
            j = tri.index(w)
            nxt[tri[(j + 1) % 3]] = tri[(j + 2) % 3]
    first = next(iter(set(nxt) - set(nxt.values())), next(iter(nxt)))
    chain = [first]
    while chain[-1] in nxt and len(chain) <= len(nxt):
        chain.append(nxt[chain[-1]])
    x = coords[w]
    ends = [x + reach[v] * (coords[v] - x) / np.linalg.norm(coords[v] - x) for v in chain]
    inside = (ends[0] + ends[-1]) / 2 - x
    inside -= (inside @ d) * d
    size = min(reach.values())
    outside = x - 0.01 * size * inside / max(float(np.linalg.norm(inside)), 1e-300)
    ring = np.asarray([outside, *ends])
    eps = 1e-3 * thickness
    n = len(ring)
    points = np.vstack(
        [x - eps * d, ring - eps * d, x + (thickness + eps) * d, ring + (thickness + eps) * d]
    )
    top = [(0, 1 + i, 1 + (i + 1) % n) for i in range(n)]
    faces = [*top, *[(n + 1, b + n + 1, a + n + 1) for _, a, b in top]]
    for i in range(n):
        a, b = 1 + i, 1 + (i + 1) % n
        faces += [(a, b + n + 1, b), (a, a + n + 1, b + n + 1)]
    return _closed_manifold(points, np.asarray(faces))


def _chord_plane(w: np.ndarray, q1: np.ndarray, q2: np.ndarray, d: np.ndarray):
    """(normal, offset): a piece keeps ``normal . x >= offset``, the side of the chord
    q1 q2 (square to the surface) away from the corner w."""
    normal = np.cross(q2 - q1, d)
    normal /= np.linalg.norm(normal)
    if normal @ (w - q1) > 0:
        normal = -normal
    return normal, float(normal @ q1)


def thicken(
    panels: Panels,
    thickness: float,
    bevel: np.ndarray,
    relief: np.ndarray,
) -> Solids:
    """The :class:`Solids` of ``panels`` at ``thickness`` (metres), with the bevel (H,) of
    each hinge (radians, from :func:`bevel_angles`) and the relief radius (V,) at each
    vertex (metres). Hinges with a bevel <= 0 trim their panels away."""
    mf = held_import("manifold3d")

    p = panels.pattern
    coords = p.coords
    bevel = np.asarray(bevel, dtype=np.float64)
    relief = np.asarray(relief, dtype=np.float64)
    scale = float(np.median(p.edge_lengths))
    pieces: list[Piece] = []
    applied: list[np.ndarray] = [np.zeros(0, dtype=np.int64)] * p.n_faces
    meshes = []
    volumes = np.zeros(panels.n)
    depth = np.zeros(panels.n)
    empty: list[int] = []
    for k in range(panels.n):
        d = panels.material[k]
        bevels = _bevels(panels, k, bevel)
        reach = _reliefs(panels, k, relief)
        gone = any(b.alpha <= 0 for b in bevels)
        tools = [] if gone else [_wedge(b, d, thickness) for b in bevels]
        for f in panels.triangles[k].tolist():
            tri = coords[p.faces[f]]
            piece = mf.Manifold.hull_points(np.vstack([tri, tri + thickness * d]))
            used = []
            for b in bevels:
                s = (tri - b.origin) @ b.inward
                along = (tri - b.origin) @ b.e
                if s.min() < -_ON_LINE * scale or along.min() < b.start or along.max() > b.stop:
                    continue  # the bevel does not cover the triangle: its piece keeps more
                used.append(b.hinge)
                if gone:
                    break
                normal = math.sin(b.alpha) * b.inward - math.cos(b.alpha) * d
                piece = piece.trim_by_plane(normal, float(normal @ b.origin))
            for j, w in enumerate(p.faces[f].tolist()):
                if relief[w] > 0 and not gone:
                    q1, q2 = _chord(coords, p.faces[f], j, reach[w])
                    normal, offset = _chord_plane(tri[j], q1, q2, d)
                    piece = piece.trim_by_plane(normal, offset)
            applied[f] = np.asarray(used, dtype=np.int64)
            if gone or piece.is_empty() or piece.volume() <= 0:
                empty.append(f)
                continue
            mesh = piece.to_mesh64()
            verts = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
            tris = np.asarray(mesh.tri_verts, dtype=np.int64)
            pieces.append(Piece(k, f, verts, tris))
        if not gone:
            tools += [_relief_tool(panels, k, w, r, thickness) for w, r in reach.items()]
        solid = mf.Manifold() if gone else _prism(panels, k, thickness)
        if tools and not solid.is_empty():
            solid = mf.Manifold.batch_boolean([solid, *tools], mf.OpType.Subtract)
        mesh = solid.to_mesh64()
        verts = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3].copy()
        tris = np.asarray(mesh.tri_verts, dtype=np.int64).copy()
        meshes.append((verts, tris))
        volumes[k] = solid.volume()
        if len(verts):
            top = coords[panels.vertices[k]].mean(axis=0)
            depth[k] = float(((verts - top) @ d).max())
    return Solids(
        panels=panels,
        thickness=float(thickness),
        bevel=bevel,
        relief=relief,
        pieces=tuple(pieces),
        bevels_of_face=tuple(applied),
        meshes=tuple(meshes),
        volumes=volumes,
        depth=depth,
        empty_faces=np.asarray(sorted(empty), dtype=np.int64),
    )


def _closed_manifold(points: np.ndarray, tri: np.ndarray):
    """The manifold3d solid of a closed triangle mesh: points (N, 3), tri (T, 3) of one
    consistent winding, turned to face outwards (positive signed volume)."""
    mf = held_import("manifold3d")

    x0, x1, x2 = (points[tri[:, k]] for k in range(3))
    if np.einsum("ij,ij->i", x0, np.cross(x1, x2)).sum() < 0:
        tri = tri[:, ::-1]
    return mf.Manifold(
        mf.Mesh64(vert_properties=np.ascontiguousarray(points), tri_verts=tri.astype(np.uint64))
    )
