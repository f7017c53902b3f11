"""Second order where first order is not enough: are the first-order motions of a set of
constraints held by a self-stress (prestress stability), or do they extend to a real, finite
mechanism? One test, used twice: for a design on its supports (:mod:`rigidfold.structure`)
and for a shape that generation found mobile at first order but whose folding path does
not leave it (:func:`obstruction`, :class:`ChildForecast`, used by
:mod:`rigidfold.generate`).

The first-order tests (:mod:`rigidfold.structure.supports`, :func:`rigidfold.mechanism.analyze`)
leave k first-order motions Z (3V x k): the **flexes**. A flat or nearly flat vertex held
around its boundary has one: the vertex may leave the plane at first order, yet no edge can
keep its length as it does, so the vertex does not move. This module tells such cases from
real mechanisms, after Connelly and Whiteley (Second-order rigidity and prestress stability
for tensegrity frameworks, SIAM J. Discrete Math. 9(3), 1996):

* Write the constraints as g_i(x) = 0, each scaled to a gradient of unit norm at the design
  (edge lengths |x_v - x_u| - L; fold angles (rho - rho_0) / |grad rho|; a held vertex's
  coordinates; a clamped support holds every vertex of the triangles at it, which holds their
  rotations exactly; a shape in generation is held by its support triangle).
  A = dg/dx (n_c x 3V) is the first-order constraint matrix.
* A **self-stress** is w with A^T w = 0 (for supports: the left singular vectors of A whose
  singular value squared is at most ``Settings.structure.rigidity_tol``; for a shape in
  generation: the n_c - rank smallest, the rank decided as the mechanism analysis decides it,
  ``Settings.mechanism.rank_tol``: near self-stresses of a nearly flat vertex count). Its
  **stress matrix** Omega(w) = sum_i w_i Hess g_i is the geometric stiffness that the
  self-stress gives the flexes: their energy at second order is z^T Omega(w) z.
* The constraints are **prestress stable** when some self-stress makes Z^T Omega(w) Z positive
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

**In generation** a prestress-stable shape cannot fold at all, whatever its first-order DOF:
moving it h (root-mean-square, in mean edge lengths) along its weakest flex strains some
constraint by at least ``energy h^2 / (2 |w|_1)`` (the self-stress w spreads the residual
``w . g = h^2 z^T Omega(w) z / 2`` over its members). The criterion is the tracer's own: a
shape is **second-order rigid** when that strain at the tracer's first step
(``Settings.path.step``) exceeds the length tolerance the tracer keeps (``Settings.path.tol``)
and no finite motion of that step meets the constraints to that tolerance
(``docs/deployability.md``). Fixing a crease adds a row that rotates at first order, so it
adds no self-stress and keeps the flexes with that crease's rate at zero: the children of a
shape are forecast from its flexes and stresses alone (:class:`ChildForecast`); a shape whose
own stress form is definite on all its flexes has no child that folds.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import casadi as ca
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mechanism.kinematics import fold_angles_and_gradients
from rigidfold.mechanism.sparse import largest_singular, smallest_singular
from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome


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
        return self.sparse_jacobian(x).toarray()

    def sparse_jacobian(self, x: np.ndarray) -> sp.csr_matrix:
        """(n_c, 3V) dg/dx at x (V, 3), sparse: 6 entries per edge, 12 per fixed crease, 1
        per held coordinate."""
        pat = self.pattern
        E, V = pat.n_edges, pat.n_vertices
        e = pat.edges
        d = x[e[:, 1]] - x[e[:, 0]]
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        xyz = np.arange(3)
        rows = [np.repeat(np.arange(E), 6)]
        cols = [np.concatenate([3 * e[:, :1] + xyz, 3 * e[:, 1:] + xyz], axis=1).ravel()]
        vals = [np.concatenate([-d, d], axis=1).ravel()]
        if len(self.creases):
            _, grad, at = fold_angles_and_gradients(x, self.stencils)
            rows.append(np.repeat(E + np.arange(len(self.creases)), at.shape[1]))
            cols.append(at.ravel())
            vals.append((grad / self.scale[:, None]).ravel())
        base = E + len(self.creases)
        rows.append(base + np.arange(3 * len(self.held)))
        cols.append((3 * self.held[:, None] + xyz).ravel())
        vals.append(np.ones(3 * len(self.held)))
        return sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
            shape=(self.n_rows, 3 * V),
        )

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
    basis, _, _ = _stress_basis(W, forms, settings)
    margin, bound, coef = _best_stress(basis, k, settings)
    form = np.tensordot(coef, basis, axes=1) if len(basis) else np.zeros((k, k))
    lam, vec = np.linalg.eigh(form)
    direction = vec[:, 0]
    if margin > settings.structure.prestress_tol:
        # near-mechanisms make near self-stresses: a finite motion along the weakest flex
        # (a rotation about two pins, say) is a mechanism whatever their stress matrices say
        moved = _finite_motion(cons, _unit(Z[:, 0]), *_flex_test(settings))
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
        moved = _finite_motion(cons, _unit(Z @ c), *_flex_test(settings))
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


def _flex_test(settings: Settings) -> tuple[float, float, int, float]:
    """(step, tol, iterations, delta) of the finite-motion test of supports
    (``Settings.structure``; ``delta``, ``Settings.path.regularization``)."""
    st = settings.structure
    return st.flex_step, st.flex_tol, st.max_iter, settings.path.regularization


def _finite_motion(
    cons: Constraints, z: np.ndarray, step: float, tol: float, iterations: int, delta: float
) -> np.ndarray | None:
    """The design moved ``step`` mean edge lengths along the flex z (3V,), corrected at
    right angles to z by Gauss-Newton until every constraint holds to ``tol`` (of the mean
    edge length): that displacement (3V,) when it does within a correction smaller than
    the step, else None. Each correction is the least-norm solution of the linearised
    constraints and z . dx = 0, from the sparse system ``[[I, A^T], [A, -delta I]]``
    (``delta``: ``Settings.path.regularization``, so that redundant rows, self-stresses,
    are allowed): a dense least-squares solve took 1.5 s at 500 vertices."""
    scale = float(np.mean(cons.lengths))
    t = step * scale
    zn = z / np.linalg.norm(z)
    x0 = cons.x0.ravel()
    x = x0 + t * z
    n = len(x0)
    for _ in range(iterations):
        g = cons.values(x.reshape(-1, 3))
        if np.linalg.norm(g) <= tol * scale:
            moved = x - x0
            corr = moved - (moved @ zn) * zn
            return moved if np.linalg.norm(corr) < t else None
        A = sp.vstack([cons.sparse_jacobian(x.reshape(-1, 3)), sp.csr_matrix(zn[None])])
        m = A.shape[0]
        K = sp.bmat([[sp.identity(n), A.T], [A, -delta * sp.identity(m)]], format="csc")
        try:
            solution = spla.splu(K, permc_spec="COLAMD").solve(np.r_[np.zeros(n), -g, 0.0])
        except RuntimeError:  # an exactly singular factor: no correction
            return None
        x = x + solution[:n]
        if not np.all(np.isfinite(x)) or np.linalg.norm(x - x0 - (x - x0) @ zn * zn) >= t:
            return None
    return None


def _stress_basis(
    W: np.ndarray, forms: np.ndarray, settings: Settings
) -> tuple[np.ndarray, np.ndarray, float]:
    """The independent stress matrices on the flexes of the self-stresses W (n_c, s), from
    every constraint's second derivatives on the flexes ``forms`` (n_c, k, k): (basis (r, k,
    k) symmetric, of norm up to 1; coef (s, r): basis[j] = sum_i coef[i, j] W_i^T forms / size;
    size, the largest entry of ``forms``). Matrices below ``structure_prestress_tol`` of
    ``size`` are dropped."""
    k = forms.shape[1]
    N = np.einsum("is,ikl->skl", W, forms)  # one stress matrix on the flexes per stress
    flat = N.reshape(len(N), k * k).T  # (k^2, s)
    # the size of the constraints' second derivatives on the flexes: stresses are unit vectors
    size = float(np.abs(forms).max(initial=0.0))
    if not (size > 0 and flat.size):
        return np.zeros((0, k, k)), np.zeros((W.shape[1], 0)), size
    _, s, vt = np.linalg.svd(flat / size, full_matrices=False)
    keep = s > settings.structure.prestress_tol
    coef = vt[keep].T  # (s, r): the stresses' combinations
    basis = np.einsum("sr,skl->rkl", coef, N) / size
    return 0.5 * (basis + basis.transpose(0, 2, 1)), coef, size


# ------------------------------------------------------------------ shapes in generation
@dataclass(frozen=True, eq=False)
class FirstOrder:
    """The first-order motions and self-stresses of a shape held by its support triangle,
    in coordinates over the mean edge length: one dense SVD of the constraint matrix below
    ``Settings.mechanism.sparse_analysis_vertices`` vertices, from there on the smallest
    singular values of each side without a dense factorisation
    (:func:`rigidfold.mechanism.sparse.smallest_singular` on A for the flexes, on A^T for the
    self-stresses: a 625-vertex shape in 0.16-0.24 s instead of 2.4-3.0 s, the same spans to
    about 1e-7, ``benchmarks/bench_second_order.py``).

    cons : Constraints of the scaled shape, its support triangle's vertices held
    flexes : (3V, k) orthonormal: the right singular vectors of the k smallest singular values
    stresses : (n_c, s) orthonormal: the left singular vectors of the n_c - rank smallest
    stress_values : (s,) their singular values over the largest (0 for exact self-stresses;
        sparse: Ritz values, round-off for exact ones)
    method : "dense" or "sparse"
    """

    cons: Constraints
    flexes: np.ndarray
    stresses: np.ndarray
    stress_values: np.ndarray
    method: str = "dense"

    @cached_property
    def forms(self) -> np.ndarray:
        """(n_c, k, k) every constraint's second derivative on the flexes."""
        return self.cons.stress_forms(self.flexes)


