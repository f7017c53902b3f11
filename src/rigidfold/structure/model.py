"""The deployed structure as a shell model: panels as plates, free creases as hinges.

Every triangle of the pattern is divided into ``n^2`` triangles (``n`` =
``Settings.structure.subdivisions``, a lattice of ``n + 1`` points per side), which become
``ShellDKGT`` elements (``ShellNLDKGT`` for the geometrically nonlinear analysis: DKT
bending, membrane with drilling DOF) of an ``ElasticMembranePlateSection`` of the material
and thickness. Nodes are shared where the plate is continuous: inside a triangle, along a
fixed crease (one panel), at a vertex between triangles that fixed creases join.

Along a free crease the two sides get their own nodes (one per side at each lattice point),
whose translations are tied (``equalDOF`` 1 2 3): the panels meet on the crease line and may
turn about it, a revolute hinge. Two sides tied at two or more points on the line make an
exact hinge. At a vertex, the groups of triangles around it that fixed creases join have one
node each, all tied to the first (the vertex is one point). A hinge may carry a rotational
spring about the crease axis (``zeroLength`` element, direction 4 about a local x along the
crease) of ``k`` N m/rad per metre of crease, lumped to the lattice nodes by their share of
the crease length (half a division at each end); ``k = 0`` is a free hinge.

A supported vertex keeps its nodes untied: a pin fixes the translations of every node at
it (so the pinned point carries the hinge of the panels meeting there), a clamp fixes their
rotations too. A boundary edge whose two ends are supported is supported along its length
(a line support: pinned, or clamped when both ends are clamped), so that the vertices of a
side pinned one by one support the whole side. Reactions are read at those nodes; an edge
node's goes to the edge's two ends by the lever rule.

Arrays of :class:`ShellMesh`::

    coords : (N, 3) float64        node coordinates, metres
    triangles : (T, 3) int64       node indices of the shell elements (counter-clockwise)
    triangle_face : (T,) int64     the pattern's triangle each element lies in
    node_vertex : (N,) int64       the pattern's vertex a node sits at, or -1
    node_edge : (N,) int64         the edge a node sits inside (not at its ends), or -1;
    node_step : (N,) int64         its lattice step from ``edges[e, 0]`` (1..n-1)
    crease_pairs : (P, 2) int64    (left, right) node pairs inside free creases (tied)
    pair_crease : (P,) int64       the free crease (edge index) of each pair
    springs : (S, 2) int64         (left, right) node pairs of the hinge springs
    spring_crease : (S,) int64     edge index; spring_axis (S, 3) unit crease direction;
    spring_length : (S,) float64   the share of the crease length each spring stands for, m
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.material import Material
from rigidfold.mesh import CreasePattern


@dataclass(frozen=True, eq=False)
class ShellMesh:
    """The shell model's nodes, elements and hinges of a pattern (see the module's text).

    pattern : the pattern modelled (actuated creases already fixed); subdivisions : n.
    """

    pattern: CreasePattern
    subdivisions: int
    coords: np.ndarray
    triangles: np.ndarray
    triangle_face: np.ndarray
    node_vertex: np.ndarray
    node_edge: np.ndarray
    node_step: np.ndarray
    crease_pairs: np.ndarray
    pair_crease: np.ndarray
    springs: np.ndarray
    spring_crease: np.ndarray
    spring_axis: np.ndarray
    spring_length: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.coords)

    @property
    def n_elements(self) -> int:
        return len(self.triangles)

    @cached_property
    def triangle_areas(self) -> np.ndarray:
        """(T,) element areas, m^2."""
        return 0.5 * np.linalg.norm(self._cross, axis=1)

    @cached_property
    def triangle_normals(self) -> np.ndarray:
        """(T, 3) unit normals of the elements (up for a counter-clockwise pattern)."""
        c = self._cross
        return c / np.linalg.norm(c, axis=1, keepdims=True)

    @cached_property
    def _cross(self) -> np.ndarray:
        p = self.coords[self.triangles]
        return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])

    def vertex_nodes(self, vertex: int) -> np.ndarray:
        """(k,) the nodes at ``vertex`` (one per group of triangles joined by fixed creases)."""
        return np.flatnonzero(self.node_vertex == vertex)

    def supported_nodes(
        self, pinned: np.ndarray, clamped: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The nodes the supports hold: (nodes (k,), clamped (k,) bool, shares (k, P + C)),
        ``shares[i, j]``: the part of node i's reaction that goes to support j (the pinned
        vertices, then the clamped ones)."""
        supports = np.concatenate([pinned, clamped]).astype(np.int64)
        is_clamp = np.arange(len(supports)) >= len(pinned)
        column = {int(v): j for j, v in enumerate(supports)}
        nodes, clamp, rows = [], [], []
        for j, v in enumerate(supports):
            for i in self.vertex_nodes(int(v)):
                share = np.zeros(len(supports))
                share[j] = 1.0
                nodes.append(int(i))
                clamp.append(bool(is_clamp[j]))
                rows.append(share)
        pat, n = self.pattern, self.subdivisions
        for e in pat.boundary_edges:
            a, b = (int(v) for v in pat.edges[e])
            if a not in column or b not in column:
                continue
            ja, jb = column[a], column[b]
            for i in np.flatnonzero(self.node_edge == e):
                share = np.zeros(len(supports))
                s = self.node_step[i] / n
                share[ja] += 1.0 - s
                share[jb] += s
                nodes.append(int(i))
                clamp.append(bool(is_clamp[ja] and is_clamp[jb]))
                rows.append(share)
        return (
            np.asarray(nodes, dtype=np.int64),
            np.asarray(clamp, dtype=bool),
            np.asarray(rows, dtype=np.float64).reshape(len(nodes), len(supports)),
        )

    def ties(self, supported: np.ndarray) -> np.ndarray:
        """(K, 2) (retained, constrained) node pairs whose translations are equal: every free
        crease's inner pairs, and at each vertex not in ``supported`` its nodes to the first."""
        supported_mask = np.zeros(self.pattern.n_vertices, dtype=bool)
        supported_mask[np.asarray(supported, dtype=np.int64)] = True
        at_vertex = np.flatnonzero(self.node_vertex >= 0)
        v = self.node_vertex[at_vertex]
        order = np.lexsort((at_vertex, v))
        nodes, v = at_vertex[order], v[order]
        first = np.ones(len(v), dtype=bool)
        first[1:] = v[1:] != v[:-1]
        retained = nodes[np.maximum.accumulate(np.where(first, np.arange(len(v)), 0))]
        keep = ~first & ~supported_mask[v]
        vertex_ties = np.column_stack([retained[keep], nodes[keep]])
        return np.vstack([self.crease_pairs, vertex_ties]).astype(np.int64)


