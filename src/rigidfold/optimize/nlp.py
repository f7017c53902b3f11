"""Problem (6) as a CasADi NLP: developability (F1) and flatness (F2) with exact derivatives.

::

    min_xi   F = F1 + F2
    F1 = sum_{i in V_in} (2 pi - sum_k theta_ik)^2
    F2 = sum_{j in E_fix} |n_j1 x n_j2|^2
    s.t.     |z_i - f(x_i, y_i)| <= dz                  (every vertex that can move)
             theta_min <= theta_ik <= theta_max          (every sector angle a shape can change)
             |rho_j| <= rho_max                          (free creases, optional, Eq. 12)
             P = T xi + t                                (Eqs. 7-11, eliminated)

The model is built once per pattern, surface, symmetry and settings as CasADi SX
expressions; the fixed-crease mask is a *parameter* ``w`` (E,), so fixing another crease
needs no rebuild. Angles are ``atan2(|a x b|, a . b)``. Constraint (12) is imposed in the
equivalent smooth form ``n_j1 . n_j2 >= cos(rho_max)``. The angles of a triangle whose
three corners (7)-(9) hold are constants of the problem: they keep no bounds, since no shape
could change them (a drawn boundary of many corners, each held on the surface, can give such
a triangle angles outside the bounds: with bounds the problem would be infeasible from the
start; :func:`held_faces`).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import scipy.sparse as sp

from rigidfold.config import Settings
from rigidfold.mesh import CreasePattern
from rigidfold.optimize.variables import LinearMap
from rigidfold.protocols import TargetSurface


@dataclass(frozen=True, eq=False)
class NLP:
    """Problem (6) in the independent variables xi, with the fixed-crease weights as parameter.

    x : ca.SX (n, 1)
        The independent variables xi (``P = T xi + t``, see ``LinearMap``).
    p : ca.SX (E, 1)
        The fixed-crease weights w: 1 on a fixed crease (its flatness enters F2 and (12) is
        lifted), 0 elsewhere.
    f : ca.SX (1, 1)
        The objective F = F1 + F2.
    f1, f2 : ca.SX (1, 1)
        Its developability and flatness parts.
    theta : ca.SX (3F, 1)
        The sector angles; entry k*F + f is the angle at ``faces[f, k]``.
    g : ca.SX (m, 1)
        The constraints, in this order: ``z - f(x, y)`` at ``dz_vertices`` (k,), the sector
        angles theta (3F,) and, when ``rho_max`` is set, ``(1 - w_j)(cos rho_max - n_j1 . n_j2)``
        per interior edge.
    lbg, ubg : (m,) float64
        Bounds of g (-inf where a constraint has no lower bound).
    dz_vertices : (k,) int64
        The vertices that can move (not fixed by (7)-(9)), whose height is bounded by dz.
    held : (h,) int64
        The triangles whose three corners (7)-(9) hold (:func:`held_faces`): their angles'
        rows of g are unbounded.
    """

    x: ca.SX
    p: ca.SX
    f: ca.SX
    f1: ca.SX
    f2: ca.SX
    theta: ca.SX
    g: ca.SX
    lbg: np.ndarray
    ubg: np.ndarray
    dz_vertices: np.ndarray
    held: np.ndarray

    @property
    def theta_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounds (3F,) each of the sector angles (entry k*F + f at ``faces[f, k]``)."""
        n = len(self.dz_vertices)
        rows = slice(n, n + self.theta.shape[0])
        return self.lbg[rows], self.ubg[rows]

    def casadi(self) -> dict[str, ca.SX]:
        """The ``{"x", "p", "f", "g"}`` problem dict of CasADi's ``nlpsol``."""
        return {"x": self.x, "p": self.p, "f": self.f, "g": self.g}


def to_casadi(matrix: sp.spmatrix) -> ca.DM:
    """A SciPy sparse matrix as a sparse CasADi DM."""
    csc = sp.csc_matrix(matrix)
    csc.sort_indices()
    sparsity = ca.Sparsity(csc.shape[0], csc.shape[1], csc.indptr.tolist(), csc.indices.tolist())
    return ca.DM(sparsity, csc.data)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def held_faces(pattern: CreasePattern, lmap: LinearMap) -> np.ndarray:
    """(h,) int64: the triangles whose three corners the linear map (7)-(9) holds, whose
    angles no shape of problem (6) can change."""
    held = np.zeros(pattern.n_vertices, dtype=bool)
    held[lmap.held_vertices] = True
    return np.flatnonzero(held[pattern.faces].all(axis=1))


