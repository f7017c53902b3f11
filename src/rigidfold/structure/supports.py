"""Supports that stabilise the mechanism: are they enough, and which are the fewest?

A design of DOF d moves, with nothing holding it, in d mechanism modes (the kernel of the
frame model's compatibility matrix, :mod:`rigidfold.mechanism`) and 6 rigid-body motions.
Let Q (v-space x (d + 6)) be an orthonormal basis of these motions of the frame model
(:mod:`rigidfold.frame.model`; translations in units of the mean edge length L). A pinned
vertex v of triangle f holds its velocity ``u_b + theta_b x (x_v - x_b)`` (b: f's barycentre
node) at zero: three rows ``B_v`` of ``P Q``; a clamped vertex also holds the rotation of
every triangle at it. The supports are springs of unit stiffness on these rows, and their
stiffness on the free motions is the pseudo stiffness matrix of Section 4 (Eq. 19),
``K~ = (P Q)^T (P Q) = sum_v B_v^T B_v`` (:class:`rigidfold.mechanism.stiffness.PseudoStiffness`
with the supports for the hinges). The supports make the mechanism **first-order rigid**
when K~ is positive definite: its smallest eigenvalue exceeds
``Settings.structure.rigidity_tol`` times its largest. Otherwise the eigenvector of the
smallest eigenvalue is the motion they leave free, named by its largest hinge rotations (a
mechanism) or as a rigid-body motion.

Actuated creases (``--actuators``) are held at their angle: they count as fixed creases
(supports of a hinge) in the frame model and in the shell model.

``auto``: the smallest set of candidate vertices (boundary vertices by default, a list, or
the boundary vertices at ground level) that is first-order rigid, and among those of that
size the one of the largest smallest eigenvalue. Every set of one size is tried, smallest
size first (from ceil((d + 6) / 3), as each pin gives three rows), while the number of sets
is at most ``Settings.structure.max_support_sets`` (in chunks of at most 128 MiB); beyond, a
greedy search adds the candidate that raises log det (K~ + tol I) the most until rigid (by
the matrix determinant lemma and rank-3 updates: no eigenvalue problem per candidate), then
drops supports while rigid, the one whose removal lowers that log det the least first.

The free motions Q come from the dense singular value decomposition of C for designs of up
to ``Settings.structure.sparse_vertices`` vertices, from a sparse factorisation of C^T C, a
subspace iteration and Rayleigh-Ritz on C above (:func:`_sparse_modes`); the dense blocks
that either needs are bounded by ``Settings.limits.max_structure_bytes``.

Where first order is not enough (K~ has eigenvalues at most ``structure_rigidity_tol``: the
supports leave first-order motions, the flexes, the eigenvectors of those eigenvalues), the
flexes go to the second-order check of :mod:`rigidfold.mechanism.second_order`: a set that is
prestress stable (a self-stress of the constraints holds every flex) is accepted and says
so; one that leaves a finite mechanism, or a flex that no self-stress holds, is refused with
the motion named. ``auto`` prefers first-order rigid sets; it returns a prestress-stable one
only when all candidates together are not first-order rigid.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mechanism.kinematics import (
    angular_velocity_blocks,
    constraint_matrix,
    fold_angle_gradients,
)
from rigidfold.mechanism.second_order import SecondOrder, Stability, held_vertices, second_order
from rigidfold.mechanism.stiffness import PseudoStiffness
from rigidfold.mesh import CreasePattern
from rigidfold.structure.choices import Candidates, indices_text

CANDIDATE_FORMS = ("boundary", "ground", "V,V,...")


def index_array(values: tuple[int, ...], count: int, what: str) -> np.ndarray:
    """The indices ``values`` as a sorted (k,) int64 array of distinct indices below
    ``count``; ValueError naming ``what`` and the indices for one out of range."""
    bad = [v for v in values if not 0 <= v < count]
    if bad:
        raise RigidfoldError(
            f"{what}: {bad[0]} is out of range 0..{count - 1} (got {indices_text(values)!r})"
        )
    return np.array(sorted(set(values)), dtype=np.int64)


def support_candidates(
    pattern: CreasePattern, spec: Candidates = None, settings: Settings = DEFAULTS
) -> np.ndarray:
    """The vertices ``auto`` may choose (sorted, int64): ``None`` or ``"boundary"``: the
    boundary vertices; ``"ground"``: those within ``settings.structure.ground_tol`` of the
    lowest boundary vertex's height; a tuple of indices: these vertices."""
    boundary = pattern.boundary_vertices
    if spec is None or spec == "boundary":
        return boundary
    if spec == "ground":
        z = pattern.coords[boundary, 2]
        return boundary[z <= z.min() + settings.structure.ground_tol]
    return index_array(spec, pattern.n_vertices, "support candidates")


