"""The rigid-folding path of a shape: numerical continuation of its constraint manifold.

A triangulated shape folds rigidly while every edge keeps its length, every fixed crease its
fold angle, and one support triangle stays where it is (the gauge). These constraints
``c(x) = 0`` on the vertex coordinates x (3V,) leave a manifold of dimension DOF through the
design; the shape *deploys* when a path on it joins the design to the flat state (every fold
angle within ``path_flat_tol`` of 0). :func:`trace_path` follows such a path by
predictor-corrector continuation on the sparse constraint Jacobian J (Allgower & Georg,
*Introduction to Numerical Continuation Methods*, ch. 2-5):

* **DOF 1** (J has 3V - 1 independent rows): the path is the manifold itself. The tangent t
  solves the augmented system ``[J; t_prev^T] t = e``, so it keeps its orientation; the
  corrector is the chord (pseudo-arclength) iteration ``[J_k; t_k^T] dy = -[c(y); 0]`` with
  the factors of the latest iterate (self-stressed constraints, as a Miura-ori's rigid quads
  give, take the projection form of :mod:`rigidfold.mechanism.rigid_folding`). The trace
  starts in the direction that lowers the folding measure ``m = |rho_free|`` and passes the
  points where m stops falling only on its way down: it ends at the flat state; where m,
  having fallen, rises ``path_turn_back`` above its lowest (the path *turns back*: the
  shape does not deploy along it); where a crease folds to ``path_fold_limit`` (its panels
  meet); where m comes no lower for ``path_wander_steps`` steps (the path *stops short*); when
  the budget runs out; or when the step does, and then the other direction from the design is
  traced too. A sign change of ``det [J; t^T]`` is a bifurcation point, which the
  trace passes on its branch and records. Where the projection form stalls (near-singular
  values of J at its regularisation delta lose the corrections), the redundant rows are
  dropped (``path_reduce``: a basis W of the self-stresses from one dense SVD, the rows by
  a pivoted QR of W^T) and the trace goes on by the square ``[J_rows; t^T]``, unregularised,
  with a Gauss-Newton corrector: each step removes the residual's part outside the
  self-stresses and leaves the part W W^T c, spread over their rows as least squares does
  (where that stalls too, J's near flexes are held and the rows of their near self-stresses
  dropped as well; so too where a trace of n - 1 rows, none redundant, stalls after its
  dense steps past stalls).
  Every row is still met to ``path_tol``; where the least-squares residual itself exceeds
  it (a *near* self-stress, its singular value below the rank threshold but not zero,
  strains the constraints in proportion to the distance moved), no rigid folding within
  tolerance goes on and the path *stops short* there, its message says so.
* **DOF > 1** (or self-stressed constraints): the path is the one closest to the straight
  line in fold angles: each step moves along the Gauss-Newton direction d that takes the
  free fold angles rho towards 0 within the mechanism, ``min |rho + J_rho d|^2 + mu |d|^2``
  subject to ``J d = 0`` (one sparse KKT system), and the corrector is the minimum-norm chord
  iteration on the same factors. The path *stops short* where no such direction lowers m.

Each step costs one sparse LU factorisation (SuperLU through SciPy). The step length (in
mean edge lengths) grows after an easy correction, halves after a failed one, and near the
flat state is cut to the linear prediction of the closest approach, so the flat end is met
rather than passed. Lengths are kept to ``path_tol`` at every point. A trace given a
``deadline`` (the time limit of the run that asks for it) ends there, out of budget
(``max_steps``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.frame.model import default_support_face
from rigidfold.mechanism import rigid_folding
from rigidfold.mechanism.analysis import analyze
from rigidfold.mechanism.rigid_folding import (
    RigidFoldingConstraints,
    System,
    correct,
    independent_rows,
    rows_without_stresses,
)
from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome


class PathStatus(Outcome):
    """How the trace of a folding path ended."""

    FLAT = "flat", "the folding path reaches the flat state: the shape deploys"
    TURNED_BACK = (
        "turned_back",
        "the folding path turns back and returns to the design without reaching the flat state",
    )
    STOPS_SHORT = (
        "stops_short",
        "the folding path stops short of the flat state: no rigid folding goes closer to flat",
    )
    COLLISION = "collision", "a crease folds to 180 degrees (its panels meet) before the flat state"
    STALLED = "stalled", "the folding path could not be continued"
    MAX_STEPS = (
        "max_steps",
        "the trace's budget (its steps, or the run's time limit) ran out before the flat state",
    )
    RIGID = "rigid", "the shape has no mechanism (DOF 0): no folding path leaves it"


@dataclass(frozen=True, eq=False)
class FoldingPath:
    """A traced rigid-folding path, the design first.

    points : (K, V, 3) float64, shapes along the path (points[0] is the design); for a path
        that deploys, points[-1] is the flat end (every free fold angle within
        ``path_flat_tol``)
    arclength : (K,) float64, distance along the path from the design, metres
    measure : (K,) float64, folding measure m = |rho_free| of each point over the design's
    max_fold : (K,) float64, largest |fold angle| of a free crease at each point, radians
    status : PathStatus; message : what happened, in words
    dof : int, the DOF the trace worked with (1: the manifold's one path)
    closest : index of the point nearest the flat state (smallest max_fold)
    fold_at_closest : (n_free,) float64, the free creases' fold angles there, radians
    limit_points, bifurcations : indices of points where dm/ds changed sign, where
        det [J; t^T] changed sign (DOF 1)
    steps : accepted continuation steps; factorizations : sparse LU factorisations
    max_length_error : largest |l - l0| / l0 over all points and edges
    escapes : dense steps past points where the sparse continuation stalled
        (``Settings.path.escape_tol``: singular and bifurcation points)
    dropped_rows : redundant constraint rows dropped where the projection continuation of a
        1-DOF shape stalled (``Settings.path.reduce``; 0: none)
    cut : the trace was ended by its ``deadline`` (status ``max_steps``): it says nothing
        of the shape, only that the time ran out
    """

    points: np.ndarray
    arclength: np.ndarray
    measure: np.ndarray
    max_fold: np.ndarray
    status: PathStatus
    message: str
    dof: int
    closest: int
    fold_at_closest: np.ndarray
    limit_points: tuple[int, ...]
    bifurcations: tuple[int, ...]
    steps: int
    factorizations: int
    max_length_error: float
    escapes: int = 0
    dropped_rows: int = 0
    cut: bool = False

    @property
    def deploys(self) -> bool:
        """The path joins the design to the flat state."""
        return self.status is PathStatus.FLAT

    @cached_property
    def fraction(self) -> np.ndarray:
        """(K,) float64: 1 at the design, 0 at the path's far end, linear in arclength."""
        total = self.arclength[-1]
        return 1.0 - self.arclength / total if total > 0 else np.ones(len(self.arclength))

    def frames(
        self,
        pattern: CreasePattern,
        n: int,
        *,
        support_face: int | None = None,
        settings: Settings = DEFAULTS,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(frames (n, V, 3), fraction (n,)): the path at ``n`` equal steps of arclength from
        its far end (fraction 0) to the design (fraction 1), for the shape ``pattern`` it was
        traced on (with the same ``support_face``). A frame between two traced points is
        their linear interpolation corrected onto the constraints (minimum-norm chord
        steps), so every frame keeps the lengths to ``path_tol``; where that correction fails
        the nearest traced point stands in, at its own fraction."""
        n = max(int(n), 2)
        if len(self.points) == 1:
            return self.points[[0] * n], np.linspace(0.0, 1.0, n)
        if support_face is None:
            support_face = default_support_face(pattern)
        cons = RigidFoldingConstraints(pattern, support_face)
        total = float(self.arclength[-1])
        fraction = np.linspace(0.0, 1.0, n)
        frames = []
        for k, f in enumerate(fraction):
            s = (1.0 - f) * total
            i = int(np.clip(np.searchsorted(self.arclength, s), 1, len(self.arclength) - 1))
            s0, s1 = self.arclength[i - 1], self.arclength[i]
            w = 0.0 if s1 <= s0 else (s - s0) / (s1 - s0)
            if w <= 1e-12 or w >= 1 - 1e-12:
                j = i - 1 if w <= 1e-12 else i
                frames.append(self.points[j])
                continue
            guess = ((1 - w) * self.points[i - 1] + w * self.points[i]).ravel() / cons.scale
            y, ok, _, _ = correct(cons, guess, "projection", None, settings)
            if ok:
                frames.append(y.reshape(-1, 3) * cons.scale)
            else:
                j = i - 1 if w < 0.5 else i
                frames.append(self.points[j])
                fraction[k] = self.fraction[j]
        return np.asarray(frames), fraction

    def to_dict(self) -> dict:
        """JSON-ready figures of the trace (not its points)."""
        return {
            "status": self.status.value,
            "message": self.message,
            "deploys": self.deploys,
            "dof": self.dof,
            "points": len(self.points),
            "length_m": float(self.arclength[-1]),
            "steps": self.steps,
            "factorizations": self.factorizations,
            "min_measure": float(self.measure.min()),
            "closest_max_fold_deg": float(np.degrees(self.max_fold[self.closest])),
            "closest_measure": float(self.measure[self.closest]),
            "fold_at_closest_deg": np.degrees(self.fold_at_closest).round(4).tolist(),
            "limit_points": len(self.limit_points),
            "bifurcations": len(self.bifurcations),
            "max_length_error": self.max_length_error,
            "escapes": self.escapes,
            "cut": self.cut,
        }


@dataclass
class _Trace:
    """The points of one direction of the trace, as it grows."""

    points: list
    arclength: list
    measure: list
    max_fold: list
    folds: list
    limit_points: list
    bifurcations: list
    steps: int = 0
    factorizations: int = 0
    escapes: int = 0
    dropped_rows: int = 0
    cut: bool = False


def _trace_direction(
    cons: RigidFoldingConstraints,
    x0: np.ndarray,
    t0: np.ndarray | None,
    mode: str,
    m0: float,
    settings: Settings,
    deadline: float | None = None,
) -> tuple[_Trace, PathStatus, str]:
    """Continue from the design x0 (mode "augmented"/"projection": along t0; "descent": the
    Gauss-Newton direction) until the path ends (see the module's text), or until the time
    ``deadline`` (of ``time.monotonic()``) has passed."""
    J, J_rho = cons.jacobian(x0)
    rho = cons.free_angles(x0)
    tr = _Trace([x0.copy()], [0.0], [1.0], [float(np.abs(rho).max(initial=0.0))], [rho], [], [])
    flat_tol, limit = settings.path.flat_tol, settings.path.fold_limit
    system = System(J, J_rho, mode, t0, settings)
    tr.factorizations += 1
    t = t0 if mode == "descent" else system.direction(t0, rho)
    det_sign = system.factors.det_sign if mode == "augmented" else 0
    # step lengths are root-mean-square vertex displacements, in mean edge lengths
    rms = math.sqrt(cons.pattern.n_vertices)
    first, largest, least = (
        rms * v for v in (settings.path.step, settings.path.max_step, settings.path.min_step)
    )
    x, h, travelled, slope_sign, slow, escapes = x0.copy(), first, 0.0, 0, 0, 0
    rows: np.ndarray | None = None  # the independent rows, once the redundant ones are dropped
    frozen: np.ndarray | None = None  # near flexes held, once their near stresses are dropped
    near_stress = (0.0, 0.0)  # then J's near singular values over its largest (least, most)
    strained: tuple[float, float] | None = None  # the largest step since x that strains
    best = 1.0  # the smallest measure so far
    lowest = np.inf  # DOF 1: the smallest measure since m first fell
    while True:
        if tr.steps >= settings.path.max_steps:
            return tr, PathStatus.MAX_STEPS, f"no flat state after {tr.steps} steps"
        if deadline is not None and time.monotonic() > deadline:
            tr.cut = True
            return (
                tr,
                PathStatus.MAX_STEPS,
                f"the run's time limit passed after {tr.steps} steps, short of the flat state",
            )
        if mode == "descent":
            d = system.direction(None, rho)
            size = float(np.linalg.norm(d))
            if not size > least:
                return (
                    tr,
                    PathStatus.STOPS_SHORT,
                    (
                        "no rigid folding lowers the folding measure below "
                        f"{tr.measure[-1]:.3g} of the design's"
                    ),
                )
            unit, step = d / size, min(h, size)
        else:
            assert t is not None
            unit, step = t, h
        # no crease turns by more than path_max_fold_step in one step; and the step is cut at
        # the linear prediction of the closest approach to the flat state
        rate = system.J_rho @ unit
        fastest = float(np.abs(rate).max(initial=0.0))
        if fastest * step > settings.path.max_fold_step:
            step = settings.path.max_fold_step / fastest
        rr = float(rate @ rate)
        if rr > 0:
            s_star = -float(rho @ rate) / rr
            if 0 < s_star < step and np.abs(rho + s_star * rate).max() < 2 * flat_tol:
                step = max(s_star, least)
        y, ok, nf, new = correct(cons, x + step * unit, mode, t, settings, rows, frozen)
        tr.factorizations += nf
        beyond = None if ok else _beyond_tolerance(cons, y, new, settings)
        if beyond is not None and strained is None:
            strained = (step, beyond)
        if ok and mode != "descent":  # the tangent must not turn too far in one step
            chord = y - x
            ok = float(chord @ unit) > np.cos(settings.path.max_turn) * np.linalg.norm(chord)
        if not ok:
            h = step / 2
            if h >= least:
                continue
            if mode == "projection" and rows is None and _may_reduce(cons, settings):
                assert t is not None
                reduced = _reduce(cons, x, t, settings)
                tr.factorizations += 1
                if reduced is not None:  # go on by the square system of the independent rows
                    rows, system, sigma = reduced
                    near_stress = (sigma, sigma)
                    mode, t, h = "augmented", system.direction(t, rho), first
                    det_sign = system.factors.det_sign
                    tr.dropped_rows = cons.n_rows - len(rows)
                    continue
            if mode == "augmented" and rows is not None and frozen is None and beyond is None:
                assert t is not None
                held = _hold_near_flexes(cons, x, t, settings)
                tr.factorizations += 1
                if held is not None:  # go on with the near self-stresses' rows dropped too
                    rows, frozen, system, near_stress = held
                    t, h = system.direction(t, rho), first
                    det_sign = system.factors.det_sign
                    tr.dropped_rows = cons.n_rows - len(rows)
                    continue
            if beyond is not None:  # the constraints have no solution within path_tol here
                assert strained is not None
                residual = float(np.abs(cons.residual(x)).max())
                return (
                    tr,
                    PathStatus.STOPS_SHORT,
                    _strained(tr, strained, (step, beyond), near_stress, residual, rms, settings),
                )
            escaped = (
                _escape(cons, x, t, rho, first, mode, settings, rows, frozen)
                if escapes < settings.path.max_escapes
                else None
            )
            if escaped is None and mode == "augmented" and rows is None and frozen is None:
                # a trace of n - 1 rows (none redundant) past its dense steps: J's near
                # flexes are held and their near self-stresses' rows dropped, as above
                assert t is not None
                held = _hold_near_flexes(cons, x, t, settings)
                tr.factorizations += 1
                if held is not None:
                    rows, frozen, system, near_stress = held
                    t, h = system.direction(t, rho), first
                    det_sign = system.factors.det_sign
                    tr.dropped_rows = cons.n_rows - len(rows)
                    continue
            if escaped is None:
                return (
                    tr,
                    PathStatus.STALLED,
                    (
                        f"the step fell below {settings.path.min_step:g} mean edge lengths at "
                        f"m = {tr.measure[-1]:.3g} of the design's"
                        + (f" ({escapes} dense steps past stalls)" if escapes else "")
                        + _stall_reason(cons, y, new, mode, settings)
                    ),
                )
            y, t, new, mode = escaped
            if new.rows is not None and rows is None:
                rows, tr.dropped_rows = new.rows, cons.n_rows - len(new.rows)
            escapes, step, nf = escapes + 1, first, 1
            tr.escapes += 1
        assert new is not None
        rho_y = cons.free_angles(y)
        fold_max = float(np.abs(rho_y).max(initial=0.0))
        if fold_max >= limit:
            return (
                tr,
                PathStatus.COLLISION,
                (
                    f"crease {int(cons.free[np.argmax(np.abs(rho_y))])} folds to "
                    f"{np.degrees(fold_max):.1f} degrees at m = "
                    f"{np.linalg.norm(rho_y) / m0:.3g} of the design's"
                ),
            )
        travelled += float(np.linalg.norm(y - x))
        strained = None
        x, rho, system = y, rho_y, new
        if mode != "descent":
            t = system.direction(t, rho)
        tr.steps += 1
        m = float(np.linalg.norm(rho)) / m0
        slope = int(np.sign(m - tr.measure[-1]))
        if slope_sign and slope and slope != slope_sign:
            tr.limit_points.append(len(tr.points) - 1)
        slope_sign = slope or slope_sign
        if mode == "augmented":
            sign = system.factors.det_sign
            if sign != det_sign:
                tr.bifurcations.append(len(tr.points))
                det_sign = sign
        slow = slow + 1 if m > best * (1 - settings.path.stall_ratio) else 0
        best = min(best, m)
        tr.points.append(x.copy())
        tr.arclength.append(travelled)
        tr.measure.append(m)
        tr.max_fold.append(fold_max)
        tr.folds.append(rho)
        if fold_max <= flat_tol:
            return (
                tr,
                PathStatus.FLAT,
                (
                    f"every fold angle below {np.degrees(flat_tol):.2g} degrees after {tr.steps} "
                    f"steps ({travelled * cons.scale:.3g} m of path)"
                ),
            )
        if slow >= (settings.path.stall_steps if mode == "descent" else settings.path.wander_steps):
            return (
                tr,
                PathStatus.STOPS_SHORT,
                (
                    f"no rigid folding lowers the folding measure below {best:.3g} of the "
                    f"design's (none in the last {slow} steps)"
                ),
            )
        if mode != "descent":
            if slope < 0:  # m falls: from here on a rise of path_turn_back is a turn back
                lowest = min(lowest, m)
            elif m > lowest + settings.path.turn_back:
                k = int(np.argmin(tr.measure))
                return (
                    tr,
                    PathStatus.TURNED_BACK,
                    (
                        f"the path turns back at m = {tr.measure[k]:.3g} of the design's (largest "
                        f"fold angle there {np.degrees(tr.max_fold[k]):.3g} degrees)"
                    ),
                )
        h = min(2 * step, largest) if nf == 1 else step


def _escape(
    cons: RigidFoldingConstraints,
    x: np.ndarray,
    t: np.ndarray | None,
    rho: np.ndarray,
    first: float,
    mode: str,
    settings: Settings,
    rows: np.ndarray | None = None,
    frozen: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, System, str] | None:
    """One step past the point x where the sparse continuation stalled (see
    ``Settings.path.escape_tol``): the null space N of J at x from a dense SVD; the
    directions tried are the last tangent's part in N (the branch continued), where N has
    two or more columns the branches of the bifurcation equation in the plane of J's two
    smallest singular vectors, the path's and its nearest flex (see :func:`_branches`:
    branch switching), and the part of the steepest descent of the folding measure (a branch
    towards flat); each step of ``first``, a quarter, a sixteenth. A 1-DOF trace corrects it
    by the square system ``[J_rows; d^T]`` of the independent rows (dropped here if the
    constraints are self-stressed and ``rows`` is None) with the Gauss-Newton corrector of
    :func:`rigidfold.mechanism.rigid_folding.correct`; a trace of more DOF by Gauss-Newton
    with the pseudo-inverse truncated at ``mechanism_rank_tol``; until every constraint
    holds to ``path_tol``. Returns (the point, its direction, the factored system there, the
    mode: "projection" where the augmented matrix is singular), or None (no step converged,
    or more than ``mechanism_second_order_vertices`` vertices)."""
    if cons.pattern.n_vertices > settings.mechanism.second_order_vertices:
        return None
    J, J_rho = cons.jacobian(x)
    U, s, vt = np.linalg.svd(J.toarray(), full_matrices=True)
    values = np.zeros(cons.n)
    values[: len(s)] = s
    small = values <= settings.path.escape_tol * values[0]
    N = vt[small].T
    if not N.shape[1]:
        return None
    square = mode != "descent"
    tries = [] if t is None else [N @ (N.T @ t)]
    if square and N.shape[1] >= 2:
        # the plane of the two smallest singular values (the path's and a near flex)
        plane = vt[cons.n - 2 :].T
        stresses = np.hstack([U[:, : len(s)][:, small[: len(s)]], U[:, len(s) :]])
        tries += _branches(cons, x, plane, stresses, rho, settings)
    tries.append(N @ (N.T @ -(J_rho.T @ rho)))
    if square and rows is None and cons.n_rows > cons.n - 1:
        rows = rows_without_stresses(U, cons.n, 1)
    wide = settings.with_(path_corrector_iter=3 * settings.path.corrector_iter)
    done: list[np.ndarray] = []
    for d in tries:
        size = float(np.linalg.norm(d))
        if not size > 0:
            continue
        d = d / size
        if any(float(d @ e) > math.cos(settings.path.max_turn) for e in done):
            continue  # tried already
        done.append(d)
        for h in (first, first / 4, first / 16):
            if square:
                # the module's corrector (the continuation's, ``correct``, may be swapped)
                y, ok, _, system = rigid_folding.correct(
                    cons, x + h * d, "augmented", d, wide, rows, frozen
                )
                if ok and system is not None and float((y - x) @ d) > 0.5 * h:
                    return y, d, system, "augmented"
                continue
            y = x + h * d
            for _ in range(3 * settings.path.corrector_iter):
                c = cons.residual(y)
                if not np.isfinite(c).all():
                    break
                if float(np.abs(c).max()) <= settings.path.tol:
                    chord = y - x
                    if float(chord @ d) <= 0.5 * h:  # slid back towards x
                        break
                    Jy, Jy_rho = cons.jacobian(y)
                    for kind in (mode, "projection"):
                        try:
                            return y, d, System(Jy, Jy_rho, kind, d, settings, rows), kind
                        except RuntimeError:  # an exactly singular augmented matrix
                            continue
                    return None
                A = np.vstack([cons.jacobian(y)[0].toarray(), d])
                dy = np.linalg.lstsq(A, np.r_[-c, 0.0], rcond=settings.mechanism.rank_tol)[0]
                y = y + dy
    return None


def _branches(
    cons: RigidFoldingConstraints,
    x: np.ndarray,
    N: np.ndarray,
    W: np.ndarray,
    rho: np.ndarray,
    settings: Settings,
) -> list[np.ndarray]:
    """Branch directions (n,) at a simple bifurcation point x: N (n, 2) spans the null space
    of J there, W (m, k) its (near) self-stresses; a branch leaves x along d in N with
    ``w^T c''(d, d) = 0`` for every stress w (the algebraic bifurcation equation, Allgower &
    Georg ch. 8), c'' by central differences of J along N (step sqrt(``path_tol``), so that
    its error is of the order of the tolerance). The roots are the deepest minima of the sum
    of squares over half a circle of directions (a degree apart); each is returned with both
    signs, those that lower the folding measure first."""
    eps = math.sqrt(settings.path.tol)
    D = []
    for j in range(2):
        Jp = cons.jacobian(x + eps * N[:, j])[0]
        Jm = cons.jacobian(x - eps * N[:, j])[0]
        D.append(W.T @ ((Jp - Jm) @ N) / (2 * eps))  # (k, 2): w^T c''(n_i, n_j)
    Q = np.stack([np.column_stack([D[0][:, i], D[1][:, i]]) for i in range(2)], axis=1)
    Q = (Q + Q.transpose(0, 2, 1)) / 2  # (k, 2, 2)
    theta = np.radians(np.arange(180.0))
    a = np.stack([np.cos(theta), np.sin(theta)])  # (2, 180)
    f = (np.einsum("ia,kij,ja->ka", a, Q, a) ** 2).sum(axis=0)
    minima = np.flatnonzero((f <= np.roll(f, 1)) & (f <= np.roll(f, -1)))
    best = minima[np.argsort(f[minima])][:2]
    out = [sign * (N @ a[:, i]) for i in best for sign in (1.0, -1.0)]
    J_rho = cons.jacobian(x)[1]
    return sorted(out, key=lambda d: float(rho @ (J_rho @ d)))


def _may_reduce(cons: RigidFoldingConstraints, settings: Settings) -> bool:
    """The redundant rows of a 1-DOF shape are dropped where its projection continuation
    stalls (``path_reduce``), up to ``mechanism_second_order_vertices`` vertices (one dense
    SVD)."""
    return (
        settings.path.reduce and cons.pattern.n_vertices <= settings.mechanism.second_order_vertices
    )


def _reduce(
    cons: RigidFoldingConstraints, x: np.ndarray, t: np.ndarray, settings: Settings
) -> tuple[np.ndarray, System, float] | None:
    """(rows (n - 1,) int, the factored ``[J_rows; t^T]`` at x, J's smallest singular value
    over its largest there): the independent rows of the constraints of a 1-DOF shape at x
    (:func:`rigidfold.mechanism.rigid_folding.independent_rows`) and the square augmented
    system they make with the tangent t (n,); None where it is exactly singular."""
    rows, sigma = independent_rows(cons.jacobian(x)[0], 1)
    try:
        return rows, System(*cons.jacobian(x), "augmented", t, settings, rows), sigma
    except RuntimeError:
        return None


def _hold_near_flexes(
    cons: RigidFoldingConstraints, x: np.ndarray, t: np.ndarray, settings: Settings
) -> tuple[np.ndarray, np.ndarray, System, tuple[float, float]] | None:
    """Where the square system of the independent rows stalls too, at x: J's near flexes
    there (right singular vectors of singular values below ``path_escape_tol`` of the
    largest, but for the smallest, the path's own) are held, ``frozen`` (n, k), and the rows
    of their near self-stresses dropped as well (``[J_rows; frozen^T; t^T]`` square): their
    residual is then left to the Gauss-Newton corrector's least squares and checked
    against ``path_tol`` like that of the exact self-stresses, rather than removed by
    moves of residual / sigma along the near flexes, which Newton's method cannot make.
    Returns (rows, frozen, the factored system at x, (the smallest, the largest) of those
    singular values over the largest one), or None (no near flex, an exactly singular
    system, or more than ``mechanism_second_order_vertices`` vertices)."""
    if cons.pattern.n_vertices > settings.mechanism.second_order_vertices:
        return None
    J, J_rho = cons.jacobian(x)
    U, s, vt = np.linalg.svd(J.toarray(), full_matrices=True)
    values = np.zeros(cons.n)  # J's n singular values: zeros past the m of a J of m < n rows
    values[: min(len(s), cons.n)] = s[: cons.n]
    near = np.flatnonzero(values[:-1] <= settings.path.escape_tol * values[0])
    if not len(near):
        return None
    frozen = vt[near].T
    rows = rows_without_stresses(U, cons.n, 1 + len(near))
    try:
        system = System(J, J_rho, "augmented", t, settings, rows, frozen)
    except RuntimeError:
        return None
    return (
        rows,
        frozen,
        system,
        (float(values[near].min() / s[0]), float(values[near].max() / s[0])),
    )


def _strained(
    tr: _Trace,
    first: tuple[float, float],
    last: tuple[float, float],
    near_stress: tuple[float, float],
    residual: float,
    rms: float,
    settings: Settings,
) -> str:
    """The message of a path that stops short where every step leaves a least-squares
    residual above ``path_tol``: ``first`` and ``last`` (step, residual) the largest and the
    smallest step tried from the last point (steps in rms vertex displacements, ``rms`` one
    mean edge length of them), ``near_stress`` the near singular values (least, most) whose
    self-stresses' rows were dropped, ``residual`` the largest |c| at the last point."""
    lo, hi = near_stress
    values = f"singular value {hi:.2g}" if lo == hi else f"singular values {lo:.2g} to {hi:.2g}"
    steps = f"a step of {last[0] / rms:.2g} mean edge lengths leaves a least-squares residual of"
    if first[0] > last[0]:
        steps = (
            f"a step of {first[0] / rms:.2g} mean edge lengths leaves a least-squares residual "
            f"of {first[1]:.2g}, one of {last[0] / rms:.2g} still"
        )
    return (
        f"no rigid folding within path_tol ({settings.path.tol:g}) goes on from "
        f"m = {tr.measure[-1]:.3g} of the design's: {steps} {last[1]:.2g} in the constraints' "
        f"near self-stress ({values} of the largest; the last point's residual "
        f"{residual:.2g}), which no correction removes: the shape moves on only by straining "
        "its panels"
    )


def _beyond_tolerance(
    cons: RigidFoldingConstraints, y: np.ndarray, system: System | None, settings: Settings
) -> float | None:
    """Where the corrector failed at y with the square system of the independent rows: the
    largest residual left (a float) when its correctable part is within ``path_tol`` and
    the rest, the part in the self-stresses of the rows dropped, is not: Gauss-Newton has
    reached the least-squares point of the constraints, and it is not within tolerance.
    None otherwise (the corrector failed for another reason)."""
    if system is None or system.stresses is None:
        return None
    c = cons.residual(y)
    norm = float(np.abs(c).max())
    if not np.isfinite(norm) or norm <= settings.path.tol:
        return None
    return norm if system.reducible_norm(c) <= settings.path.tol else None


def _stall_reason(
    cons: RigidFoldingConstraints,
    y: np.ndarray,
    system: System | None,
    mode: str,
    settings: Settings,
) -> str:
    """What the corrector's last failed attempt left at y: the residual, and (with the
    square system of the independent rows) how much of it a correction could remove."""
    c = np.abs(cons.residual(y))
    if not np.isfinite(c).all():
        return ": the corrector diverged (a triangle collapsed)"
    where = f"{mode} system"
    if system is not None and system.stresses is not None:
        where += f", {system.reducible_norm(c):.1e} of it correctable: a singular point"
    return f": the corrector's residual stayed at {c.max():.1e} ({where})"


def trace_path(
    pattern: CreasePattern,
    *,
    dof: int | None = None,
    support_face: int | None = None,
    settings: Settings = DEFAULTS,
    deadline: float | None = None,
) -> FoldingPath:
    """Trace the rigid-folding path of ``pattern`` from the design towards the flat state.

    dof : the shape's DOF where known; default that of :func:`rigidfold.mechanism.analyze`
        (with ``support_face``). ``support_face``: the gauge triangle (default
        :func:`rigidfold.frame.model.default_support_face`). ``deadline``: a time of
        ``time.monotonic()`` after which the trace ends, ``max_steps`` (a run's time limit).
        See the module's text.
    """
    if support_face is None:
        support_face = default_support_face(pattern)
    cons = RigidFoldingConstraints(pattern, support_face)
    if dof is None:
        dof = analyze(pattern, support_face=support_face, settings=settings).dof
    x0 = cons.x0.copy()
    J, J_rho = cons.jacobian(x0)
    rho = cons.free_angles(x0)
    m0 = float(np.linalg.norm(rho))
    if dof <= 0:
        return _result(
            cons,
            [_single(cons, x0, rho)],
            PathStatus.RIGID,
            PathStatus.RIGID.message,
            max(dof, 0),
            m0,
        )
    if m0 == 0 or np.abs(rho).max() <= settings.path.flat_tol:
        return _result(
            cons,
            [_single(cons, x0, rho)],
            PathStatus.FLAT,
            "the shape is flat already",
            dof,
            m0 or 1.0,
        )
    if dof == 1:
        mode = "augmented" if cons.n_rows == cons.n - 1 else "projection"
        t = _first_tangent(J, J_rho, rho, settings)
        traces = []
        for sign in (1.0, -1.0):
            try:
                tr, status, message = _trace_direction(
                    cons, x0, sign * t, mode, m0, settings, deadline
                )
            except RuntimeError:  # the augmented matrix is singular at the design
                mode = "projection"
                tr, status, message = _trace_direction(
                    cons, x0, sign * t, mode, m0, settings, deadline
                )
            traces.append((tr, status, message))
            if status is not PathStatus.STALLED:
                break
        best = next((r for r in traces if r[1] is PathStatus.FLAT), traces[0])
        tr, status, message = best
        if len(traces) == 2 and best is traces[1]:
            message += " (in the direction that first folds further)"
        k = int(np.argmin(tr.measure))
        if status not in (PathStatus.FLAT, PathStatus.TURNED_BACK) and k < len(tr.measure) - 1:
            status, message = (
                PathStatus.TURNED_BACK,
                (
                    f"the path turns back at m = {tr.measure[k]:.3g} of the design's (largest fold "
                    f"angle there {np.degrees(tr.max_fold[k]):.3g} degrees); then {message}"
                ),
            )
        factorizations = sum(t[0].factorizations for t in traces)
        return _result(cons, [tr], status, message, 1, m0, factorizations)
    tr, status, message = _trace_direction(cons, x0, None, "descent", m0, settings, deadline)
    return _result(cons, [tr], status, message, dof, m0)


def _first_tangent(
    J: sp.csc_matrix, J_rho: sp.csr_matrix, rho: np.ndarray, settings: Settings
) -> np.ndarray:
    """The unit tangent of a 1-DOF manifold at the design, oriented to lower m first: the
    projection of -grad(m^2 / 2) onto the null space of J."""
    t = System(J, J_rho, "projection", None, settings).direction(-(J_rho.T @ rho), rho)
    if not np.isfinite(t).all():
        raise RigidfoldError("the shape's folding path has no tangent at the design")
    return t


def _single(cons: RigidFoldingConstraints, x: np.ndarray, rho: np.ndarray) -> _Trace:
    return _Trace([x.copy()], [0.0], [1.0], [float(np.abs(rho).max(initial=0.0))], [rho], [], [])


def _result(
    cons: RigidFoldingConstraints,
    traces: list[_Trace],
    status: PathStatus,
    message: str,
    dof: int,
    m0: float,
    factorizations: int | None = None,
) -> FoldingPath:
    tr = traces[0]
    V = cons.pattern.n_vertices
    points = np.asarray(tr.points).reshape(-1, V, 3) * cons.scale
    max_fold = np.asarray(tr.max_fold)
    closest = int(np.argmin(max_fold))
    error = max(cons.length_error(p) for p in np.asarray(tr.points))
    return FoldingPath(
        points=points,
        arclength=np.asarray(tr.arclength) * cons.scale,
        measure=np.asarray(tr.measure),
        max_fold=max_fold,
        status=status,
        message=message,
        dof=dof,
        closest=closest,
        fold_at_closest=np.asarray(tr.folds[closest]),
        limit_points=tuple(tr.limit_points),
        bifurcations=tuple(tr.bifurcations),
        steps=sum(t.steps for t in traces),
        factorizations=(
            sum(t.factorizations for t in traces) if factorizations is None else factorizations
        ),
        max_length_error=error,
        escapes=sum(t.escapes for t in traces),
        dropped_rows=max(t.dropped_rows for t in traces),
        cut=any(t.cut for t in traces),
    )