def build_nlp(
    pattern: CreasePattern, surface: TargetSurface, lmap: LinearMap, settings: Settings
) -> NLP:
    """Problem (6) for a crease pattern, target surface, linear map (7)-(11) and settings.

    surface : TargetSurface (e.g. a rigidfold.surfaces.Surface)
        Its ``height`` must accept CasADi symbols (``xp=casadi``).
    """
    s = settings
    V, E = pattern.n_vertices, pattern.n_edges
    faces, ef = pattern.faces, pattern.edge_faces
    interior = pattern.interior_edges
    xi = ca.SX.sym("xi", lmap.n_variables)
    w = ca.SX.sym("w", E)
    P = ca.mtimes(to_casadi(lmap.T), xi) + ca.DM(lmap.t)
    x, y, z = P[:V], P[V : 2 * V], P[2 * V :]

    def at(idx: np.ndarray):
        i = idx.tolist()
        return (x[i], y[i], z[i])

    corners = [at(faces[:, k]) for k in range(3)]
    angles = []
    for k in range(3):
        u = _sub(corners[(k + 1) % 3], corners[k])
        v = _sub(corners[(k + 2) % 3], corners[k])
        c = _cross(u, v)
        angles.append(ca.atan2(ca.sqrt(_dot(c, c)), _dot(u, v)))
    theta = ca.vertcat(*angles)  # (3F,), entry k*F + f is the angle at faces[f, k]

    inner = pattern.interior_vertices
    row_of = np.full(V, -1)
    row_of[inner] = np.arange(len(inner))
    vert = faces.T.ravel()  # vertex of angle k*F + f
    keep = row_of[vert] >= 0
    A = sp.coo_matrix(
        (np.ones(keep.sum()), (row_of[vert[keep]], np.flatnonzero(keep))),
        shape=(len(inner), 3 * len(faces)),
    )
    defect = 2 * np.pi - ca.mtimes(to_casadi(A), theta)
    F1 = ca.sumsqr(defect)

    nrm = _cross(_sub(corners[1], corners[0]), _sub(corners[2], corners[0]))
    length = ca.sqrt(_dot(nrm, nrm))
    unit = tuple(c / length for c in nrm)
    ia, ib = ef[interior, 0].tolist(), ef[interior, 1].tolist()
    na = tuple(c[ia] for c in unit)
    nb = tuple(c[ib] for c in unit)
    cr = _cross(na, nb)
    flat = _dot(cr, cr)  # |n_a x n_b|^2 per interior edge
    w_int = w[interior.tolist()]
    F2 = ca.dot(w_int, flat)

    # dz constraint on every vertex that is not completely fixed by (7)-(9)
    dz_vertices = np.setdiff1d(np.arange(V), lmap.held_vertices)
    mv = dz_vertices.tolist()
    height = surface.height(x[mv], y[mv], xp=ca)
    g = [z[mv] - height, theta]
    held = held_faces(pattern, lmap)
    lo, hi = (
        np.full((3, len(faces)), s.design.theta_min),
        np.full((3, len(faces)), s.design.theta_max),
    )
    lo[:, held], hi[:, held] = -np.inf, np.inf  # constants of the problem
    lbg = [np.full(len(mv), -s.design.dz), lo.ravel()]
    ubg = [np.full(len(mv), s.design.dz), hi.ravel()]
    if s.design.rho_max is not None:
        g.append((1 - w_int) * (np.cos(s.design.rho_max) - _dot(na, nb)))
        lbg.append(np.full(len(interior), -np.inf))
        ubg.append(np.zeros(len(interior)))
    return NLP(
        x=xi,
        p=w,
        f=F1 + F2,
        f1=F1,
        f2=F2,
        theta=theta,
        g=ca.vertcat(*g),
        lbg=np.concatenate(lbg),
        ubg=np.concatenate(ubg),
        dz_vertices=dz_vertices,
        held=held,
    )