def first_order(
    pattern: CreasePattern, support_face: int, dof: int, settings: Settings = DEFAULTS
) -> FirstOrder:
    """:class:`FirstOrder` of ``pattern`` (its fixed creases' angles kept) held by the
    triangle ``support_face``, with the ``dof`` flexes of the mechanism analysis (the same
    rank decision: rank = 3V - dof). Dense below ``Settings.mechanism.
    sparse_analysis_vertices`` vertices (the paper's patterns keep the reference), sparse
    from there on (:class:`FirstOrder`)."""
    scale = float(np.mean(pattern.edge_lengths))
    cons = Constraints(pattern.with_coords(pattern.coords / scale), pattern.faces[support_face])
    if pattern.n_vertices >= settings.mechanism.sparse_analysis_vertices:
        return _sparse_first_order(cons, dof, settings)
    A = cons.jacobian(cons.x0)
    U, sv, vt = np.linalg.svd(A, full_matrices=True)
    n_c, n = A.shape
    rank = n - dof
    values = sv / sv[0] if len(sv) and sv[0] > 0 else sv
    padded = np.zeros(n_c)
    padded[: len(values)] = values
    return FirstOrder(
        cons=cons,
        flexes=vt[rank:].T.copy(),
        stresses=U[:, rank:].copy(),
        stress_values=padded[rank:],
    )