@dataclass(frozen=True, eq=False)
class Supports:
    """Pinned and clamped vertices, and actuated creases (held at their angle).

    pinned : (k,) int64; clamped : (c,) int64; actuated : (a,) int64 edge indices.
    """

    pinned: np.ndarray
    clamped: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    actuated: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self) -> None:
        for name in ("pinned", "clamped", "actuated"):
            arr = np.array(sorted(set(np.asarray(getattr(self, name)).ravel().tolist())))
            arr = arr.astype(np.int64)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        both = np.intersect1d(self.pinned, self.clamped)
        if len(both):
            raise RigidfoldError(f"vertex {int(both[0])} is both pinned and clamped")

    @property
    def vertices(self) -> np.ndarray:
        """(k + c,) the supported vertices: pinned, then clamped."""
        return np.concatenate([self.pinned, self.clamped])

    def held(self, pattern: CreasePattern) -> CreasePattern:
        """``pattern`` with the actuated creases fixed."""
        if not len(self.actuated):
            return pattern
        bad = [int(e) for e in self.actuated if e not in set(pattern.free_creases.tolist())]
        if bad:
            raise RigidfoldError(f"actuator {bad[0]} is not a free crease of the design")
        fixed = pattern.fixed.copy()
        fixed[self.actuated] = True
        return pattern.with_fixed(fixed)

    def to_dict(self) -> dict:
        return {
            "pinned": self.pinned.tolist(),
            "clamped": self.clamped.tolist(),
            "actuated_creases": self.actuated.tolist(),
        }


