"""Exact first-order look-ahead: the creases that fixing a candidate would lock (Property 2).

The mechanisms of a shape are ``H a`` for a in R^d, with hinge rotations ``H_phi a``
(:class:`~rigidfold.mechanism.Mechanism`, Eq. 18). Fixing a candidate G (one crease, or a
mirror group fixed together) keeps the mechanisms with ``H_phi[G] a = 0``. At the same
geometry these are exactly the mechanisms the analysis finds once G is fixed (the fixed
creases' fold-angle rates are its extra kinematic constraints, and the metric that makes H
orthonormal does not change on them), so a free crease p keeps the rotations
``H_phi[p] Q`` (Q an orthonormal basis of that subspace), whose norm is the residual of the
row H_phi[p] after projecting out the row span of H_phi[G]:

* one crease j: ``r_jp = |H_phi[p]| sqrt(1 - (Psi_j . Psi_p)^2)`` with Psi the normalised
  rows (Eq. 31): p loses its rotations when its row is parallel to j's (Property 2);
* a group: the residual of H_phi[p] from span(H_phi[G]).

A folded free crease p (|rho_p| > ``flat_angle``) outside G is predicted locked when
``r_p <= lookahead_tol * max_q r_q`` (q over the free creases outside G): the lock test of
:attr:`Mechanism.locked <rigidfold.mechanism.Mechanism.locked>` (``lock_tol``) applied to
the mechanisms left after the fix. When the fix leaves no mechanism (DOF 0), every folded
free crease outside G is locked, as the analysis says of a 0-DOF shape. With
``lookahead_tol == lock_tol`` (the default) the forecast is what :func:`~rigidfold.mechanism.
analyze` finds after fixing the candidate at the same geometry (``tests/test_lookahead.py``).

Creases whose row is ~0 (norm <= ``lock_tol`` times the largest: still in every mode)
constrain nothing when fixed: they are dropped from a candidate's rows, so a candidate made
only of them keeps the DOF and locks no other crease. A flat one is never predicted locked;
a folded one (a shape that is locked already, never one ``generate`` accepted) is predicted
locked whatever is fixed, as the analysis finds it. Within a group, rows that are linearly
dependent (singular values of the normalised rows below ``mechanism_rank_tol`` times the
largest) count once.

One GEMM of the unit candidate rows with H_phi, (n, d) x (d, h), gives every squared
residual ``|H_phi[p]|^2 - |projection|^2``; the few whose lock decision lies within the
round-off of that subtraction are recomputed from the difference vectors, so a parallel pair
is told from a nearly parallel one to round-off. :func:`lookahead_order` forecasts the
ranking block by block as generation asks for the next candidate: it usually fixes the first
it tries, so a selection pays for a few candidates' forecast, not all h.

The order (:func:`lookahead_order`) puts off, besides the candidates forecast to lock, those
whose fix locked a crease at an earlier shape of the run (``locked_before``): the forecast is
made at the shape before the solve, and the re-optimised shape can lock a crease that kept
rotations at first order (the fix flattens a folded candidate: a finite motion); the shapes
of one run differ by one fix each, and such a fix locks again at the next shape. Once every
other candidate has failed, a put-off candidate whose forecast locks are all carried to
nearly flat by its own fix is fixed together with them (:func:`flat_groups`): the typical
case is a degree-4 vertex, a local one-DOF mechanism whose four rows are parallel; fixing
one crease flat closes the vertex, and the other three end a few hundredths of a degree from
flat, free and locked. Fixed with it, they are fixed creases (flat, part of one panel), not
locked ones: the group removes the vertex's mode (DOF - 1) and locks nothing.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mechanism import Mechanism


@dataclass(frozen=True, eq=False)
class LockForecast:
    """The creases each candidate would lock at first order, at one shape.

    hinges : (h,) int64 edge indices of the free creases (rows of H_phi)
    candidates : n tuples of edge indices, each fixed together (a crease or a mirror group)
    residual_sq : (n, h) float64, [k, p]: squared norm of the rotations crease p keeps after
        candidate k is fixed (0 for k's own creases); to round-off ``8 eps |H_phi[p]|^2``,
        exact where it decides a lock
    folded : (h,) bool, the creases with |rho| > ``flat_angle`` (only they can lock)
    locked : (n, h) bool, [k, p]: candidate k would lock crease p (:meth:`locks`)
    dof_after : (n,) int64, the DOF left after fixing candidate k
    tol : float, the ``lookahead_tol`` used
    """

    hinges: np.ndarray
    candidates: tuple[tuple[int, ...], ...]
    residual_sq: np.ndarray
    folded: np.ndarray
    locked: np.ndarray
    dof_after: np.ndarray
    tol: float

    @property
    def predicts_lock(self) -> np.ndarray:
        """(n,) bool: candidate k would lock at least one crease."""
        return np.asarray(self.locked.any(axis=1))

    def locks(self, k: int) -> np.ndarray:
        """(m,) int64 edge indices of the creases candidate k would lock."""
        return self.hinges[self.locked[k]]

    @cached_property
    def rotation_left(self) -> np.ndarray:
        """(n, h) float64: the rotations kept relative to the largest of the row, the
        quantity compared with ``tol`` (0 where the fix leaves no rotation; NaN for flat
        creases)."""
        r = np.sqrt(np.maximum(self.residual_sq, 0.0))
        top = r.max(axis=1, initial=0.0)[:, None]
        left = np.divide(r, top, out=np.zeros_like(r), where=top > 0)
        left[:, ~self.folded] = np.nan
        return left

    def left(self, k: int, creases: Sequence[int]) -> list[float | None]:
        """:attr:`rotation_left` of some edges after candidate k; None for an edge that is no
        free crease here or is flat (no forecast is made for it)."""
        row = {int(e): j for j, e in enumerate(self.hinges)}
        values = [self.rotation_left[k, row[int(e)]] if int(e) in row else np.nan for e in creases]
        return [None if np.isnan(v) else float(v) for v in values]

    def to_dict(self) -> dict:
        """JSON-serialisable: the tolerance and, per candidate, its creases, the DOF left and
        the creases it would lock."""
        return {
            "tol": self.tol,
            "candidates": [
                {"fixed": list(c), "dof_after": int(dof), "locks": self.locks(k).tolist()}
                for k, (c, dof) in enumerate(zip(self.candidates, self.dof_after, strict=True))
            ],
        }


def group_bases(
    H_phi: np.ndarray, members: np.ndarray, still: np.ndarray, rank_tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal bases of the row spans of the candidates' rows of H_phi.

    H_phi : (h, d) float64 hinge rotations of orthonormal modes
    members : (n, k) int64 rows of H_phi fixed together by each candidate, -1 = padding
    still : (h,) bool, rows that count as zero (they constrain nothing)
    rank_tol : a group's normalised rows count once where their singular values fall below
        this times the largest
    returns : basis (n, k, d) float64, orthonormal rows padded with zero rows; rank (n,)
    """
    H_phi = np.asarray(H_phi, dtype=float)
    members = np.asarray(members, dtype=np.int64)
    if members.ndim != 2 or H_phi.ndim != 2:
        raise RigidfoldError(
            f"need H_phi (h, d) and members (n, k), got {H_phi.shape} and {members.shape}"
        )
    rows = np.where(members >= 0, members, 0)
    use = (members >= 0) & ~np.asarray(still, dtype=bool)[rows]
    picked = H_phi[rows]  # (n, k, d)
    norms = np.sqrt(np.einsum("nkd,nkd->nk", picked, picked))
    unit = picked * np.divide(1.0, norms, out=np.zeros(rows.shape), where=use)[..., None]
    if members.shape[1] == 1 or H_phi.shape[1] == 0:
        return unit, use.sum(axis=1)
    _, sv, vt = np.linalg.svd(unit, full_matrices=False)  # sv (n, k), vt (n, k, d)
    keep = sv > rank_tol * np.maximum(sv[:, :1], np.finfo(float).tiny)
    return vt * keep[..., None], keep.sum(axis=1)


def squared_residuals(H_phi: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """|H_phi[p]|^2 - |its projection onto candidate i's span|^2, by one GEMM.

    H_phi : (h, d); basis : (n, k, d) orthonormal rows (:func:`group_bases`)
    returns : (n, h) float64, with a round-off of up to about ``8 eps |H_phi[p]|^2`` (the
        subtraction cancels for rows nearly in the span: :func:`exact_residuals`)
    """
    n, k, d = basis.shape
    sq = np.einsum("hd,hd->h", H_phi, H_phi)
    coef = (basis.reshape(n * k, d) @ H_phi.T).reshape(n, k, H_phi.shape[0])
    coef *= coef
    return sq - (coef[:, 0] if k == 1 else coef.sum(axis=1))


def exact_residuals(
    H_phi: np.ndarray, basis: np.ndarray, ci: np.ndarray, pi: np.ndarray
) -> np.ndarray:
    """(m,) squared residuals of rows ``pi`` after candidates ``ci`` (both (m,) int), from
    the difference vectors: no cancellation."""
    rows = H_phi[pi]
    projection = np.einsum("mkd,mk->md", basis[ci], np.einsum("mkd,md->mk", basis[ci], rows))
    diff = rows - projection
    return np.einsum("md,md->m", diff, diff)


def lock_forecast(
    mechanism: Mechanism,
    candidates: Sequence[Sequence[int]] | None = None,
    *,
    settings: Settings = DEFAULTS,
) -> LockForecast:
    """The creases each candidate would lock at first order (see the module's text).

    mechanism : the analysed shape; candidates : groups of free-crease edge indices fixed
    together (default: every free crease alone), e.g. the groups of
    :func:`~rigidfold.selection.rank_candidates`.
    """
    hinges, H_phi = mechanism.hinges, mechanism.H_phi
    groups = (
        tuple((e,) for e in hinges.tolist())
        if candidates is None
        else tuple(map(tuple, candidates))
    )
    members = _rows(groups, hinges, mechanism.pattern.n_edges)
    norms = mechanism.rotation_norms
    still = norms <= settings.mechanism.lock_tol * max(norms.max(initial=0.0), np.finfo(float).tiny)
    basis, rank = group_bases(H_phi, members, still, settings.mechanism.rank_tol)
    r2 = squared_residuals(H_phi, basis)
    ci, slot = np.divmod(np.flatnonzero(members >= 0), members.shape[1])
    inside = (ci, members[ci, slot])
    r2[inside] = 0.0
    dof_after = mechanism.dof - rank
    top2 = r2.max(axis=1, initial=0.0)
    # no rotation left (DOF 0): the analysis calls every folded crease locked
    bound2 = np.where(
        (dof_after == 0) | (top2 <= 0.0), np.inf, settings.generation.lookahead_tol**2 * top2
    )
    folded = np.abs(mechanism.pattern.fold_angles[hinges]) > settings.geometry.flat_angle
    margin = 8 * np.finfo(float).eps * norms**2  # round-off of squared_residuals
    near = (r2 <= bound2[:, None] + margin) & folded
    near[inside] = False
    ci, pi = np.divmod(np.flatnonzero(near), near.shape[1])
    if len(ci):  # decide these from the exact residuals
        r2[ci, pi] = exact_residuals(H_phi, basis, ci, pi)
        near[ci, pi] = r2[ci, pi] <= bound2[ci]
    return LockForecast(
        hinges, groups, r2, folded, near, dof_after, settings.generation.lookahead_tol
    )


def _rows(groups: tuple[tuple[int, ...], ...], hinges: np.ndarray, n_edges: int) -> np.ndarray:
    """(n, k) rows of H_phi of each group's creases, -1 = padding; ValueError for a group
    that is empty or holds an edge that is no free crease."""
    row_of = np.full(n_edges + 1, -1, dtype=np.int64)  # the last one for any other number
    row_of[hinges] = np.arange(len(hinges))
    sizes = np.fromiter(map(len, groups), dtype=np.int64, count=len(groups))
    flat = np.fromiter(itertools.chain.from_iterable(groups), np.int64, int(sizes.sum()))
    rows = row_of[np.where((flat >= 0) & (flat < n_edges), flat, n_edges)]
    if (rows < 0).any() or (sizes == 0).any():
        owner = np.repeat(np.arange(len(groups)), sizes)
        bad = int(np.concatenate([owner[rows < 0], np.flatnonzero(sizes == 0)]).min())
        raise RigidfoldError(f"candidate {list(groups[bad])} is not a set of free creases")
    if (sizes == 1).all():
        return rows[:, None]
    owner = np.repeat(np.arange(len(groups)), sizes)
    members = np.full((len(groups), int(sizes.max(initial=1))), -1, dtype=np.int64)
    members[owner, np.arange(len(flat)) - np.repeat(np.cumsum(sizes) - sizes, sizes)] = rows
    return members


def _no_edges() -> np.ndarray:
    return np.zeros(0, dtype=np.int64)


@dataclass(frozen=True, eq=False)
class Choice:
    """One fix to try, in the order of :func:`lookahead_order`.

    index : int, the candidate's position in the ranking
    locks : (m,) int64 edges the candidate alone is forecast to lock
    locked_before : (b,) int64 edges its fix locked at an earlier shape of the run
    carried : (c,) int64 creases fixed together with the candidate (:func:`flat_groups`):
        the nearly flat ones it would lock; empty for the candidate alone
    passed : the put-off candidates ranked between this one and the one before it
    rigid : its fix is forecast to leave a shape that is mobile at first order only
        (second-order rigid; :class:`rigidfold.mechanism.second_order.ChildForecast`)
    idle : its fix is forecast to remove no mechanism (its creases are still in every mode,
        :func:`lock_forecast`'s rank 0): the shape keeps its DOF
    """

    index: int
    locks: np.ndarray = field(default_factory=_no_edges)
    locked_before: np.ndarray = field(default_factory=_no_edges)
    carried: np.ndarray = field(default_factory=_no_edges)
    passed: tuple[Choice, ...] = ()
    rigid: bool = False
    idle: bool = False

    @property
    def put_off(self) -> bool:
        """Forecast to lock, to be second-order rigid or to remove no mechanism, or locked
        at an earlier shape: tried once all others failed."""
        return bool(len(self.locks) or len(self.locked_before) or self.rigid or self.idle)


def carried_angles(
    mechanism: Mechanism,
    group: Sequence[int],
    creases: Sequence[int] | np.ndarray,
    *,
    settings: Settings = DEFAULTS,
) -> np.ndarray:
    """Fold angles of ``creases`` once the fix of ``group`` has flattened it, at first order.

    The smallest motion in the mechanism's modes that takes the group's fold angles to zero,
    ``a = -pinv(H_phi[G]) rho_G``, turns crease p by ``H_phi[p] a``; for a crease the fix is
    forecast to lock (its row in the span of the group's rows) that rotation is the same for
    every such motion. Rows that count as zero (:func:`lock_forecast`) are left out of G.

    group, creases : edge indices of free creases
    returns : (m,) float64 radians, ``rho[creases] + H_phi[creases] a``
    """
    rows = _rows(
        (tuple(group), *((int(e),) for e in creases)), mechanism.hinges, mechanism.pattern.n_edges
    )
    H_phi = mechanism.H_phi
    rho = mechanism.pattern.fold_angles[mechanism.hinges]
    norms = mechanism.rotation_norms
    g = rows[0][rows[0] >= 0]
    g = g[
        norms[g] > settings.mechanism.lock_tol * max(norms.max(initial=0.0), np.finfo(float).tiny)
    ]
    c = rows[1:, 0]
    if not len(g):
        return rho[c]
    a = np.linalg.lstsq(H_phi[g], -rho[g], rcond=settings.mechanism.rank_tol)[0]
    return rho[c] + H_phi[c] @ a


def flat_groups(
    mechanism: Mechanism,
    candidates: Sequence[Sequence[int]],
    put_off: Sequence[Choice],
    *,
    settings: Settings = DEFAULTS,
) -> list[Choice]:
    """The put-off candidates to fix together with the creases they would lock.

    A candidate qualifies when its fix is forecast to lock creases, every one of them ends
    within ``settings.generation.lookahead_carry_angle`` of flat once the candidate is flat
    (:func:`carried_angles`), and it locked no other crease at an earlier shape. Returned
    with ``carried`` = those creases: each set of creases once (from the candidate that
    carries it flattest), the smallest sets first, then the flattest.

    candidates : the ranking (edge groups); put_off : Choices of it (:func:`lookahead_order`)
    whose fix leaves a mechanism (DOF >= 1: at DOF 0 no motion carries a crease anywhere)
    """
    best: dict[frozenset[int], tuple[float, Choice]] = {}
    for choice in put_off:
        locks = choice.locks
        if not len(locks) or not np.isin(choice.locked_before, locks).all():
            continue
        group = candidates[choice.index]
        left = float(np.abs(carried_angles(mechanism, group, locks, settings=settings)).max())
        key = frozenset(map(int, group)) | frozenset(locks.tolist())
        if left <= settings.generation.lookahead_carry_angle and left < best.get(key, (np.inf,))[0]:
            best[key] = (left, dataclasses.replace(choice, carried=locks, passed=()))
    ranked = sorted(best.items(), key=lambda item: (len(item[0]), item[1][0]))
    return [choice for _, (_, choice) in ranked]


def lookahead_order(
    mechanism: Mechanism,
    candidates: Sequence[Sequence[int]],
    *,
    settings: Settings = DEFAULTS,
    dof0_ends: bool = True,
    block: int = 8,
    locked_before: Mapping[tuple[int, ...], Sequence[int]] | None = None,
    rigid: Callable[[tuple[int, ...]], bool] | None = None,
    idle_last: bool = False,
) -> Iterator[Choice]:
    """The order to try ranked candidates with look-ahead: put off those predicted to lock.

    candidates : in the criterion's order (best first); dof0_ends : a fix that leaves DOF 0
    ends generation (unless ``Settings.generation.retry_zero_dof``, or a target DOF 0), so such a
    candidate is not put off although every crease locks at DOF 0. locked_before : {candidate
    (its edges, as ranked): the creases its fix locked at an earlier shape of the run}; such a
    candidate is put off too. rigid : whether a candidate's fix (its edges) is forecast to
    leave a second-order rigid shape (that shape cannot fold); such a candidate that leaves
    DOF >= 1 is put off too. idle_last : a candidate forecast to remove no mechanism (every
    crease of it still in every mode: the shape keeps its DOF) is put off too.
    yields : :class:`Choice`: first every candidate not put off, in the criterion's order,
        with ``passed``, the put-off ones ranked between it and the one before; then the
        groups of :func:`flat_groups` (a candidate with the nearly flat creases it would
        lock); then the put-off ones, alone, in the criterion's order. A put-off candidate is
        thus solved only once every other has failed, so generation with look-ahead never
        ends where it would not without (when every candidate is put off, the groups and
        then the criterion's full order).

    Lazy: the forecast (:func:`lock_forecast`) is made ``block`` candidates at a time as the
    iteration reaches them.
    """
    if block < 1:
        raise RigidfoldError(f"block must be >= 1, got {block}")
    known = locked_before or {}
    put_off: list[Choice] = []
    moving: list[Choice] = []  # put off, leaving a mechanism: a group may close one of its modes
    passed: list[Choice] = []
    for start in range(0, len(candidates), block):
        forecast = lock_forecast(mechanism, candidates[start : start + block], settings=settings)
        ends = dof0_ends & (forecast.dof_after == 0)
        for i, group in enumerate(forecast.candidates):
            before = np.asarray(known.get(tuple(map(int, group)), ()), dtype=np.int64)
            moves = bool(forecast.dof_after[i] > 0)
            stiff = rigid is not None and moves and rigid(tuple(map(int, group)))
            idle = idle_last and bool(forecast.dof_after[i] == mechanism.dof)
            choice = Choice(start + i, forecast.locks(i), before, rigid=stiff, idle=idle)
            if choice.put_off and not ends[i]:
                passed.append(choice)
                put_off.append(choice)
                if forecast.dof_after[i] > 0:
                    moving.append(choice)
            else:
                yield dataclasses.replace(choice, passed=tuple(passed))
                passed = []
    yield from flat_groups(mechanism, candidates, moving, settings=settings)
    yield from put_off
