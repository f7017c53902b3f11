"""Topology of a triangulated disc: edges, edge-to-face incidence, boundary, validation.

Pure array functions. A *half-edge* of face ``f`` is the directed pair
``(faces[f, k], faces[f, (k + 1) % 3])``; faces are ordered counter-clockwise seen from +z.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from rigidfold.errors import RigidfoldError


def half_edges(faces: np.ndarray) -> np.ndarray:
    """Directed edges of all faces.

    faces : (F, 3) int
    returns : (3F, 2) int, row ``3 f + k`` is ``(faces[f, k], faces[f, k+1])``.
    """
    return np.stack([faces, np.roll(faces, -1, axis=1)], axis=-1).reshape(-1, 2)


def edges_from_faces(faces: np.ndarray) -> np.ndarray:
    """Undirected edges of a triangle mesh, each as ``(u, v)`` with ``u < v``, sorted.

    faces : (F, 3) int  ->  (E, 2) int64
    """
    he = np.sort(half_edges(faces), axis=1)
    return np.unique(he, axis=0).astype(np.int64)


def edge_keys(edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """Unique integer key of each undirected edge: ``min * V + max``.  (E, 2) -> (E,)"""
    lo = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64)
    hi = np.maximum(edges[:, 0], edges[:, 1]).astype(np.int64)
    return lo * n_vertices + hi


def half_edge_edges(faces: np.ndarray, edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """Edge index of every half-edge: entry ``3 f + k`` is the edge of ``faces[f, k..k+1]``.

    faces : (F, 3) int, edges : (E, 2) int  ->  (3F,) int64
    Raises ValueError when a face edge is missing from ``edges``.
    """
    he = half_edges(faces)
    keys = edge_keys(edges, n_vertices)
    order = np.argsort(keys)
    he_keys = edge_keys(he, n_vertices)
    pos = np.minimum(np.searchsorted(keys[order], he_keys), len(keys) - 1)
    found = keys[order][pos] == he_keys
    if not found.all():
        u, v = he[np.flatnonzero(~found)[0]].tolist()
        raise RigidfoldError(f"edge ({u}, {v}) of a face is missing from the edge list")
    return order[pos].astype(np.int64)


def edge_faces(faces: np.ndarray, edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """Faces on either side of each edge.

    Column 0 is the face that traverses the edge as ``edges[e, 0] -> edges[e, 1]`` (the face on
    its left), column 1 the face that traverses it backwards; -1 where there is none.

    faces : (F, 3) int, edges : (E, 2) int  ->  (E, 2) int64
    Raises ValueError when a face edge is missing from ``edges`` or a half-edge repeats.
    """
    he = half_edges(faces)
    edge_of_he = half_edge_edges(faces, edges, n_vertices)
    forward = he[:, 0] == edges[edge_of_he, 0]
    face_of_he = np.repeat(np.arange(len(faces)), 3)
    out = np.full((len(edges), 2), -1, dtype=np.int64)
    slot = edge_of_he * 2 + np.where(forward, 0, 1)
    counts = np.bincount(slot, minlength=2 * len(edges))
    if counts.max(initial=0) > 1:
        e = int(np.argmax(counts) // 2)
        u, v = edges[e].tolist()
        raise RigidfoldError(
            f"edge ({u}, {v}) is shared by more than two faces or by two faces with "
            "inconsistent orientation (not an oriented edge-manifold)"
        )
    out.reshape(-1)[slot] = face_of_he
    return out


def crease_stencils(
    faces: np.ndarray, edges: np.ndarray, edge_faces_: np.ndarray, creases: np.ndarray
) -> np.ndarray:
    """The four vertices that a crease's fold angle depends on.

    Row j is ``(u, v, a, b)``: the ends ``edges[c] = (u, v)`` of crease ``c = creases[j]``,
    ``a`` the third vertex of the face left of u -> v (``edge_faces_[c, 0]``) and ``b`` that of
    the face right of it.

    faces : (F, 3) int, edges : (E, 2) int, edge_faces_ : (E, 2) int, creases : (n,) int
    indices of interior edges  ->  (n, 4) int64
    """
    e = edges[creases]
    ef = edge_faces_[creases]
    a = faces[ef[:, 0]].sum(axis=1) - e.sum(axis=1)
    b = faces[ef[:, 1]].sum(axis=1) - e.sum(axis=1)
    return np.column_stack([e[:, 0], e[:, 1], a, b]).astype(np.int64, copy=False)


def boundary_loop(edges: np.ndarray, boundary: np.ndarray, n_vertices: int) -> np.ndarray:
    """Ordered vertices of the single boundary loop of a disc.

    The loop follows the boundary half-edges, so it runs counter-clockwise when the faces do.

    edges : (E, 2) int, boundary : (B, 2) int directed boundary half-edges (u -> v with the face
    on the left).  returns : (B,) int
    Raises ValueError when the boundary is not one simple closed loop.
    """
    nxt = np.full(n_vertices, -1, dtype=np.int64)
    if np.bincount(boundary[:, 0], minlength=n_vertices).max(initial=0) > 1:
        v = int(np.argmax(np.bincount(boundary[:, 0], minlength=n_vertices)))
        raise RigidfoldError(f"boundary vertex {v} is a pinch point (the surface is not a disc)")
    nxt[boundary[:, 0]] = boundary[:, 1]
    start = int(boundary[0, 0])
    loop = [start]
    v = int(nxt[start])
    while v != start:
        if v < 0 or len(loop) > len(boundary):
            raise RigidfoldError("the boundary is not a single closed loop")
        loop.append(v)
        v = int(nxt[v])
    if len(loop) != len(boundary):
        raise RigidfoldError(
            f"the boundary has several loops ({len(boundary)} boundary edges, the loop through "
            f"vertex {start} has {len(loop)}): the crease pattern must be a disc without holes"
        )
    return np.asarray(loop, dtype=np.int64)


def face_components(n_faces: int, edge_faces_: np.ndarray, join: np.ndarray) -> np.ndarray:
    """Label faces connected through the edges selected by ``join``.

    n_faces : int, edge_faces_ : (E, 2) int, join : (E,) bool  ->  (F,) int labels 0..k-1
    """
    sel = join & (edge_faces_[:, 0] >= 0) & (edge_faces_[:, 1] >= 0)
    a, b = edge_faces_[sel, 0], edge_faces_[sel, 1]
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(n_faces, n_faces))
    _, labels = connected_components(graph, directed=False)
    return labels.astype(np.int64)


def validate_topology(faces: np.ndarray, edges: np.ndarray, n_vertices: int) -> None:
    """Check that the faces form an oriented triangulated disc whose edges are ``edges``.

    Raises ValueError naming the first problem found.
    """
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise RigidfoldError(f"faces must be an (F, 3) array of triangles, got shape {faces.shape}")
    if len(faces) == 0:
        raise RigidfoldError("the crease pattern has no faces")
    if faces.min() < 0 or faces.max() >= n_vertices:
        raise RigidfoldError(
            f"face vertex index out of range 0..{n_vertices - 1}: "
            f"got {int(faces.min())}..{int(faces.max())}"
        )
    repeated = (
        (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    )
    if repeated.any():
        raise RigidfoldError(
            f"face {int(np.argmax(repeated))} repeats a vertex: {faces[repeated][0].tolist()}"
        )
    if edges.ndim != 2 or edges.shape[1] != 2 or len(edges) == 0:
        raise RigidfoldError(f"edges must be a non-empty (E, 2) array, got shape {edges.shape}")
    if edges.min() < 0 or edges.max() >= n_vertices:
        raise RigidfoldError(f"edge vertex index out of range 0..{n_vertices - 1}")
    if (edges[:, 0] == edges[:, 1]).any():
        raise RigidfoldError(f"edge {int(np.argmax(edges[:, 0] == edges[:, 1]))} is a loop")
    keys = edge_keys(edges, n_vertices)
    uniq, first, counts = np.unique(keys, return_index=True, return_counts=True)
    if len(uniq) != len(keys):
        e = int(first[np.argmax(counts > 1)])
        raise RigidfoldError(f"the edge list contains edge {tuple(edges[e].tolist())} twice")
    face_keys = np.unique(edge_keys(half_edges(faces), n_vertices))
    if len(face_keys) != len(keys):
        extra = np.setdiff1d(keys, face_keys)
        if len(extra):
            e = int(np.flatnonzero(np.isin(keys, extra))[0])
            raise RigidfoldError(f"edge {e} {tuple(edges[e].tolist())} belongs to no face")
    ef = edge_faces(faces, edges, n_vertices)  # raises on non-manifold / inconsistent orientation
    used = np.zeros(n_vertices, dtype=bool)
    used[faces.ravel()] = True
    if not used.all():
        raise RigidfoldError(f"vertex {int(np.argmin(used))} belongs to no face")
    labels = face_components(len(faces), ef, np.ones(len(edges), dtype=bool))
    if labels.max() > 0:
        raise RigidfoldError(f"the crease pattern has {labels.max() + 1} disconnected parts")
    euler = n_vertices - len(edges) + len(faces)
    is_boundary = (ef < 0).any(axis=1)
    if not is_boundary.any():
        raise RigidfoldError("the crease pattern is a closed surface; it must be a disc")
    boundary_he = boundary_half_edges(edges, ef)
    boundary_loop(edges, boundary_he, n_vertices)
    if euler != 1:
        raise RigidfoldError(f"the crease pattern is not a disc (V - E + F = {euler}, expected 1)")


def boundary_half_edges(edges: np.ndarray, edge_faces_: np.ndarray) -> np.ndarray:
    """Boundary edges directed with their face on the left.  -> (B, 2) int"""
    fwd = (edge_faces_[:, 0] >= 0) & (edge_faces_[:, 1] < 0)
    bwd = (edge_faces_[:, 1] >= 0) & (edge_faces_[:, 0] < 0)
    return np.concatenate([edges[fwd], edges[bwd][:, ::-1]]).astype(np.int64)