class SupportModes:
    """The free motions of a design and the support rows on them (see the module's text).

    pattern : the design with its actuated creases fixed. ``Q`` (3V, m) holds, as columns,
    the right singular vectors of the kinematic constraint matrix C (edge lengths and fixed
    creases, rows of unit norm, no gauge: :func:`rigidfold.mechanism.kinematics.constraint_matrix`)
    whose singular values ``sigma`` (m,) are at most ``structure_soft_modes`` times the
    largest: the 6 rigid-body motions, the d mechanisms and the near-mechanisms.
    """

    def __init__(self, pattern: CreasePattern, settings: Settings = DEFAULTS) -> None:
        self.pattern = pattern
        self.settings = settings
        C = constraint_matrix(pattern, 0)[:-9]  # the support triangle's rows dropped
        if pattern.n_vertices <= settings.structure.sparse_vertices:
            sigma, vt, top = _dense_modes(C.toarray())
        else:
            start = len(pattern.boundary_vertices) + 6
            sigma, vt, top = _sparse_modes(C, start, settings)
        soft = sigma <= settings.structure.soft_modes * top
        self.sigma = sigma[soft]
        self.Q = vt[soft].T
        self.dof = int(np.sum(sigma <= settings.mechanism.rank_tol * top)) - 6
        self.near = int(soft.sum()) - 6 - self.dof
        x = pattern.coords - pattern.coords.mean(axis=0)
        V = pattern.n_vertices
        rigid = np.zeros((3 * V, 6))
        for a in range(3):
            rigid[a::3, a] = 1.0
            rigid[:, 3 + a] = np.cross(np.eye(3)[a], x).ravel()
        self.rigid = rigid
        self.scale = float(np.mean(pattern.edge_lengths))
        self._grams: dict[int, np.ndarray] = {}

    @cached_property
    def _angular(self) -> np.ndarray:
        """(F, 3, 3, 3) :func:`~rigidfold.mechanism.kinematics.angular_velocity_blocks`."""
        return angular_velocity_blocks(self.pattern)

    @property
    def n_modes(self) -> int:
        """m: 6 + d + the near-mechanisms."""
        return self.Q.shape[1]

    def pin_rows(self, vertex: int) -> np.ndarray:
        """(3, m) velocity of ``vertex`` on the motions Q."""
        return self.Q[3 * vertex : 3 * vertex + 3]

    def clamp_rows(self, vertex: int) -> np.ndarray:
        """(3 + 3k, m) velocity of ``vertex`` and the angular velocities (times the mean edge
        length) of the k triangles at it."""
        faces = np.flatnonzero(np.any(self.pattern.faces == vertex, axis=1))
        W = self._angular[faces]  # (k, 3, 3, 3)
        rows = [self.pin_rows(vertex)]
        for f, block in zip(faces, W, strict=True):
            cols = (3 * self.pattern.faces[f][:, None] + np.arange(3)).ravel()
            rows.append(self.scale * block.reshape(3, 9) @ self.Q[cols])
        return np.vstack(rows)

    def gram(self, vertex: int, clamp: bool = False) -> np.ndarray:
        """(m, m) B_v^T B_v of one support."""
        key = -1 - vertex if clamp else vertex
        if key not in self._grams:
            B = self.clamp_rows(vertex) if clamp else self.pin_rows(vertex)
            self._grams[key] = B.T @ B
        return self._grams[key]

    @property
    def own(self) -> np.ndarray:
        """(m, m) diag(sigma^2): the motions' own stiffness."""
        return np.diag(self.sigma**2)

    def stiffness(self, supports: Supports) -> PseudoStiffness:
        """K~ = diag(sigma^2) + sum of the supports' B^T B, as the PseudoStiffness of the
        stacked rows [diag(sigma); B] with unit stiffnesses."""
        rows = [np.diag(self.sigma)]
        rows += [self.pin_rows(int(v)) for v in supports.pinned]
        rows += [self.clamp_rows(int(v)) for v in supports.clamped]
        B = np.vstack(rows)
        return PseudoStiffness(B, np.ones(len(B)))

    def rigidity(self, supports: Supports) -> Rigidity:
        """Whether ``supports`` make the design first-order rigid, and the motion they leave
        free when they do not."""
        stiff = self.stiffness(supports)
        lam = stiff.eigenvalues
        soft = lam <= self.settings.structure.rigidity_tol
        rigid = not bool(soft.any())
        weakest = self.Q @ stiff.eigenvectors[:, 0]
        second = None
        if not rigid:
            held = held_vertices(self.pattern, supports.pinned, supports.clamped)
            k = int(soft.sum())
            rows = self.pattern.n_edges + len(self.pattern.fixed_creases) + 3 * len(held)
            check_structure_bytes(
                2 * 8 * rows * k * k,
                f"the second-order check of the {k} first-order motions the supports leave",
                self.settings,
            )
            flexes = self.Q @ stiff.eigenvectors[:, soft]
            second = second_order(self.pattern, held, flexes, self.settings)
            weakest = second.witness
        noun = "a first-order motion"
        if second is None or second.stability is Stability.MECHANISM:
            noun = "a mechanism"
        return Rigidity(
            supports=supports,
            dof=self.dof,
            near_mechanisms=self.near,
            eigenvalues=lam,
            rigid=rigid,
            mode=None if rigid else self.describe(weakest, noun),
            second_order=second,
        )

    def describe(self, motion: np.ndarray, noun: str = "a mechanism") -> str:
        """A motion (3V,) of the vertices in words: ``noun`` that folds the creases it
        folds most, or the rigid-body motion it is."""
        pat = self.pattern
        free = pat.free_creases
        rates = fold_angle_gradients(pat, free) @ motion if len(free) else np.zeros(0)
        coef, *_ = np.linalg.lstsq(self.rigid, motion, rcond=None)
        size = max(float(np.linalg.norm(motion)), 1e-300)
        rest = float(np.linalg.norm(motion - self.rigid @ coef)) / size
        if len(rates) and rest > 1e-3:
            order = np.argsort(-np.abs(rates))[:3]
            top = np.abs(rates[order[0]])
            names = [
                f"{int(free[j])} ({'-'.join(map(str, pat.edges[free[j]]))})"
                for j in order
                if np.abs(rates[j]) > 0.1 * top
            ]
            return f"{noun} that folds crease " + ", ".join(names)
        t, w = coef[:3], coef[3:]
        if np.linalg.norm(w) * self.scale > 1e-6 * np.linalg.norm(t):
            return "a rigid-body rotation about the axis " + _vector(w / np.linalg.norm(w))
        return "a rigid-body translation along " + _vector(t / np.linalg.norm(t))