def shell_mesh(pattern: CreasePattern, subdivisions: int) -> ShellMesh:
    """The shell mesh of ``pattern`` with every triangle divided into ``subdivisions^2``."""
    n = int(subdivisions)
    if n < 1:
        raise RigidfoldError(f"subdivisions must be an integer >= 1, got {subdivisions!r}")
    pat = pattern
    free = np.zeros(pat.n_edges, dtype=bool)
    free[pat.free_creases] = True
    root = _vertex_groups(pat)
    keys: dict[tuple, int] = {}
    coords: list[np.ndarray] = []
    node_vertex: list[int] = []
    node_edge: list[int] = []
    node_step: list[int] = []

    def node(key: tuple, point: np.ndarray, vertex: int = -1, edge: int = -1, step: int = 0):
        index = keys.get(key)
        if index is None:
            index = keys[key] = len(coords)
            coords.append(point)
            node_vertex.append(vertex)
            node_edge.append(edge)
            node_step.append(step)
        return index

    x = pat.coords
    lattice = [(j, k) for k in range(n + 1) for j in range(n + 1 - k)]
    where = {jk: i for i, jk in enumerate(lattice)}
    up = [(where[j, k], where[j + 1, k], where[j, k + 1]) for j, k in lattice if j + k <= n - 1]
    down = [
        (where[j + 1, k], where[j + 1, k + 1], where[j, k + 1])
        for j, k in lattice
        if j + k <= n - 2
    ]
    local = np.array(up + down, dtype=np.int64)
    triangles = np.empty((pat.n_faces, len(local), 3), dtype=np.int64)
    for f in range(pat.n_faces):
        corners = pat.faces[f]
        ids = np.empty(len(lattice), dtype=np.int64)
        for i, (j, k) in enumerate(lattice):
            w = (n - j - k, j, k)
            point = (w[0] * x[corners[0]] + w[1] * x[corners[1]] + w[2] * x[corners[2]]) / n
            zero = [c for c in range(3) if w[c] == 0]
            if len(zero) == 2:  # a corner of the triangle: a vertex
                c = next(c for c in range(3) if w[c] == n)
                v = int(corners[c])
                ids[i] = node(("v", v, root[v, f]), point, v)
            elif len(zero) == 1:  # on the side opposite the corner of weight 0
                side = (zero[0] + 1) % 3  # face_edges[f, side] runs corners side -> side + 1
                p, q = side, (side + 1) % 3
                e = int(pat.face_edges[f, side])
                s = w[q] if pat.edges[e, 0] == corners[p] else w[p]
                key = ("e", e, s, f) if free[e] else ("e", e, s)
                ids[i] = node(key, point, edge=e, step=int(s))
            else:
                ids[i] = node(("f", f, j, k), point)
        triangles[f] = ids[local]
    pairs, pair_crease, springs, spring_crease, spring_length = [], [], [], [], []
    for e in pat.free_creases:
        fl, fr = (int(f) for f in pat.edge_faces[e])
        u, w_ = (int(v) for v in pat.edges[e])
        length = float(np.linalg.norm(x[w_] - x[u]))
        for s in range(n + 1):
            if s in (0, n):
                v = u if s == 0 else w_
                left, right = keys[("v", v, root[v, fl])], keys[("v", v, root[v, fr])]
                share = length / (2 * n)
            else:
                left, right = keys[("e", int(e), s, fl)], keys[("e", int(e), s, fr)]
                pairs.append((left, right))
                pair_crease.append(int(e))
                share = length / n
            if left != right:
                springs.append((left, right))
                spring_crease.append(int(e))
                spring_length.append(share)
    spring_crease_arr = np.asarray(spring_crease, dtype=np.int64)
    ends = pat.edges[spring_crease_arr]
    axis = x[ends[:, 1]] - x[ends[:, 0]] if len(ends) else np.zeros((0, 3))
    if len(axis):
        axis = axis / np.linalg.norm(axis, axis=1, keepdims=True)
    return ShellMesh(
        pattern=pat,
        subdivisions=n,
        coords=np.asarray(coords, dtype=np.float64),
        triangles=triangles.reshape(-1, 3),
        triangle_face=np.repeat(np.arange(pat.n_faces), len(local)),
        node_vertex=np.asarray(node_vertex, dtype=np.int64),
        node_edge=np.asarray(node_edge, dtype=np.int64),
        node_step=np.asarray(node_step, dtype=np.int64),
        crease_pairs=np.asarray(pairs, dtype=np.int64).reshape(-1, 2),
        pair_crease=np.asarray(pair_crease, dtype=np.int64),
        springs=np.asarray(springs, dtype=np.int64).reshape(-1, 2),
        spring_crease=spring_crease_arr,
        spring_axis=np.asarray(axis, dtype=np.float64).reshape(-1, 3),
        spring_length=np.asarray(spring_length, dtype=np.float64),
    )