def _sparse_first_order(cons: Constraints, dof: int, settings: Settings) -> FirstOrder:
    """:class:`FirstOrder` from the sparse constraint matrix: the ``dof`` smallest right
    singular vectors of A, the n_c - (3V - dof) smallest of A^T (its left ones)."""
    A = cons.sparse_jacobian(cons.x0)
    n_c, n = A.shape
    _, flexes = smallest_singular(A, dof, settings)
    values, stresses = smallest_singular(A.T, n_c - n + dof, settings)
    top = largest_singular(A)
    return FirstOrder(
        cons=cons,
        flexes=np.linalg.qr(flexes)[0],  # orthonormal to round-off, as the dense ones
        stresses=np.linalg.qr(stresses)[0],
        stress_values=values / top if top > 0 else values,
        method="sparse",
    )


@dataclass(frozen=True, eq=False)
class Obstruction:
    """The second-order test of a shape's flexes (see the module's text).

    rigid : second-order rigid: a self-stress makes the stress form definite on the flexes,
        the strain it needs for one tracer step exceeds the tracer's tolerance, and no
        finite motion of that step was found
    flexes, stresses : k and s
    margin : lambda_min of the best stress form on the flexes over the forms' size (> 0:
        definite, prestress stable)
    sigma : the best self-stress's singular value, |A^T w| / |w| over the largest (0: exact;
        up to ``Settings.mechanism.rank_tol``: a near self-stress)
    energy : its stress form's smallest eigenvalue for a flex of unit root-mean-square
        displacement, over |w| (mean edge lengths; the second-order stiffness)
    strain : the least largest constraint strain of one tracer step along the weakest flex,
        ``energy h^2 |w| / (2 |w|_1)`` with h = ``Settings.path.step``
    finite_motion : a step of ``path_step`` met every constraint to ``path_tol``
    """

    rigid: bool
    flexes: int
    stresses: int
    margin: float
    sigma: float
    energy: float
    strain: float
    finite_motion: bool

    def to_dict(self) -> dict:
        return {
            "rigid": self.rigid,
            "flexes": self.flexes,
            "self_stresses": self.stresses,
            "margin": self.margin,
            "sigma": self.sigma,
            "energy": self.energy,
            "strain": self.strain,
            "finite_motion": self.finite_motion,
        }