def _dense_modes(C: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(the singular values (3V,), zeros past the rows; the right singular vectors (3V, 3V)
    as rows; the largest singular value) of the dense constraint matrix C."""
    _, sv, vt = np.linalg.svd(C, full_matrices=True)
    sigma = np.zeros(C.shape[1])
    sigma[: len(sv)] = sv
    return sigma, vt, float(sv[0]) if len(sv) else 1.0


def _sparse_modes(
    C: sp.csr_matrix, start: int, settings: Settings
) -> tuple[np.ndarray, np.ndarray, float]:
    """(Ritz values (k,), ascending; their right vectors (k, 3V) as rows; the largest
    singular value of C) of a subspace that holds every direction of C's singular values up
    to ``structure_soft_modes`` times the largest: ``start`` random columns and
    ``mechanism_sparse_oversampling`` more, filtered by ``(C^T C + delta I)^-1``
    (``structure_soft_shift``, ``structure_soft_iterations`` solves), then Rayleigh-Ritz on
    C; the columns double while the soft Ritz values leave fewer than half the oversampling
    spare. RigidfoldError (one line) when the subspace would pass
    ``Settings.limits.max_structure_bytes``."""
    n = C.shape[1]
    p = settings.mechanism.sparse_oversampling
    cols = min(n, start + p)
    check_structure_bytes(
        _modes_bytes(n, cols), f"{cols} free motions of the supports' search", settings
    )
    M = (C.T @ C).tocsc()
    rng = np.random.default_rng(0)  # the same subspace on every run
    largest = spla.eigsh(M, k=1, which="LA", v0=rng.random(n) - 0.5, return_eigenvectors=False)
    top = float(np.sqrt(max(float(largest[0]), 0.0))) or 1.0
    lu = spla.splu(
        (M + settings.structure.soft_shift * top**2 * sp.identity(n)).tocsc(),
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    while True:
        check_structure_bytes(
            _modes_bytes(n, cols), f"{cols} free motions of the supports' search", settings
        )
        W = np.asfortranarray(rng.random((cols, n)).T - 0.5)
        for _ in range(settings.structure.soft_iterations):
            W = np.linalg.qr(lu.solve(W))[0]
        R: np.ndarray = np.asarray(np.linalg.qr(np.asarray(C @ W), mode="r"))
        if R.shape[0] < cols:
            R = np.vstack([R, np.zeros((cols - R.shape[0], cols))])
        _, values, vt = np.linalg.svd(R)
        values, vt = values[::-1], vt[::-1]
        found = int(np.sum(values <= settings.structure.soft_modes * top))
        if cols == n or found <= cols - p // 2:
            return values, vt @ W.T, top
        cols = min(n, 2 * cols)


def _modes_bytes(n: int, cols: int) -> int:
    """Bytes of the sparse free motions' dense blocks: about four n x cols arrays."""
    return 8 * 4 * n * cols


def check_structure_bytes(need: int, what: str, settings: Settings = DEFAULTS) -> None:
    """RigidfoldError (one line) when ``need`` bytes for ``what`` pass
    ``Settings.limits.max_structure_bytes``."""
    cap = settings.limits.max_structure_bytes
    if need > cap:
        raise RigidfoldError(
            f"the design is too large for the structure check: {what} need about "
            f"{need / 2**30:.3g} GiB, over Settings.limits.max_structure_bytes "
            f"({cap / 2**30:.3g} GiB)"
        )


def _vector(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{c:.3g}" for c in v + 0.0) + ")"


@dataclass(frozen=True, eq=False)
class Rigidity:
    """Whether supports make the design first-order rigid.

    supports : Supports; dof : the mechanism's DOF without supports; near_mechanisms : the
    motions of small stiffness counted with them; eigenvalues : (m,) ascending eigenvalues of
    K~ (m = 6 + dof + near_mechanisms); rigid : first-order rigid; mode : the motion left
    free at first order, in words (None when rigid); second_order : the second-order check
    of the flexes when not first-order rigid (:mod:`rigidfold.mechanism.second_order`).
    """

    supports: Supports
    dof: int
    near_mechanisms: int
    eigenvalues: np.ndarray
    rigid: bool
    mode: str | None
    second_order: SecondOrder | None = None

    @property
    def stability(self) -> Stability:
        """First-order rigid, prestress stable, or the kind of motion left."""
        if self.rigid or self.second_order is None:
            return Stability.FIRST_ORDER if self.rigid else Stability.MECHANISM
        return self.second_order.stability

    @property
    def stable(self) -> bool:
        """The supports hold the design: first-order rigid or prestress stable."""
        return self.stability in (Stability.FIRST_ORDER, Stability.PRESTRESS)

    @property
    def message(self) -> str:
        """The stability's message with the motion concerned."""
        return self.stability.describe(self.mode)

    @property
    def detail(self) -> str | None:
        """The motion concerned, with the second order's word where it decided: ``a
        mechanism that folds crease 3 (1-4)``, ``not prestress stable: ...``, ``prestress
        stable: ...``; None when first-order rigid."""
        kind = self.stability
        if kind is Stability.FIRST_ORDER:
            return None
        if kind is Stability.MECHANISM:
            return self.mode
        word = "prestress stable" if kind is Stability.PRESTRESS else "not prestress stable"
        return f"{word}: {self.mode}"

    @property
    def smallest(self) -> float:
        return float(self.eigenvalues[0]) if len(self.eigenvalues) else 0.0

    def to_dict(self) -> dict:
        return {
            **self.supports.to_dict(),
            "mechanism_dof": self.dof,
            "near_mechanisms": self.near_mechanisms,
            "first_order_rigid": self.rigid,
            "stability": self.stability.value,
            "stable": self.stable,
            "smallest_eigenvalue": self.smallest,
            "mode": self.mode,
            "second_order": None if self.second_order is None else self.second_order.to_dict(),
        }


@lru_cache(maxsize=2)
def support_modes(pattern: CreasePattern, settings: Settings = DEFAULTS) -> SupportModes:
    """The :class:`SupportModes` of ``pattern`` (its actuated creases fixed), kept for the
    last two designs: ``auto`` and ``--supports service`` find the free motions once (a
    pattern is hashed by identity)."""
    return SupportModes(pattern, settings)


def check_supports(
    pattern: CreasePattern,
    supports: Supports,
    settings: Settings = DEFAULTS,
    modes: SupportModes | None = None,
) -> Rigidity:
    """First-order rigidity of ``pattern`` (actuated creases held) on ``supports``; with
    ``modes``, the free motions of ``supports.held(pattern)`` found before (several sets of
    supports of one design)."""
    if modes is None:
        modes = support_modes(supports.held(pattern), settings)
    return modes.rigidity(supports)


def auto_supports(
    pattern: CreasePattern,
    candidates: np.ndarray,
    *,
    clamped: np.ndarray | None = None,
    actuated: np.ndarray | None = None,
    settings: Settings = DEFAULTS,
) -> Rigidity:
    """The smallest set of pinned ``candidates`` (with the ``clamped`` vertices and the
    ``actuated`` creases) that makes ``pattern`` first-order rigid, of the largest smallest
    eigenvalue among the sets of that size tried (see the module's text). When even all
    candidates are not first-order rigid, the result for all of them (``rigid`` False), with
    its second-order check (``stable`` when prestress stable)."""
    none = np.zeros(0, dtype=np.int64)
    base = Supports(
        none,
        none if clamped is None else np.asarray(clamped),
        none if actuated is None else np.asarray(actuated),
    )
    modes = support_modes(base.held(pattern), settings)
    cand = np.setdiff1d(np.asarray(candidates, dtype=np.int64), base.clamped)
    if not len(cand):
        raise RigidfoldError("no candidate vertex for the supports")
    m = modes.n_modes
    check_structure_bytes(8 * m * m * 8, f"the stiffness on {m} free motions", settings)
    G0 = modes.own + sum(
        (modes.gram(int(v), clamp=True) for v in base.clamped), np.zeros((modes.n_modes,) * 2)
    )
    B = np.stack([modes.pin_rows(int(v)) for v in cand])  # (c, 3, m)
    tol = settings.structure.rigidity_tol
    everything = modes.rigidity(Supports(cand, base.clamped, base.actuated))
    if not everything.rigid:
        return everything
    need = int(np.sum(modes.sigma**2 <= tol))  # motions that only supports can hold
    k0 = max(1, math.ceil((need - 6 * len(base.clamped)) / 3))
    for k in range(k0, len(cand) + 1):
        if math.comb(len(cand), k) > settings.structure.max_support_sets:
            chosen = _greedy(G0, B, tol, k)
            return modes.rigidity(Supports(cand[chosen], base.clamped, base.actuated))
        best = _best_set(G0, B, k, tol)
        if best is not None:
            return modes.rigidity(Supports(cand[best], base.clamped, base.actuated))
    return everything  # not reached: all candidates together are rigid


_CHUNK_BYTES = 2**27
"""Memory of one chunk of the exhaustive search's stiffness matrices (128 MiB)."""


def _best_set(G0: np.ndarray, B: np.ndarray, k: int, tol: float) -> np.ndarray | None:
    """Indices into B (c, 3, m) of the k supports, of all sets of k, whose K~ (G0 and their
    rows' B^T B) has the largest smallest eigenvalue above ``tol``; None when none has."""
    m = G0.shape[0]
    grams = np.stack([b.T @ b for b in B]) if B.size * m <= _CHUNK_BYTES // 8 else None
    size = max(1, min(8192, _CHUNK_BYTES // max(8 * m * m * (k if grams is not None else 1), 1)))
    best, best_lam = None, 0.0
    combos = itertools.combinations(range(len(B)), k)
    while True:
        chunk = np.array(list(itertools.islice(combos, size)), dtype=np.int64)
        if not len(chunk):
            break
        if grams is not None:
            stiff = G0 + grams[chunk].sum(axis=1)
        else:
            rows = B[chunk].reshape(len(chunk), 3 * k, m)
            stiff = G0 + np.einsum("sim,sin->smn", rows, rows)
        lam = np.linalg.eigvalsh(stiff)
        ok = lam[:, 0] > tol
        if ok.any():
            i = int(np.argmax(np.where(ok, lam[:, 0], -np.inf)))
            if best is None or lam[i, 0] > best_lam:
                best, best_lam = chunk[i], float(lam[i, 0])
    return best


def _rigid(stiff: np.ndarray, tol: float) -> bool:
    """Whether the symmetric ``stiff`` has every eigenvalue above ``tol`` (a Cholesky
    factorisation of ``stiff - tol I``)."""
    try:
        np.linalg.cholesky(stiff - tol * np.eye(len(stiff)))
    except np.linalg.LinAlgError:
        return False
    return True


def _greedy(G0: np.ndarray, B: np.ndarray, tol: float, least: int = 1) -> np.ndarray:
    """Indices into B (c, 3, m) of a rigid set (see the module's text): add the support that
    raises log det (K~ + tol I) the most until rigid (tested from ``least`` supports on),
    then drop supports while rigid (of those that may go, the one whose removal lowers log
    det (K~ - tol I) the least first). Each support's gain is
    log det(I_3 + B_v (K~ + tol I)^-1 B_v^T) (the matrix determinant lemma), kept up to date
    by rank-3 updates of (K~ + tol I)^-1 B^T, so a step costs O(c m), not an eigenvalue
    problem per candidate; a support may go when I_3 - B_v (K~ - tol I)^-1 B_v^T is positive
    definite (the Schur complement of K~ - tol I without it)."""
    c, _, m = B.shape
    eye = np.eye(m)
    current = G0.copy()
    factor = sla.cho_factor(current + tol * eye)
    W = sla.cho_solve(factor, B.reshape(3 * c, m).T).T.reshape(c, 3, m)  # B (K~ + tol I)^-1
    chosen: list[int] = []
    free = np.ones(c, dtype=bool)
    while not (len(chosen) >= least and _rigid(current, tol)):
        if not free.any():
            break
        S = np.eye(3) + np.einsum("cim,cjm->cij", B, W)  # (c, 3, 3)
        gain = np.round(np.linalg.slogdet(S)[1], 8)  # round-off does not choose
        gain[~free] = -np.inf
        pick = int(np.argmax(gain))  # ties: the lowest index
        chosen.append(pick)
        free[pick] = False
        current = current + B[pick].T @ B[pick]
        # (K + B_p^T B_p)^-1 = K^-1 - K^-1 B_p^T S_p^-1 B_p K^-1
        cross = np.einsum("cim,jm->cij", B, W[pick])  # B_v K^-1 B_p^T, (c, 3, 3)
        W = W - np.einsum("cij,jk,km->cim", cross, np.linalg.inv(S[pick]), W[pick])
    while len(chosen) > 1:
        # K~ - tol I - B_i^T B_i is positive definite iff I_3 - B_i (K~ - tol I)^-1 B_i^T is
        # (its Schur complement): one factorisation a round, a 3 x 3 test per support
        try:
            factor = sla.cho_factor(current - tol * eye)
        except np.linalg.LinAlgError:
            break
        trials = []
        for i in chosen:
            rest = np.eye(3) - B[i] @ sla.cho_solve(factor, B[i].T)
            sign, logdet = np.linalg.slogdet(rest)
            if sign > 0 and _rigid(rest, 1e-8):  # a margin over round-off
                trials.append((round(-float(logdet), 8), i))
        if not trials:
            break
        _, drop = min(trials)  # lowers log det the least; ties: the lowest index
        chosen.remove(drop)
        current = current - B[drop].T @ B[drop]
    return np.array(sorted(chosen), dtype=np.int64)


@dataclass(frozen=True, eq=False)
class SupportGrowth:
    """How ``--supports service`` grew the supports (:mod:`rigidfold.structure.service`).

    rigid : (k,) int64 the pins ``auto`` chose for first-order rigidity; added : (a,) int64
    the pins kept beside them for the deflection, in the order they were added; trail : one
    ``(step, vertex, pins, largest displacement m, allowed displacement m)`` per analysis of
    the search, in order: step ``"rigid"`` (auto's set; vertex -1), ``"add"`` (vertex
    pinned), then ``"drop"`` (vertex taken away again: the rest meet the limit) or
    ``"keep"`` (without it they do not); candidates : how many vertices it could pin;
    passed : whether the last set met the deflection limit (in the search's linear
    analysis). hinge_hint : (hinge stiffness N m/rad per m, its largest displacement m) that
    meets the limit on the last set where pins alone did not, or None; searched_hinges :
    whether that was searched (up to ``Settings.structure.hint_hinge_stiffness``).
    """

    rigid: np.ndarray
    added: np.ndarray
    trail: tuple[tuple[str, int, int, float, float], ...]
    candidates: int
    passed: bool
    hinge_hint: tuple[float, float] | None = None
    searched_hinges: bool = False

    def to_dict(self) -> dict:
        return {
            "hinge_stiffness_that_meets_the_limit": None
            if self.hinge_hint is None
            else {"Nm_per_rad_per_m": self.hinge_hint[0], "max_displacement_m": self.hinge_hint[1]},
            "hinge_stiffness_searched": self.searched_hinges,
            "rigid": self.rigid.tolist(),
            "added_for_deflection": self.added.tolist(),
            "candidates": self.candidates,
            "passed": self.passed,
            "analyses": [
                {
                    "step": step,
                    "vertex": v,
                    "pins": n,
                    "max_displacement_m": d,
                    "allowed_displacement_m": a,
                }
                for step, v, n, d, a in self.trail
            ],
        }