def _vertex_groups(pat: CreasePattern) -> dict[tuple[int, int], int]:
    """(vertex, triangle at it) -> a label shared by the triangles around the vertex that
    fixed creases at it join (union-find over the fixed creases' ends)."""
    parent: dict[tuple[int, int], tuple[int, int]] = {}
    for f, corners in enumerate(pat.faces):
        for v in corners:
            parent[int(v), f] = (int(v), f)

    def find(a: tuple[int, int]) -> tuple[int, int]:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for e in pat.fixed_creases:
        fl, fr = (int(f) for f in pat.edge_faces[e])
        for v in pat.edges[e]:
            a, b = find((int(v), fl)), find((int(v), fr))
            if a != b:
                parent[max(a, b)] = min(a, b)
    return {key: find(key)[1] for key in parent}


def build_shells(
    ops: Any,
    mesh: ShellMesh,
    material: Material,
    thickness: float,
    density: float,
    *,
    nonlinear: bool = False,
) -> None:
    """Start the OpenSees model of ``mesh`` in ``ops`` (openseespy.opensees, wiped first):
    node tag i + 1 is node i, and element tag t + 1 the shell (ASDShellT3) of triangle t,
    of one elastic membrane-plate section of ``material``, ``thickness`` (m) and ``density``
    (kg/m^3); corotational where ``nonlinear``."""
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, c in enumerate(mesh.coords):
        ops.node(i + 1, *map(float, c))
    ops.section(
        "ElasticMembranePlateSection",
        1,
        float(material.E),
        float(material.nu),
        float(thickness),
        float(density),
    )
    extra = ["-corotational"] if nonlinear else []
    for t, (a, b, c) in enumerate(mesh.triangles):
        ops.element("ASDShellT3", t + 1, int(a) + 1, int(b) + 1, int(c) + 1, 1, *extra)


