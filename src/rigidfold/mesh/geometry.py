"""Geometry of a triangulated polyhedron: angles, normals, fold angles, mirror images.

Pure NumPy array functions. Angles use ``atan2(|a x b|, a . b)``, which is accurate for
small and for nearly straight angles alike.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from rigidfold.errors import RigidfoldError
from rigidfold.protocols import SymmetryPlane


def angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unsigned angle between vectors.  a, b : (..., 3) -> (...,) radians in [0, pi]"""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i", a, b))


def angle_change(angle: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``angle - reference`` taken modulo 2 pi, in [-pi, pi): the change of a fold angle
    (arrays of one shape, radians), continuous where the angle passes +-180 degrees (a
    crease whose facets are folded onto each other)."""
    return np.remainder(angle - reference + np.pi, 2 * np.pi) - np.pi


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices: ``skew(v) @ w == cross(v, w)``.  (..., 3) -> (..., 3, 3)"""
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def corner_angles(coords: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Interior angle of each triangle at each of its corners.

    coords : (V, 3) float, faces : (F, 3) int  ->  (F, 3) float radians;
    entry ``[f, k]`` is the angle at vertex ``faces[f, k]``.
    """
    p = coords[faces]  # (F, 3, 3)
    to_next = np.roll(p, -1, axis=1) - p
    to_prev = np.roll(p, 1, axis=1) - p
    return angle_between(to_next, to_prev)


def angle_sums(coords: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Sum of the sector angles around each vertex.  -> (V,) radians"""
    return np.bincount(
        faces.ravel(), weights=corner_angles(coords, faces).ravel(), minlength=len(coords)
    )


def face_normals(coords: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit normals by the right-hand rule on the face order.  -> (F, 3) float"""
    p = coords[faces]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def face_areas(coords: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Triangle areas.  -> (F,) float"""
    p = coords[faces]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def plan_face_areas(coords: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed areas of the triangles projected on the xy plane, positive when CCW from +z.

    coords : (V, 2) or (V, 3) float; faces : (F, 3) int  ->  (F,) float
    """
    p = coords[faces, :2]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def projected_area(coords: np.ndarray, faces: np.ndarray) -> float:
    """Signed area of the faces projected on the xy plane (positive when CCW from +z)."""
    return float(np.sum(plan_face_areas(coords, faces)))


def plan_area(coords: np.ndarray, faces: np.ndarray, tol: float) -> tuple[float, float, bool]:
    """(signed projected area, surface area, whether the projection has zero area): the plan
    is zero when ``|projected| <= tol * surface`` (a vertical, closed or flat-folded sheet)."""
    plan = projected_area(coords, faces)
    surface = float(face_areas(coords, faces).sum())
    return plan, surface, abs(plan) <= tol * surface


def edge_lengths(coords: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Edge lengths.  edges : (E, 2) int  ->  (E,) float"""
    return np.linalg.norm(coords[edges[:, 1]] - coords[edges[:, 0]], axis=1)


def from_y_up(coords: np.ndarray) -> np.ndarray:
    """(V, 3) coordinates of a file drawn y up (Blender, Origami Simulator) turned z up:
    (x, y, z) -> (x, -z, y), a rotation about x; :func:`to_y_up` is its inverse."""
    return coords[:, [0, 2, 1]] * [1.0, -1.0, 1.0]


def to_y_up(coords: np.ndarray) -> np.ndarray:
    """(V, 3) z-up coordinates turned y up: (x, y, z) -> (x, z, -y), the inverse of
    :func:`from_y_up`."""
    return coords[:, [0, 2, 1]] * [1.0, 1.0, -1.0]


def best_fit(
    frames: np.ndarray, target: np.ndarray, points: np.ndarray | None = None
) -> np.ndarray:
    """(K, V, 3) ``frames`` each turned and moved (a proper rotation and a translation) so
    that their ``points`` best fit ``target[points]`` in the least-squares sense (Kabsch).

    frames : (K, V, 3) float64; target : (V, 3) float64; points : (n,) int vertex indices,
    n >= 3 not on one line (default: every vertex).
    """
    chosen = slice(None) if points is None else np.asarray(points)
    ref = target[chosen]
    centre = ref.mean(axis=0)
    mean = frames[:, chosen].mean(axis=1, keepdims=True)
    h = np.einsum("kvi,vj->kij", frames[:, chosen] - mean, ref - centre)
    u, _, vt = np.linalg.svd(h)
    sign = np.sign(np.linalg.det(np.einsum("kij,kjl->kil", u, vt)))
    u[:, :, 2] *= sign[:, None]
    rotation = np.einsum("kij,kjl->kil", u, vt)
    return np.einsum("kvi,kij->kvj", frames - mean, rotation) + centre


def rigid_motions(coords: np.ndarray, frames: np.ndarray, groups) -> tuple[np.ndarray, np.ndarray]:
    """(rotations (K, G, 3, 3), translations (K, G, 3)): the rigid motion of each group of
    vertices from ``coords`` onto each of ``frames``, by least squares over its vertices
    (Kabsch), so that group g at frame k holds ``rotations[k, g] @ x + translations[k, g]``
    for a point x of it at ``coords``.

    coords : (V, 3) float64; frames : (K, V, 3) float64; groups : G vertex index arrays,
    each of >= 3 vertices not on one line.
    """
    frames = np.asarray(frames, dtype=np.float64)
    n_frames, n_groups = len(frames), len(groups)
    rotations = np.empty((n_frames, n_groups, 3, 3))
    translations = np.empty((n_frames, n_groups, 3))
    for k, verts in enumerate(groups):
        src = coords[verts]
        dst = frames[:, verts]
        c_src = src.mean(axis=0)
        c_dst = dst.mean(axis=1)
        h = np.einsum("vi,kvj->kij", src - c_src, dst - c_dst[:, None])
        u, _, vt = np.linalg.svd(h)
        d = np.sign(np.linalg.det(np.einsum("kij,kjl->kil", u, vt)))
        u[:, :, 2] *= d[:, None]
        r = np.einsum("kij,kjl->kli", u, vt)  # R = (U V^T)^T maps src onto dst
        rotations[:, k] = r
        translations[:, k] = c_dst - np.einsum("kij,j->ki", r, c_src)
    return rotations, translations


def fold_angles(
    coords: np.ndarray, faces: np.ndarray, edges: np.ndarray, edge_faces: np.ndarray
) -> np.ndarray:
    """Signed fold angle of each edge, FOLD convention: valley positive, mountain negative.

    With ``n_a`` the normal of the face on the left of ``edges[e, 0] -> edges[e, 1]``, ``n_b``
    that of the face on the right and ``t`` the unit edge direction,
    ``rho = atan2(-(n_a x n_b) . t, n_a . n_b)``. A valley (a trough seen from +z, the side the
    CCW normals point to) gives rho > 0. Boundary edges get 0.

    coords : (V, 3), faces : (F, 3), edges : (E, 2), edge_faces : (E, 2) -> (E,) radians
    """
    rho = np.zeros(len(edges))
    interior = (edge_faces >= 0).all(axis=1)
    if not interior.any():
        return rho
    n = face_normals(coords, faces)
    na = n[edge_faces[interior, 0]]
    nb = n[edge_faces[interior, 1]]
    t = coords[edges[interior, 1]] - coords[edges[interior, 0]]
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    sin = -np.einsum("ij,ij->i", np.cross(na, nb), t)
    cos = np.einsum("ij,ij->i", na, nb)
    rho[interior] = np.arctan2(sin, cos)
    return rho


def plan_turning_angles(coords: np.ndarray, loop: np.ndarray) -> np.ndarray:
    """Turning angle of a closed polygon in plan (xy) at each of its vertices.

    coords : (V, 3), loop : (B,) int vertex indices in order  ->  (B,) radians, 0 where the
    polygon goes straight on.
    """
    p = coords[loop, :2]
    d_in = p - np.roll(p, 1, axis=0)
    d_out = np.roll(p, -1, axis=0) - p
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.einsum("ij,ij->i", d_in, d_out)
    return np.arctan2(cross, dot)


def mirror_pairs(coords: np.ndarray, plane: SymmetryPlane, tol: float) -> np.ndarray:
    """For each vertex, the index of the vertex at its mirror image in plan.

    coords : (V, 2) or (V, 3) float, only x and y are used; plane : a SymmetryPlane
    (``reflect(xy (N, 2)) -> (N, 2)``); tol : largest distance (metres) between a mirror image
    and its vertex.  returns : (V,) int64
    Raises ValueError when some vertex has no mirror image among the vertices.
    """
    xy = np.asarray(coords)[:, :2]
    dist, idx = cKDTree(xy).query(plane.reflect(xy))
    if (dist > tol).any():
        v = int(np.argmax(dist))
        raise RigidfoldError(
            f"the crease pattern is not symmetric about the plane {plane}: vertex {v} at "
            f"({xy[v, 0]:g}, {xy[v, 1]:g}) has no mirror image"
        )
    return idx.astype(np.int64)