def obstruction(
    pattern: CreasePattern, support_face: int, dof: int, settings: Settings = DEFAULTS
) -> Obstruction:
    """Whether the shape ``pattern`` of first-order DOF ``dof`` (>= 1) held by its triangle
    ``support_face`` is second-order rigid (:class:`Obstruction`)."""
    fo = first_order(pattern, support_face, dof, settings)
    return _obstruction(fo, fo.flexes, fo.forms, settings)


def _obstruction(
    fo: FirstOrder, Z: np.ndarray, forms: np.ndarray, settings: Settings
) -> Obstruction:
    """The test on the flexes Z (3V, k) (all of the shape's, or a child's), whose forms
    (n_c, k, k) are given."""
    k, s = Z.shape[1], fo.stresses.shape[1]
    basis, coef, _ = _stress_basis(fo.stresses, forms, settings)
    margin, _, best = _best_stress(basis, k, settings)
    if not len(basis) or not margin > settings.structure.prestress_tol:
        return Obstruction(False, k, s, float(margin), 0.0, 0.0, 0.0, False)
    a = coef @ best  # the best self-stress in the stresses' basis
    w = fo.stresses @ a
    form = np.einsum("i,ikl->kl", w, forms)
    lam, vec = np.linalg.eigh(0.5 * (form + form.T))
    V = fo.cons.pattern.n_vertices
    norm_w = float(np.linalg.norm(w))
    energy = float(lam[0]) * V / norm_w  # unit rms flex: |z|^2 = V
    h = settings.path.step
    strain = energy * h**2 * norm_w / (2 * float(np.abs(w).sum()))
    sigma = float(np.sqrt(np.sum(a**2 * fo.stress_values**2)) / np.linalg.norm(a))
    moved = _finite_motion(
        fo.cons,
        _unit(Z @ vec[:, 0]),
        settings.path.step,
        settings.path.tol,
        settings.structure.max_iter,
        settings.path.regularization,
    )
    rigid = moved is None and strain > settings.path.tol
    return Obstruction(rigid, k, s, float(margin), sigma, energy, strain, moved is not None)


@dataclass(frozen=True, eq=False)
class ChildForecast:
    """The second-order test of a shape's children before they are solved: fixing free
    crease c keeps the flexes with c's fold-angle rate at zero (and adds no self-stress, as
    c rotates at first order), so a child's stress forms are the shape's restricted to them.

    first : the shape's :class:`FirstOrder`; rates : (E, k) every crease's fold-angle rate
    along each flex (zero rows for boundary edges); basis, coef, size : the shape's stress
    forms (:func:`_stress_basis`)
    """

    first: FirstOrder
    rates: np.ndarray
    basis: np.ndarray
    size: float
    settings: Settings

    @classmethod
    def at(
        cls, pattern: CreasePattern, support_face: int, dof: int, settings: Settings = DEFAULTS
    ) -> ChildForecast:
        fo = first_order(pattern, support_face, dof, settings)
        interior = pattern.interior_edges
        _, grad, cols = fold_angles_and_gradients(fo.cons.x0, pattern.crease_stencils(interior))
        rates = np.zeros((pattern.n_edges, fo.flexes.shape[1]))
        rates[interior] = np.einsum("ca,cak->ck", grad, fo.flexes[cols])
        basis, _, size = _stress_basis(fo.stresses, fo.forms, settings)
        return cls(fo, rates, basis, size, settings)

    @cached_property
    def dead_end(self) -> bool:
        """The shape's own stress form is definite on all its flexes: no child folds."""
        margin, _, _ = _best_stress(self.basis, self.first.flexes.shape[1], self.settings)
        return bool(margin > self.settings.structure.prestress_tol)

    def rigid(self, creases: tuple[int, ...] | list[int]) -> bool:
        """Whether fixing ``creases`` (edge indices) is forecast to leave a second-order
        rigid child (a child of DOF 0 is not: the analysis tells it)."""
        R = self.rates[list(creases)]
        _, s, vt = np.linalg.svd(R, full_matrices=True)
        top = float(np.abs(self.rates).max(initial=0.0))
        r = int(np.sum(s > self.settings.mechanism.rank_tol * max(top, np.finfo(float).tiny)))
        A = vt[r:].T  # (k, k'): the flexes kept
        if A.shape[1] == 0 or not len(self.basis):
            return False
        reduced = np.einsum("ka,rkl,lb->rab", A, self.basis, A)
        margin, _, _ = _best_stress(reduced, A.shape[1], self.settings)
        return bool(margin > self.settings.structure.prestress_tol)
