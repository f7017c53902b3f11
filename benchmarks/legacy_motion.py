"""The folding-motion tracer of rigidfold before issue 29, kept as the reference of
``benchmarks/bench_path.py`` (ratio against today's tracer in the same run).

Dense Jacobians: frames at equal steps of the folding measure m = |rho_free| by Gauss-Newton
(``scipy.linalg.lstsq``), halving a step that fails; where m cannot be driven to 0 on a
1-DOF shape, pseudo-arclength continuation with a dense SVD per step. Its tolerances are
the Settings fields it had (``LEGACY``). It is not part of the package.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import scipy.linalg

from rigidfold.config import DEFAULTS, Settings
from rigidfold.frame.model import default_support_face
from rigidfold.mechanism.kinematics import fold_angles_and_gradients
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import edge_lengths

LEGACY = SimpleNamespace(
    **{
        "motion_frames": 11,
        "motion_tol": 1e-13,
        "motion_max_iter": 50,
        "motion_length_tol": 0.001,
        "motion_arc_step": 0.2,
        "motion_arc_max_steps": 400,
        "motion_max_halvings": 6,
        "motion_level_tol": 1e-12,
        "motion_stall_iter": 5,
        "motion_stall_ratio": 0.9,
        "motion_probe": 1e-06,
        "motion_arc_min_step": 1e-06,
        "motion_turn_back": 0.5,
    }
)
"""The tolerances of the old tracer (Settings.motion_* before issue 29)."""


@dataclass
class LegacyMotion:
    """What the old tracer found: ``traced`` (its status was OK), its message, frames and
    the largest relative edge-length error over them."""

    traced: bool
    message: str
    frames: int
    max_length_error: float


def _fold_angles_and_jacobian(stencils: np.ndarray, X: np.ndarray):
    """Fold angles (n,) of the creases with ``stencils`` at X (V, 3), Jacobian (n, 3V) dense."""
    n = len(stencils)
    rho, grad, cols = fold_angles_and_gradients(X, stencils)
    J = np.zeros((n, X.size))
    np.add.at(J, (np.repeat(np.arange(n), 12), cols.ravel()), grad.ravel())
    return rho, J


class _Constraints:
    """Residual r(X) and Jacobian of the rigid-folding constraints plus the folding measure.

    Rows: edge lengths (E), fixed-crease fold angles (n_fix), the support triangle (9), and
    last ``m(X) - target`` with ``m = sqrt(sum_j rho_j^2)`` over the free creases.
    """

    def __init__(self, pattern: CreasePattern, support_face: int) -> None:
        self.pattern = pattern
        self.L0 = pattern.edge_lengths
        fixed, free = pattern.fixed_creases, pattern.free_creases
        self.n_fixed = len(fixed)
        self.rho_fixed0 = pattern.fold_angles[fixed]
        self.stencils = pattern.crease_stencils(np.concatenate([fixed, free]))
        self.support = (3 * pattern.faces[support_face][:, None] + np.arange(3)).ravel()
        self.X0 = pattern.coords.ravel().copy()

    def measure(self, x: np.ndarray) -> float:
        X = x.reshape(-1, 3)
        rho, _ = _fold_angles_and_jacobian(self.stencils[self.n_fixed :], X)
        return float(np.linalg.norm(rho))

    def __call__(self, x: np.ndarray, target: float) -> tuple[np.ndarray, np.ndarray]:
        pat, V = self.pattern, self.pattern.n_vertices
        X = x.reshape(V, 3)
        e = pat.edges
        d = X[e[:, 1]] - X[e[:, 0]]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        Je = np.zeros((len(e), 3 * V))
        rows = np.arange(len(e))[:, None]
        Je[rows, 3 * e[:, :1] + np.arange(3)] = -u
        Je[rows, 3 * e[:, 1:] + np.arange(3)] = u
        rho, Jr = _fold_angles_and_jacobian(self.stencils, X)
        rho_fix, rho_free = rho[: self.n_fixed], rho[self.n_fixed :]
        m = float(np.linalg.norm(rho_free))
        Jm = (rho_free @ Jr[self.n_fixed :]) / m if m > 0 else np.zeros(3 * V)
        Js = np.zeros((9, 3 * V))
        Js[np.arange(9), self.support] = 1.0
        r = np.concatenate(
            [
                length - self.L0,
                rho_fix - self.rho_fixed0,
                x[self.support] - self.X0[self.support],
                [m - target],
            ]
        )
        return r, np.vstack([Je, Jr[: self.n_fixed], Js, Jm[None]])


def _newton(constraints: _Constraints, x: np.ndarray, target: float, settings: Settings):
    """Gauss-Newton onto the constraints; returns (x, accepted).

    Stops when the residual or the step is below ``motion_tol``, or when, after
    ``motion_stall_iter`` iterations, an iteration no longer reduces the residual below
    ``motion_stall_ratio`` times the previous one. Near the flat state an imperfect design
    (F > 0) may have no exact rigid-folding shape; the least-squares one is accepted while
    every edge length is within ``motion_length_tol`` (relative) and every fixed-crease angle
    and support coordinate within ``motion_length_tol`` (radians, metres) of its value.
    """
    previous, stall = np.inf, LEGACY.motion_stall_ratio
    for iteration in range(LEGACY.motion_max_iter):
        r, J = constraints(x, target)
        norm = float(np.linalg.norm(r))
        if norm <= LEGACY.motion_tol:
            return x, True
        if iteration >= LEGACY.motion_stall_iter and norm > stall * previous:
            break  # converging no more: least squares
        previous = norm
        dx = scipy.linalg.lstsq(J, -r, lapack_driver="gelsd")[0]
        x = x + dx
        if np.linalg.norm(dx) <= LEGACY.motion_tol:
            break
    r, _ = constraints(x, target)
    E, tol = len(constraints.L0), LEGACY.motion_length_tol
    ok = np.max(np.abs(r[:E]) / constraints.L0) <= tol and np.max(np.abs(r[E:-1])) <= tol
    return x, bool(ok and np.isfinite(r).all())


def legacy_folding_motion(
    pattern: CreasePattern,
    flat: np.ndarray,
    *,
    support_face: int | None = None,
    settings: Settings = DEFAULTS,
) -> LegacyMotion:
    """Trace the folding motion of ``pattern`` down to its development ``flat`` (V, 2).

    Returns ``LEGACY.motion_frames`` frames from the plane to the designed shape, at equal
    steps of the folding measure m = |rho_free|, the support panel held still (the panel of
    ``support_face``, default :func:`rigidfold.frame.model.default_support_face`). A step that
    does not converge is retried with half the step up to ``motion_max_halvings`` times; then
    the 1-DOF path is traced (:func:`trace_one_dof_path`).
    """
    if support_face is None:
        support_face = default_support_face(pattern)
    panel = np.flatnonzero(pattern.facets == pattern.facets[support_face])
    cons = _Constraints(pattern, support_face)
    x = pattern.coords.ravel().copy()
    m0 = cons.measure(x)
    n = max(int(LEGACY.motion_frames), 2) - 1
    velocity = np.zeros_like(x)  # dx/ds of the last step, for the secant predictor
    path, s_done, status, message = [x.copy()], 0.0, "ok", ""
    # frames at m = (1 - k/n) m0 for k < n; the flat one (k = n) is the development (the
    # constraints are singular at the flat state itself)
    levels = [k / n for k in range(1, n)]
    for level in levels if m0 > 0 else []:
        ds = level - s_done
        halvings = 0
        while s_done < level - LEGACY.motion_level_tol:
            step = min(ds, level - s_done)
            guess = x + velocity * step
            y, ok = _newton(cons, guess, (1.0 - s_done - step) * m0, settings)
            if not ok:
                halvings += 1
                if halvings > LEGACY.motion_max_halvings:
                    break
                ds = step / 2
                continue
            velocity = (y - x) / step
            x, s_done = y, s_done + step
        if s_done < level - LEGACY.motion_level_tol:
            status = "failed"
            message = f"no rigid-folding shape below {1 - s_done:.4f} of the design's folding"
            break
        path.append(x.copy())
    dof, turned_back = None, False
    if status == "failed":
        trace = trace_one_dof_path(pattern, support_face=support_face, settings=settings)
        if trace is not None and trace.reached_flat:
            path, status = trace.frames_towards_flat(n), "ok"
            message = "traced by pseudo-arclength: " + trace.message
        elif trace is not None:
            message += "; " + trace.message
        if status == "failed":
            dof = 1 if trace is not None else _rigid_folding_dof(cons, settings)
            turned_back = trace is not None and trace.turned_back
    V = pattern.n_vertices
    frames = np.array([p.reshape(V, 3) for p in path])
    del panel, dof, turned_back, flat  # the support is held still by a rigid motion, not timed
    L0 = pattern.edge_lengths
    err = max(float(np.max(np.abs(edge_lengths(f, pattern.edges) - L0) / L0)) for f in frames)
    return LegacyMotion(status == "ok", message, len(frames), err)


def _rigid_folding_dof(constraints: _Constraints, settings: Settings) -> int:
    """First-order DOF of the rigid-folding constraints (edge lengths, fixed-crease angles,
    support gauge) at the design: the nullity of their Jacobian (to ``mechanism_rank_tol``)."""
    _, J = constraints(constraints.X0, 0.0)
    return _kernel(J[:-1], settings)[1]


def _kernel(J: np.ndarray, settings: Settings) -> tuple[np.ndarray, int]:
    """(the last right singular vector of ``J``, its nullity): the columns of ``J`` minus its
    rank, counting singular values above ``mechanism_rank_tol`` times the largest."""
    _, sv, vt = np.linalg.svd(J)
    return vt[-1], J.shape[1] - int(np.sum(sv > settings.mechanism.rank_tol * sv[0]))


@dataclass
class PathTrace:
    """The one folding path of a 1-DOF shape, traced from the design towards the plane.

    points : (K, 3V) shapes along the path (the design first), at arclength steps
    measure : (K,) folding measure m = |rho_free| of each point over the design's
    reached_flat : the measure fell to the last motion level (1 / (motion_frames - 1))
    min_measure : the smallest measure on the path
    message : what happened, in words
    turned_back : the path turns back before the plane (``motion_turn_back``): the shape
        does not unfold to flat along its mechanism (False when the trace merely stopped)
    """

    points: np.ndarray
    measure: np.ndarray
    reached_flat: bool
    min_measure: float
    message: str
    turned_back: bool = False

    def frames_towards_flat(self, n: int) -> list[np.ndarray]:
        """n points equally spaced in arclength, the design first (for :func:`_hold_support`)."""
        idx = np.unique(np.round(np.linspace(0, len(self.points) - 1, n)).astype(int))
        return [self.points[i].copy() for i in idx]


def trace_one_dof_path(
    pattern: CreasePattern, *, support_face: int | None = None, settings: Settings = DEFAULTS
) -> PathTrace | None:
    """Follow the folding path of a 1-DOF shape by pseudo-arclength continuation.

    The rigid-folding constraints (edge lengths, fixed-crease angles, support gauge) leave a
    curve of shapes through the design when the mechanism has one DOF. Each step predicts
    along the curve's tangent (the null vector of the constraint Jacobian, oriented to keep
    going the same way, first towards a smaller folding measure m) and corrects by
    Gauss-Newton in the plane normal to the tangent, so the trace passes points where m
    stops decreasing. It stops when m reaches the last motion level (the plane is in reach),
    when m has risen above its minimum by ``motion_turn_back`` levels (the path turns back:
    the shape does not unfold to flat along its mechanism), when the step falls below
    ``motion_arc_min_step`` times the largest, or after ``motion_arc_max_steps``. The
    direction that decreases m first is found with a probe step of ``motion_probe`` times the
    mean edge length.

    returns None when the shape does not have exactly one DOF (to ``mechanism_rank_tol``).
    """
    if support_face is None:
        support_face = default_support_face(pattern)
    cons = _Constraints(pattern, support_face)

    def constraints(x):
        r, J = cons(x, 0.0)
        return r[:-1], J[:-1]

    def tangent(J, previous=None):
        t, nullity = _kernel(J, settings)
        if previous is not None and t @ previous < 0:
            t = -t
        return t, nullity

    x = pattern.coords.ravel().copy()
    m0 = cons.measure(x)
    if m0 <= 0:
        return None
    t, nullity = tangent(constraints(x)[1])
    if nullity != 1:
        return None
    probe = LEGACY.motion_probe * float(np.mean(pattern.edge_lengths))
    if cons.measure(x + probe * t) > cons.measure(x - probe * t):
        t = -t
    h_max = LEGACY.motion_arc_step * float(np.mean(pattern.edge_lengths))
    h, level = h_max / 4, 1.0 / max(int(LEGACY.motion_frames) - 1, 1)
    points, measure, turned_back = [x.copy()], [1.0], False
    message = f"no step possible after {LEGACY.motion_arc_max_steps} steps"
    for _ in range(LEGACY.motion_arc_max_steps):
        guess = x + h * t
        y = guess.copy()
        for _ in range(LEGACY.motion_max_iter):
            r, J = constraints(y)
            if not np.isfinite(r).all() or np.linalg.norm(r) <= LEGACY.motion_tol:
                break
            A = np.vstack([J, t])
            b = -np.concatenate([r, [t @ (y - guess)]])
            y = y + scipy.linalg.lstsq(A, b, lapack_driver="gelsy")[0]
        if not np.isfinite(r).all() or np.linalg.norm(r) > LEGACY.motion_tol:
            h /= 2
            if h < LEGACY.motion_arc_min_step * h_max:
                message = f"the path could not be continued at m = {measure[-1]:.3f}"
                break
            continue
        x = y
        t, _ = tangent(J, t)
        points.append(x.copy())
        measure.append(cons.measure(x) / m0)
        h = min(2 * h, h_max)
        m_min = min(measure)
        if measure[-1] <= level:
            message = (
                f"m falls from 1 to {measure[-1]:.3f} of the design's in {len(points) - 1} steps"
            )
            break
        if measure[-1] > m_min + level * LEGACY.motion_turn_back:
            message = (
                f"the 1-DOF folding path turns back at m = {m_min:.3f} of the design's folding "
                "measure (pseudo-arclength trace): the shape does not unfold to flat along its "
                "mechanism"
            )
            turned_back = True
            break
    m = np.asarray(measure)
    return PathTrace(
        np.asarray(points), m, bool(m[-1] <= level), float(m.min()), message, turned_back
    )
