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
  shape does not deploy along it); where a crease folds to ``path_collision_angle`` (its panels
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
  iteration on the same factors. The path *stops short* where no such direction lowers m,
  and ends out of budget where it creeps: where, at the fall of m over its last
  ``path_pace_steps`` steps, the flat state lies more than ``path_pace_margin`` times the
  steps left away.

Each step costs one sparse LU factorisation (SuperLU through SciPy). The step length (in
mean edge lengths) grows after an easy correction, halves after a failed one, and near the
flat state is cut to the linear prediction of the closest approach, so the flat end is met
rather than passed. Lengths are kept to ``path_tol`` at every point. A trace given a
``deadline`` (the time limit of the run that asks for it) ends there, out of budget
(``max_steps``).

In the code, each direction of a trace is a ``_Tracer`` whose :class:`Mode` (augmented,
projection, descent) says which system it steps by; its steps are *predict*, *correct*,
*accept* with *end* (has the path ended at the new point?), and, where the step has
fallen below ``path_min_step``, *recover* (:mod:`rigidfold.mechanism.recovery`: rows
dropped, near flexes held, a dense step past the point).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.frame.model import default_support_face
from rigidfold.mechanism.analysis import analyze
from rigidfold.mechanism.recovery import escape, hold_near_flexes, may_reduce, reduce_rows
from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints, System, correct
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


class Mode(StrEnum):
    """How the tracer predicts and corrects a step (see the module's text)."""

    AUGMENTED = "augmented"
    """DOF 1: the tangent and the pseudo-arclength corrector of the square ``[J; t^T]`` (or
    ``[J_rows; t^T]`` of the independent rows, once the redundant ones are dropped)."""
    PROJECTION = "projection"
    """DOF 1 with self-stressed constraints: the tangent and the corrector in the
    regularised projection form."""
    DESCENT = "descent"
    """DOF > 1: the Gauss-Newton direction towards flat within the mechanism, and the
    minimum-norm corrector."""


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

    @classmethod
    def start(cls, x: np.ndarray, rho: np.ndarray) -> _Trace:
        """The trace of the one point x (n,), the design, with free fold angles rho."""
        return cls([x.copy()], [0.0], [1.0], [float(np.abs(rho).max(initial=0.0))], [rho], [], [])


@dataclass(frozen=True)
class _End:
    """How and why the trace of a direction ended."""

    status: PathStatus
    message: str


@dataclass(frozen=True)
class _Step:
    """A step tried from the tracer's point x.

    y : (n,) the corrected point; ok : it is on the constraints to ``path_tol`` (and, DOF 1,
    its chord within ``path_max_turn`` of the tangent); length : the step predicted (rms
    vertex displacement); factorizations : those the corrector made (1: an easy step, the
    next may grow); system : the corrector's last factored system (at y where ok);
    beyond : where the corrector failed with the independent rows because the constraints
    have no solution within ``path_tol`` there, the least-squares residual left, else None.
    """

    y: np.ndarray
    ok: bool
    length: float
    factorizations: int
    system: System | None
    beyond: float | None = None


class _Tracer:
    """One direction of the trace from the design x0: the continuation's state and its steps.

    :meth:`run` repeats :meth:`predict` (the step along the tangent t, or along the descent
    direction), :meth:`correct` (back onto c = 0) and :meth:`accept` (the new point, and
    :meth:`end`: has the path ended there?); a step that fails is halved, and where it falls
    below ``path_min_step``, :meth:`recover` changes the system (rows dropped, near flexes
    held: :mod:`rigidfold.mechanism.recovery`), takes a dense step past the point, or ends
    the trace. Lengths are in the constraints' scale (``cons.scale``); step lengths are
    root-mean-square vertex displacements (``rms``: one mean edge length of them).
    """

    def __init__(
        self,
        cons: RigidFoldingConstraints,
        x0: np.ndarray,
        t0: np.ndarray | None,
        mode: Mode,
        m0: float,
        settings: Settings,
        deadline: float | None,
    ) -> None:
        self.cons, self.m0, self.settings, self.deadline = cons, m0, settings, deadline
        self.mode = mode
        J, J_rho = cons.jacobian(x0)
        self.rho = cons.free_angles(x0)  # the free fold angles at x
        self.trace = _Trace.start(x0, self.rho)
        self.system = System(J, J_rho, mode.value, t0, settings)  # factored at x
        self.trace.factorizations += 1
        self.t = t0 if mode is Mode.DESCENT else self.system.direction(t0, self.rho)
        self.det_sign = self.system.factors.det_sign if mode is Mode.AUGMENTED else 0
        self.rms = math.sqrt(cons.pattern.n_vertices)
        self.first, self.largest, self.least = (
            self.rms * v
            for v in (settings.path.step, settings.path.max_step, settings.path.min_step)
        )
        self.x, self.h, self.travelled = x0.copy(), self.first, 0.0  # point, step, arclength
        self.slope_sign = 0  # the sign of dm/ds, last it was not 0
        self.slow = 0  # steps since m last fell by path_stall_ratio below its best
        self.rows: np.ndarray | None = None  # the independent rows, once the others dropped
        self.frozen: np.ndarray | None = None  # near flexes held, once their stresses dropped
        self.near_stress = (0.0, 0.0)  # then J's near singular values over its largest
        self.strained: tuple[float, float] | None = None  # the largest step since x (step,
        # residual) that left a least-squares residual above path_tol
        self.best = 1.0  # the smallest measure so far
        self.lowest = np.inf  # DOF 1: the smallest measure since m first fell

    def run(self) -> tuple[_Trace, PathStatus, str]:
        """Step until the path ends: (its points, how it ended, why in words)."""
        while True:
            prediction = self.out_of_budget() or self.predict()
            if isinstance(prediction, _End):
                return self.trace, prediction.status, prediction.message
            step = self.correct(*prediction)
            if not step.ok:
                self.h = step.length / 2
                if self.h >= self.least:
                    continue  # a shorter step from x
                recovered = self.recover(step)
                if recovered is None:
                    continue  # a new system at x: a step of ``first`` from there
                if isinstance(recovered, _End):
                    return self.trace, recovered.status, recovered.message
                step = recovered
            end = self.accept(step)
            if end is not None:
                return self.trace, end.status, end.message
            self.h = min(2 * step.length, self.largest) if step.factorizations == 1 else step.length

    def out_of_pace(self) -> _End | None:
        """A descent (DOF > 1) that creeps ends out of budget: where, at the fall of the
        folding measure over the last ``path_pace_steps`` steps, the flat state lies more
        than ``path_pace_margin`` times the steps left of ``path_max_steps`` away (a descent's
        measure falls at every step, else it stalls, so its pace is positive)."""
        settings, tr = self.settings.path, self.trace
        window = settings.pace_steps
        if tr.steps < window:
            return None
        m = tr.measure[-1]
        fallen = tr.measure[-1 - window] - m
        left = settings.max_steps - tr.steps
        if m * window <= settings.pace_margin * left * fallen:
            return None
        return _End(
            PathStatus.MAX_STEPS,
            f"at its pace (the folding measure down {fallen / window:.2g} of the design's a "
            f"step over the last {window}), the flat state is beyond the {left} steps left "
            f"after {tr.steps} (m = {m:.3g})",
        )

    def out_of_budget(self) -> _End | None:
        """The end of a trace that has taken ``path_max_steps`` steps or passed its deadline."""
        tr = self.trace
        if tr.steps >= self.settings.path.max_steps:
            return _End(PathStatus.MAX_STEPS, f"no flat state after {tr.steps} steps")
        if self.deadline is not None and time.monotonic() > self.deadline:
            tr.cut = True
            return _End(
                PathStatus.MAX_STEPS,
                f"the run's time limit passed after {tr.steps} steps, short of the flat state",
            )
        return None

    def predict(self) -> tuple[np.ndarray, float] | _End:
        """(the unit direction (n,), the step length) of the next step from x: along the
        tangent (DOF 1) or the descent direction, h long at most; no crease turns by more than
        ``path_max_fold_step`` in it, and it is cut at the linear prediction of the closest
        approach to the flat state. A descent that no longer lowers m ends the trace."""
        settings, rho = self.settings.path, self.rho
        if self.mode is Mode.DESCENT:
            d = self.system.direction(None, rho)
            size = float(np.linalg.norm(d))
            if not size > self.least:
                return _End(
                    PathStatus.STOPS_SHORT,
                    "no rigid folding lowers the folding measure below "
                    f"{self.trace.measure[-1]:.3g} of the design's",
                )
            unit, step = d / size, min(self.h, size)
        else:
            assert self.t is not None
            unit, step = self.t, self.h
        rate = self.system.J_rho @ unit
        fastest = float(np.abs(rate).max(initial=0.0))
        if fastest * step > settings.max_fold_step:
            step = settings.max_fold_step / fastest
        rr = float(rate @ rate)
        if rr > 0:
            s_star = -float(rho @ rate) / rr
            if 0 < s_star < step and np.abs(rho + s_star * rate).max() < 2 * settings.flat_tol:
                step = max(s_star, self.least)
        return unit, step

    def correct(self, unit: np.ndarray, length: float) -> _Step:
        """The prediction x + length * unit corrected onto the constraints (the module's
        ``correct``: chord steps on the current mode's system)."""
        y, ok, nf, system = correct(
            self.cons,
            self.x + length * unit,
            self.mode.value,
            self.t,
            self.settings,
            self.rows,
            self.frozen,
            most=self.settings.path.corrector_factorizations,
        )
        self.trace.factorizations += nf
        beyond = None if ok else _beyond_tolerance(self.cons, y, system, self.settings)
        if beyond is not None and self.strained is None:
            self.strained = (length, beyond)
        if ok and self.mode is not Mode.DESCENT:  # the tangent must not turn too far in one step
            chord = y - self.x
            ok = float(chord @ unit) > np.cos(self.settings.path.max_turn) * np.linalg.norm(chord)
        return _Step(y, ok, length, nf, system, beyond)

    def recover(self, failed: _Step) -> _Step | _End | None:
        """Where the step has fallen below ``path_min_step`` at x (``failed`` the last one
        tried): None where the trace goes on from x with a new system (a 1-DOF projection
        trace with the redundant rows dropped; a trace of the independent rows with J's near
        flexes held as well); the point of a dense step past x; or the end of the trace,
        where the constraints have no solution within ``path_tol`` (stops short) or nothing
        goes on (stalled)."""
        cons, settings, tr = self.cons, self.settings, self.trace
        late = self.out_of_budget()  # each way on below is a dense factorisation or more
        if late is not None:
            return late
        if self.mode is Mode.PROJECTION and self.rows is None and may_reduce(cons, settings):
            assert self.t is not None
            reduced = reduce_rows(cons, self.x, self.t, settings)
            tr.factorizations += 1
            if reduced is not None:  # go on by the square system of the independent rows
                rows, system, sigma = reduced
                self.near_stress = (sigma, sigma)
                self.mode = Mode.AUGMENTED
                self._go_on(rows, system)
                return None
        held = self.mode is Mode.AUGMENTED and self.rows is not None and self.frozen is None
        if held and failed.beyond is None and self._hold_near_flexes():
            return None  # go on with the near self-stresses' rows dropped too
        if failed.beyond is not None:  # the constraints have no solution within path_tol here
            assert self.strained is not None
            residual = float(np.abs(cons.residual(self.x)).max())
            last = (failed.length, failed.beyond)
            return _End(
                PathStatus.STOPS_SHORT,
                _strained(tr, self.strained, last, self.near_stress, residual, self.rms, settings),
            )
        escaped = (
            escape(
                cons,
                self.x,
                self.t,
                self.rho,
                self.first,
                self.mode.value,
                settings,
                self.rows,
                self.frozen,
                self.deadline,
            )
            if tr.escapes < settings.path.max_escapes
            else None
        )
        late = self.out_of_budget()
        if late is not None:
            return late  # the escape was cut by the deadline: no verdict
        if escaped is None:
            if self.mode is Mode.AUGMENTED and self.rows is None and self.frozen is None:
                # a trace of n - 1 rows (none redundant) past its dense steps: J's near
                # flexes are held and their near self-stresses' rows dropped, as above
                if self._hold_near_flexes():
                    return None
            return _End(
                PathStatus.STALLED,
                f"the step fell below {settings.path.min_step:g} mean edge lengths at "
                f"m = {tr.measure[-1]:.3g} of the design's"
                + (f" ({tr.escapes} dense steps past stalls)" if tr.escapes else "")
                + _stall_reason(cons, failed.y, failed.system, self.mode.value, settings),
            )
        y, self.t, system, mode = escaped
        self.mode = Mode(mode)
        if system.rows is not None and self.rows is None:
            self.rows, tr.dropped_rows = system.rows, cons.n_rows - len(system.rows)
        tr.escapes += 1
        return _Step(y, True, self.first, 1, system)

    def _hold_near_flexes(self) -> bool:
        """Hold J's near flexes at x and drop their near self-stresses' rows
        (:func:`rigidfold.mechanism.recovery.hold_near_flexes`); False where there are none."""
        assert self.t is not None
        held = hold_near_flexes(self.cons, self.x, self.t, self.settings)
        self.trace.factorizations += 1
        if held is None:
            return False
        rows, self.frozen, system, self.near_stress = held
        self._go_on(rows, system)
        return True

    def _go_on(self, rows: np.ndarray, system: System) -> None:
        """Continue from x by ``system``, the square system of the constraints' ``rows``:
        its tangent, its determinant's sign, and a first step again."""
        self.rows, self.system = rows, system
        self.t, self.h = system.direction(self.t, self.rho), self.first
        self.det_sign = system.factors.det_sign
        self.trace.dropped_rows = self.cons.n_rows - len(rows)

    def accept(self, step: _Step) -> _End | None:
        """Move to the corrected point of ``step`` and record it (limit points where dm/ds
        changed sign, bifurcations where det [J; t^T] did), then :meth:`end`; a point where a
        crease folds to ``path_collision_angle`` (its panels meet) ends the trace unrecorded."""
        cons, tr = self.cons, self.trace
        assert step.system is not None
        rho = cons.free_angles(step.y)
        fold_max = float(np.abs(rho).max(initial=0.0))
        if fold_max >= self.settings.path.collision_angle:
            return _End(
                PathStatus.COLLISION,
                f"crease {int(cons.free[np.argmax(np.abs(rho))])} folds to "
                f"{np.degrees(fold_max):.1f} degrees at m = "
                f"{np.linalg.norm(rho) / self.m0:.3g} of the design's",
            )
        self.travelled += float(np.linalg.norm(step.y - self.x))
        self.strained = None
        self.x, self.rho, self.system = step.y, rho, step.system
        if self.mode is not Mode.DESCENT:
            self.t = self.system.direction(self.t, self.rho)
        tr.steps += 1
        m = float(np.linalg.norm(self.rho)) / self.m0
        slope = int(np.sign(m - tr.measure[-1]))
        if self.slope_sign and slope and slope != self.slope_sign:
            tr.limit_points.append(len(tr.points) - 1)
        self.slope_sign = slope or self.slope_sign
        if self.mode is Mode.AUGMENTED:
            sign = self.system.factors.det_sign
            if sign != self.det_sign:
                tr.bifurcations.append(len(tr.points))
                self.det_sign = sign
        self.slow = self.slow + 1 if m > self.best * (1 - self.settings.path.stall_ratio) else 0
        self.best = min(self.best, m)
        tr.points.append(self.x.copy())
        tr.arclength.append(self.travelled)
        tr.measure.append(m)
        tr.max_fold.append(fold_max)
        tr.folds.append(self.rho)
        return self.end(slope)

    def end(self, slope: int) -> _End | None:
        """Whether the path ends at the point just recorded (``slope`` the sign of dm/ds on
        the way to it): flat; stops short (m came no lower for ``path_wander_steps``, for a
        descent ``path_stall_steps``, steps); a descent out of pace (:meth:`out_of_pace`); or
        turned back (DOF 1: m, having fallen, rose ``path_turn_back`` above its lowest)."""
        settings, tr = self.settings.path, self.trace
        m, fold_max = tr.measure[-1], tr.max_fold[-1]
        if fold_max <= settings.flat_tol:
            return _End(
                PathStatus.FLAT,
                f"every fold angle below {np.degrees(settings.flat_tol):.2g} degrees after "
                f"{tr.steps} steps ({self.travelled * self.cons.scale:.3g} m of path)",
            )
        patience = settings.stall_steps if self.mode is Mode.DESCENT else settings.wander_steps
        if self.slow >= patience:
            return _End(
                PathStatus.STOPS_SHORT,
                f"no rigid folding lowers the folding measure below {self.best:.3g} of the "
                f"design's (none in the last {self.slow} steps)",
            )
        if self.mode is Mode.DESCENT:
            return self.out_of_pace()
        if slope < 0:  # m falls: from here on a rise of path_turn_back is a turn back
            self.lowest = min(self.lowest, m)
        elif m > self.lowest + settings.turn_back:
            k = int(np.argmin(tr.measure))
            return _End(
                PathStatus.TURNED_BACK,
                f"the path turns back at m = {tr.measure[k]:.3g} of the design's (largest "
                f"fold angle there {np.degrees(tr.max_fold[k]):.3g} degrees)",
            )
        return None


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
            [_Trace.start(x0, rho)],
            PathStatus.RIGID,
            PathStatus.RIGID.message,
            max(dof, 0),
            m0,
        )
    if m0 == 0 or np.abs(rho).max() <= settings.path.flat_tol:
        return _result(
            cons,
            [_Trace.start(x0, rho)],
            PathStatus.FLAT,
            "the shape is flat already",
            dof,
            m0 or 1.0,
        )
    if dof == 1:
        mode = Mode.AUGMENTED if cons.n_rows == cons.n - 1 else Mode.PROJECTION
        t = _first_tangent(J, J_rho, rho, settings)
        traces = []
        for sign in (1.0, -1.0):
            try:
                tracer = _Tracer(cons, x0, sign * t, mode, m0, settings, deadline)
                tr, status, message = tracer.run()
            except RuntimeError:  # the augmented matrix is singular at the design
                mode = Mode.PROJECTION
                tracer = _Tracer(cons, x0, sign * t, mode, m0, settings, deadline)
                tr, status, message = tracer.run()
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
    tr, status, message = _Tracer(cons, x0, None, Mode.DESCENT, m0, settings, deadline).run()
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
