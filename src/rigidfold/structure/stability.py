"""Second order where first order is not enough: are the motions that the supports leave
free at first order held by a self-stress of the constraints (prestress stability), or do
they extend to a real, finite mechanism?

:mod:`rigidfold.structure.supports` decides first-order rigidity. When it fails, the
supports and the constraints of the design (edge lengths, the angles of fixed and actuated
creases, the pinned and clamped vertices) leave k first-order motions Z (3V x k): the
**flexes**. A flat or nearly flat vertex held around its boundary has one: the vertex may
leave the plane at first order, yet no edge can keep its length as it does, so the vertex
does not move. This module tells such cases from real mechanisms, after Connelly and
Whiteley (Second-order rigidity and prestress stability for tensegrity frameworks, SIAM J.
Discrete Math. 9(3), 1996):

* Write the constraints as g_i(x) = 0, each scaled to a gradient of unit norm at the design
  (edge lengths |x_v - x_u| - L; fold angles (rho - rho_0) / |grad rho|; a pinned vertex's
  coordinates; a clamped vertex pins every vertex of the triangles at it, which holds their
  rotations exactly). A = dg/dx (n_c x 3V) is the first-order constraint matrix.
* A **self-stress** is w with A^T w = 0 (the left singular vectors of A whose singular
  value squared is at most ``Settings.structure.rigidity_tol``, the same threshold as the
  first-order test; forces in the edges and creases in equilibrium with the supports'
  reactions). Its **stress matrix** Omega(w) = sum_i w_i Hess g_i is the geometric
  stiffness that the self-stress gives the flexes: their energy at second order is
  z^T Omega(w) z.
* The supports are **prestress stable** when some self-stress makes Z^T Omega(w) Z positive
  definite and the weakest flex (the first, of the smallest first-order stiffness) does not
  extend to a finite motion (see below: near-mechanisms of nearly flat vertices give near
  self-stresses, whose stress matrices need not vanish on a real motion). The stress
  matrices on the flexes span a space of symmetric k x k matrices (at most k (k + 1) / 2
  of them; those below ``structure_prestress_tol`` times the largest second derivative of
  one constraint on the flexes are dropped); the best w maximises lambda_min(Z^T Omega(w) Z) over a
  box, a concave maximisation solved by cutting planes on linear programs (scipy's HiGHS):
  each program's optimum bounds the answer from above, each trial w gives a value from
  below, so the search ends with either a positive definite stress matrix (prestress
  stable: accepted) or a proof that none exists (above by at most
  ``structure_prestress_tol`` of the stress matrices' size).
* A set that is not prestress stable is refused. A flex that extends to a finite motion
  (Gauss-Newton from the design moved ``structure_flex_step`` mean edge lengths along a
  flex, corrected at right angles to it, meets every constraint to
  ``structure_flex_tol`` within a correction smaller than the step) is reported as a
  **mechanism** (the flexes tried: the one of the smallest energy under the best
  self-stress, two of zero energy where that energy takes both signs, and the flexes'
  basis); otherwise as a first-order motion that no self-stress holds (it may be
  rigid at a higher order; it is refused all the same). With one self-stress, prestress
  stability and second-order rigidity are the same; with several, prestress stability is
  the stronger (sufficient) condition.

A prestress-stable design carries a load across its flexes only through the forces of that
self-stress and large deflection: its linear analysis may not converge, which the check
reports.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import casadi as ca
import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mechanism.kinematics import fold_angles_and_gradients
from rigidfold.mesh import CreasePattern
from rigidfold.status import Outcome


class Stability(Outcome):
    """How the supports hold the design."""

    FIRST_ORDER = "first_order", "the supports make the design first-order rigid"
    PRESTRESS = (
        "prestress_stable",
        "prestress stable: the supports leave first-order motions only, held at second order "
        "by a self-stress of the constraints",
    )
    MECHANISM = "mechanism", "the supports leave a finite mechanism"
    NOT_PRESTRESS_STABLE = (
        "not_prestress_stable",
        "the supports leave a first-order motion that no self-stress holds",
    )


@dataclass(frozen=True, eq=False)
class SecondOrder:
    """The second-order check of the flexes that the supports leave.

    stability : PRESTRESS, MECHANISM or NOT_PRESTRESS_STABLE; flexes : k, first-order motions;
    stresses : self-stresses of the constraints; stress_forms : independent stress matrices
    on the flexes; margin : lambda_min(Z^T Omega(w) Z) of the best self-stress found, over
    the largest norm of the stress matrices on the flexes (> 0: prestress stable); bound :
    the cutting planes' upper bound of that margin; witness : (3V,) the motion that decided:
    the flex of the smallest energy under the best self-stress (unit largest vertex
    displacement), or, for a mechanism, the finite displacement found (every constraint met).
    """

    stability: Stability
    flexes: int
    stresses: int
    stress_forms: int
    margin: float
    bound: float
    witness: np.ndarray

    @property
    def stable(self) -> bool:
        return self.stability is Stability.PRESTRESS

    def to_dict(self) -> dict:
        return {
            "stability": self.stability.value,
            "flexes": self.flexes,
            "self_stresses": self.stresses,
            "stress_forms": self.stress_forms,
            "margin": self.margin,
            "bound": self.bound,
        }


@lru_cache(maxsize=1)
def _fold_angle_hessian() -> ca.Function:
    """Hessian (12, 12) of the fold angle rho(p_u, p_v, p_a, p_b) (the convention of
    :func:`rigidfold.mechanism.kinematics.fold_angles_and_gradients`)."""
    q = ca.SX.sym("q", 12)
    pu, pv, pa, pb = q[0:3], q[3:6], q[6:9], q[9:12]
    na = ca.cross(pv - pu, pa - pu)
    nb = ca.cross(pu - pv, pb - pv)
    t = (pv - pu) / ca.norm_2(pv - pu)
    rho = ca.atan2(-ca.dot(ca.cross(na, nb), t), ca.dot(na, nb))
    return ca.Function("rho_hess", [q], [ca.hessian(rho, q)[0]])


class Constraints:
    """The constraints g(x) = 0 of a design on its supports, scaled to unit gradients at
    the design (see the module's text).

    pattern : the design with its actuated creases fixed; held : (p,) int64 vertices whose
    position is held (the pinned ones, and every vertex of the triangles at a clamped one).
    """

    def __init__(self, pattern: CreasePattern, held: np.ndarray) -> None:
        self.pattern = pattern
        self.held = np.asarray(held, dtype=np.int64)
        self.x0 = pattern.coords.copy()
        self.lengths = pattern.edge_lengths.copy()
        self.creases = pattern.fixed_creases
        self.stencils = pattern.crease_stencils(self.creases)
        rho, grad, _ = fold_angles_and_gradients(self.x0, self.stencils)
        self.rho0 = rho
        self.scale = np.maximum(np.linalg.norm(grad, axis=1), 1e-300)

    @property
    def n_rows(self) -> int:
        return self.pattern.n_edges + len(self.creases) + 3 * len(self.held)

    def values(self, x: np.ndarray) -> np.ndarray:
        """(n_c,) g at vertex coordinates x (V, 3)."""
        e = self.pattern.edges
        length = np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1) - self.lengths
        rho, _, _ = fold_angles_and_gradients(x, self.stencils)
        angle = (rho - self.rho0) / self.scale
        pins = (x[self.held] - self.x0[self.held]).ravel()
        return np.concatenate([length, angle, pins])

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """(n_c, 3V) dense dg/dx at x (V, 3)."""
        pat = self.pattern
        E, V = pat.n_edges, pat.n_vertices
        A = np.zeros((self.n_rows, 3 * V))
        e = pat.edges
        d = x[e[:, 1]] - x[e[:, 0]]
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        rows = np.arange(E)[:, None]
        A[rows, 3 * e[:, :1] + np.arange(3)] = -d
        A[rows, 3 * e[:, 1:] + np.arange(3)] = d
        if len(self.creases):
            _, grad, cols = fold_angles_and_gradients(x, self.stencils)
            r = E + np.arange(len(self.creases))[:, None]
            np.add.at(A, (np.broadcast_to(r, cols.shape), cols), grad / self.scale[:, None])
        base = E + len(self.creases)
        for k, v in enumerate(self.held):
            A[base + 3 * k + np.arange(3), 3 * v + np.arange(3)] = 1.0
        return A

    def stress_forms(self, Z: np.ndarray) -> np.ndarray:
        """(n_c, k, k) z^T Hess g_i z of every constraint on the flexes Z (3V, k), at the
        design (the pins are linear: zero)."""
        pat = self.pattern
        k = Z.shape[1]
        Zv = Z.reshape(pat.n_vertices, 3, k)
        e = pat.edges
        d = self.x0[e[:, 1]] - self.x0[e[:, 0]]
        L = np.linalg.norm(d, axis=1)
        u = d / L[:, None]
        dz = Zv[e[:, 1]] - Zv[e[:, 0]]  # (E, 3, k)
        perp = dz - u[:, :, None] * np.einsum("ed,edk->ek", u, dz)[:, None, :]
        edge = np.einsum("edk,edl->ekl", perp, dz) / L[:, None, None]
        out = np.zeros((self.n_rows, k, k))
        out[: pat.n_edges] = edge
        if len(self.creases):
            hess = _fold_angle_hessian().map(len(self.creases))
            q = self.x0[self.stencils].reshape(len(self.creases), 12).T
            H = np.asarray(hess(q)).reshape(12, len(self.creases), 12).transpose(1, 0, 2)
            Zs = Zv[self.stencils].reshape(len(self.creases), 12, k)
            forms = np.einsum("cak,cab,cbl->ckl", Zs, H, Zs) / self.scale[:, None, None]
            out[pat.n_edges : pat.n_edges + len(self.creases)] = forms
        return out


def held_vertices(pattern: CreasePattern, pinned: np.ndarray, clamped: np.ndarray) -> np.ndarray:
    """(p,) sorted vertices whose position the supports hold: the pinned ones and every
    vertex of the triangles at a clamped one."""
    clamped = np.asarray(clamped, dtype=np.int64)
    at = np.any(np.isin(pattern.faces, clamped), axis=1)
    both = np.concatenate([np.asarray(pinned, dtype=np.int64), pattern.faces[at].ravel()])
    return np.unique(both).astype(np.int64)


def second_order(
    pattern: CreasePattern,
    held: np.ndarray,
    flexes: np.ndarray,
    settings: Settings = DEFAULTS,
) -> SecondOrder:
    """The second-order check (see the module's text) of ``pattern`` (actuated creases
    fixed) with the vertices ``held`` and its first-order motions ``flexes`` (3V, k), k > 0."""
    cons = Constraints(pattern, held)
    Z = np.linalg.qr(np.asarray(flexes, dtype=np.float64))[0]
    k = Z.shape[1]
    A = cons.jacobian(cons.x0)
    U, sv, _ = np.linalg.svd(A, full_matrices=True)
    sigma = np.zeros(A.shape[0])
    sigma[: len(sv)] = sv
    W = U[:, sigma**2 <= settings.structure.rigidity_tol]  # (n_c, s) self-stresses
    forms = cons.stress_forms(Z)  # (n_c, k, k)
    N = np.einsum("is,ikl->skl", W, forms)  # one stress matrix on the flexes per stress
    flat = N.reshape(len(N), k * k).T  # (k^2, s)
    # the size of the constraints' second derivatives on the flexes: stresses are unit vectors
    size = float(np.abs(forms).max(initial=0.0))
    basis = np.zeros((0, k, k))
    if size > 0 and flat.size:
        u, s, _ = np.linalg.svd(flat / size, full_matrices=False)
        keep = s > settings.structure.prestress_tol
        basis = (u[:, keep] * s[keep]).T.reshape(-1, k, k)
        basis = 0.5 * (basis + basis.transpose(0, 2, 1))
    margin, bound, coef = _best_stress(basis, k, settings)
    form = np.tensordot(coef, basis, axes=1) if len(basis) else np.zeros((k, k))
    lam, vec = np.linalg.eigh(form)
    direction = vec[:, 0]
    if margin > settings.structure.prestress_tol:
        # near-mechanisms make near self-stresses: a finite motion along the weakest flex
        # (a rotation about two pins, say) is a mechanism whatever their stress matrices say
        moved = _finite_motion(cons, _unit(Z[:, 0]), settings)
        if moved is not None:
            return SecondOrder(Stability.MECHANISM, k, W.shape[1], len(basis), margin, bound, moved)
        witness = _unit(Z @ direction)
        return SecondOrder(Stability.PRESTRESS, k, W.shape[1], len(basis), margin, bound, witness)
    # a finite motion's tangent has zero energy under every self-stress: try the flex of the
    # smallest energy, the two of zero energy between it and the largest, the flexes' basis
    tries = [direction, *np.eye(k)[: min(k, 6)]]
    if k > 1 and lam[0] < 0 < lam[-1]:
        a, b = np.sqrt(lam[-1]) * vec[:, 0], np.sqrt(-lam[0]) * vec[:, -1]
        tries[1:1] = [a + b, a - b]
    for c in tries:
        moved = _finite_motion(cons, _unit(Z @ c), settings)
        if moved is not None:
            return SecondOrder(Stability.MECHANISM, k, W.shape[1], len(basis), margin, bound, moved)
    return SecondOrder(
        Stability.NOT_PRESTRESS_STABLE,
        k,
        W.shape[1],
        len(basis),
        margin,
        bound,
        _unit(Z @ direction),
    )


def _unit(z: np.ndarray) -> np.ndarray:
    """z scaled to a largest vertex displacement of 1."""
    top = float(np.linalg.norm(z.reshape(-1, 3), axis=1).max(initial=0.0))
    return z / top if top > 0 else z


def _best_stress(basis: np.ndarray, k: int, settings: Settings) -> tuple[float, float, np.ndarray]:
    """max over c in [-1, 1]^r of lambda_min(sum_r c_r B_r) for symmetric B (r, k, k), by
    cutting planes: (the best value found, the last upper bound, the best c (r,))."""
    from scipy.optimize import linprog  # only when first order was not enough

    r = len(basis)
    if r == 0:  # no self-stress acts on the flexes
        return 0.0, 0.0, np.zeros(0)
    cuts = [np.eye(k)[i] for i in range(k)]
    best, best_coef, bound = -np.inf, np.zeros(r), np.inf
    for _ in range(settings.structure.prestress_cuts):
        # maximise t s.t. t <= y^T (sum c_r B_r) y for every cut y; variables (c, t)
        G = np.array([[y @ B @ y for B in basis] for y in cuts])
        res = linprog(
            c=np.r_[np.zeros(r), -1.0],
            A_ub=np.column_stack([-G, np.ones(len(cuts))]),
            b_ub=np.zeros(len(cuts)),
            bounds=[(-1.0, 1.0)] * r + [(None, None)],
            method="highs",
        )
        if res.status != 0:
            break
        coef, bound = res.x[:r], float(-res.fun)
        lam, vec = np.linalg.eigh(np.tensordot(coef, basis, axes=1))
        if lam[0] > best:
            best, best_coef = float(lam[0]), coef
        if best > settings.structure.prestress_tol or bound <= settings.structure.prestress_tol:
            break
        if bound - best <= settings.structure.prestress_tol:
            break
        cuts.append(vec[:, 0])
    return best, bound, best_coef


def _finite_motion(cons: Constraints, z: np.ndarray, settings: Settings) -> np.ndarray | None:
    """The design moved ``structure_flex_step`` mean edge lengths along the flex z (3V,),
    corrected at right angles to z by Gauss-Newton until every constraint holds to
    ``structure_flex_tol`` (of the mean edge length): that displacement (3V,) when it does
    within a correction smaller than the step, else None."""
    scale = float(np.mean(cons.lengths))
    t = settings.structure.flex_step * scale
    zn = z / np.linalg.norm(z)
    x0 = cons.x0.ravel()
    x = x0 + t * z
    for _ in range(settings.structure.max_iter):
        g = cons.values(x.reshape(-1, 3))
        if np.linalg.norm(g) <= settings.structure.flex_tol * scale:
            moved = x - x0
            corr = moved - (moved @ zn) * zn
            return moved if np.linalg.norm(corr) < t else None
        A = np.vstack([cons.jacobian(x.reshape(-1, 3)), zn])
        dx = np.linalg.lstsq(A, np.r_[-g, 0.0], rcond=None)[0]
        x = x + dx
        if np.linalg.norm(x - x0 - (x - x0) @ zn * zn) >= t:
            return None
    return None