def build_spring(
    ops: Any, tag: int, material_tag: int, a: int, b: int, axis: np.ndarray, stiffness: float
) -> None:
    """A rotational spring of ``stiffness`` (N m/rad) about ``axis`` (3,) between nodes a
    and b, in ``ops``: uniaxial material ``material_tag`` and zeroLength element ``tag``,
    its local x along the axis."""
    ops.uniaxialMaterial("Elastic", material_tag, float(stiffness))
    ref = np.eye(3)[int(np.argmin(np.abs(axis)))]
    ops.element(
        "zeroLength",
        tag,
        int(a) + 1,
        int(b) + 1,
        "-mat",
        material_tag,
        "-dir",
        4,
        "-orient",
        *map(float, axis),
        *map(float, np.cross(ref, axis)),
    )


def build_model(
    ops: Any,
    mesh: ShellMesh,
    material: Material,
    thickness: float,
    *,
    hinge_stiffness: float,
    pinned: np.ndarray,
    clamped: np.ndarray,
    nonlinear: bool = False,
) -> np.ndarray:
    """Build the OpenSees model of ``mesh`` in ``ops`` (openseespy.opensees, wiped first).

    Node tag i + 1 is node i, element tag t + 1 element t, the springs follow. Returns the
    (K, 2) ties (:meth:`ShellMesh.ties`): the constrained node of each follows the retained
    one's translations.
    """
    build_shells(ops, mesh, material, thickness, material.density, nonlinear=nonlinear)
    if hinge_stiffness > 0:
        tag = mesh.n_elements
        for s, ((a, b), axis) in enumerate(zip(mesh.springs, mesh.spring_axis, strict=True)):
            tag += 1
            build_spring(ops, tag, s + 1, a, b, axis, hinge_stiffness * mesh.spring_length[s])
    nodes, clamp, _ = mesh.supported_nodes(pinned, clamped)
    for i, c in zip(nodes, clamp, strict=True):
        rot = 1 if c else 0
        ops.fix(int(i) + 1, 1, 1, 1, rot, rot, rot)
    supported = np.concatenate([np.asarray(pinned), np.asarray(clamped)]).astype(np.int64)
    ties = mesh.ties(supported)
    for r, c in ties:
        ops.equalDOF(int(r) + 1, int(c) + 1, 1, 2, 3)
    return ties
