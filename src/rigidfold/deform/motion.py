"""The folding motion: a path of rigidly folded shapes from the plane to the designed shape.

The path is traced by continuation on the rigid-folding constraints, independent of the
large-deformation analysis:

* unknowns: the vertex coordinates X (V, 3);
* constraints: every edge length (rigid triangles), every fixed crease's fold angle, the
  support triangle's nine coordinates (gauge), and ``d`` *driver* creases (d = DOF, the
  free creases with the most independent rotations in the mechanism, chosen by a pivoted
  QR of H_phi^T) whose fold angles go linearly from the design to 0;
* each frame: a secant predictor, then Gauss-Newton (least-squares, minimum norm) steps.
  A step that does not converge is halved.

For a 1-DOF mechanism the path is the mechanism's own; with more DOF it is the one along
which the drivers fold proportionally. The flat end is replaced by the development diagram
(Step 8) at z = 0, and a rigid motion that goes smoothly from the identity (designed shape)
to the map of the flat state onto the development puts the whole path in that frame.
``max_length_error`` is the largest relative edge-length error over all frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from scipy.spatial.transform import Rotation, Slerp

from rigidfold.config import DEFAULTS, Settings
from rigidfold.frame.model import default_support_face
from rigidfold.mechanism import analyze
from rigidfold.mechanism.kinematics import _fold_angle_map
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import edge_lengths


@dataclass
class Motion:
    """Frames of the folding motion, flat first.

    frames : (K, V, 3) float64; frames[0] is flat (z = 0), frames[-1] the designed shape
    parameter : (K,) fraction folded, 0 (flat) .. 1 (designed)
    drivers : edge indices of the driver creases
    max_length_error : largest |l - l0| / l0 over all edges and frames
    status : "ok" or "failed"; message says why it failed
    """

    frames: np.ndarray
    parameter: np.ndarray
    drivers: np.ndarray
    max_length_error: float
    status: str
    message: str = ""

    def summary(self) -> dict:
        return {
            "status": self.status,
            "message": self.message,
            "frames": len(self.frames),
            "drivers": self.drivers.tolist(),
            "max_length_error": self.max_length_error,
        }


def _crease_stencils(pattern: CreasePattern, creases: np.ndarray) -> np.ndarray:
    """(n, 4) vertices (u, v, a, b) of each crease: its ends and the two opposite corners."""
    e = pattern.edges[creases]
    ef = pattern.edge_faces[creases]
    a = pattern.faces[ef[:, 0]].sum(axis=1) - e.sum(axis=1)
    b = pattern.faces[ef[:, 1]].sum(axis=1) - e.sum(axis=1)
    return np.column_stack([e[:, 0], e[:, 1], a, b])


def _fold_angles_and_jacobian(stencils: np.ndarray, X: np.ndarray):
    """Fold angles (n,) of the creases with ``stencils`` at X (V, 3), Jacobian (n, 3V) dense."""
    n = len(stencils)
    q = X[stencils].reshape(n, 12).T
    rho, grad = _fold_angle_map(n)(q)
    cols = (3 * stencils[:, :, None] + np.arange(3)).reshape(n, 12)
    J = np.zeros((n, X.size))
    np.add.at(J, (np.repeat(np.arange(n), 12), cols.ravel()), np.asarray(grad).T.ravel())
    return np.asarray(rho).ravel(), J


class _Constraints:
    """Residual r(X) and Jacobian of the rigid-folding constraints with driver targets."""

    def __init__(self, pattern: CreasePattern, drivers: np.ndarray, support_face: int) -> None:
        self.pattern = pattern
        self.L0 = pattern.edge_lengths
        self.fixed = pattern.fixed_creases
        self.rho_fixed0 = pattern.fold_angles[self.fixed]
        self.drivers = drivers
        self.stencils = _crease_stencils(pattern, np.concatenate([self.fixed, drivers]))
        self.support = (3 * pattern.faces[support_face][:, None] + np.arange(3)).ravel()
        self.X0 = pattern.coords.ravel().copy()

    def __call__(self, x: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
        if len(self.stencils):
            rho, Jr = _fold_angles_and_jacobian(self.stencils, X)
        else:
            rho, Jr = np.zeros(0), np.zeros((0, 3 * V))
        goal = np.concatenate([self.rho_fixed0, target])
        Js = np.zeros((9, 3 * V))
        Js[np.arange(9), self.support] = 1.0
        r = np.concatenate([length - self.L0, rho - goal, x[self.support] - self.X0[self.support]])
        return r, np.vstack([Je, Jr, Js])


def _choose_drivers(pattern: CreasePattern, settings: Settings) -> np.ndarray:
    mech = analyze(pattern, settings=settings)
    if mech.dof == 0:
        return np.zeros(0, dtype=np.int64)
    _, _, piv = scipy.linalg.qr(mech.H_phi.T, pivoting=True, mode="economic")
    return mech.hinges[np.sort(piv[: mech.dof])]


def _newton(constraints: _Constraints, x: np.ndarray, target: np.ndarray, settings: Settings):
    """Gauss-Newton onto the constraints; (x, accepted).

    Stops when the residual or the step is below ``motion_tol``. Near the flat state an
    imperfect design (F > 0) may have no exact rigid-folding shape; the least-squares one is
    accepted while every edge stays within ``motion_length_tol`` of its length.
    """
    previous = np.inf
    for _ in range(settings.motion_max_iter):
        r, J = constraints(x, target)
        norm = float(np.linalg.norm(r))
        if norm <= settings.motion_tol:
            return x, True
        if norm > 0.5 * previous:  # no longer converging quadratically: a least-squares point
            break
        previous = norm
        dx = scipy.linalg.lstsq(J, -r, lapack_driver="gelsd")[0]
        x = x + dx
        if np.linalg.norm(dx) <= settings.motion_tol:
            break
    r, _ = constraints(x, target)
    E = len(constraints.L0)
    ok = np.max(np.abs(r[:E]) / constraints.L0) <= settings.motion_length_tol
    return x, bool(ok and np.isfinite(r).all())


def folding_motion(
    pattern: CreasePattern,
    flat: np.ndarray,
    *,
    support_face: int | None = None,
    settings: Settings = DEFAULTS,
) -> Motion:
    """Trace the folding motion of ``pattern`` from its development ``flat`` (V, 2).

    Returns ``settings.motion_frames`` frames from the plane to the designed shape.
    """
    if support_face is None:
        support_face = default_support_face(pattern)
    drivers = _choose_drivers(pattern, settings)
    cons = _Constraints(pattern, drivers, support_face)
    rho0 = pattern.fold_angles[drivers]
    n = max(int(settings.motion_frames), 2) - 1
    x = pattern.coords.ravel().copy()
    velocity = np.zeros_like(x)  # dx/ds of the last step, for the secant predictor
    path, s_done, status, message = [x.copy()], 0.0, "ok", ""
    for k in range(1, n + 1):
        ds = k / n - s_done
        halvings = 0
        while s_done < k / n - 1e-12:
            step = min(ds, k / n - s_done)
            y, ok = _newton(cons, x + velocity * step, (1.0 - s_done - step) * rho0, settings)
            if not ok:
                halvings += 1
                if halvings > settings.deform_max_halvings:
                    break
                ds = step / 2
                continue
            velocity = (y - x) / step
            x, s_done = y, s_done + step
        if s_done < k / n - 1e-12:
            status = "failed"
            message = f"no rigid-folding shape beyond {1 - s_done:.4f} of the design's fold angles"
            break
        path.append(x.copy())
    V = pattern.n_vertices
    frames = np.array([p.reshape(V, 3) for p in path])
    if status == "ok":
        frames = _place_flat(frames, flat)
    else:
        frames = frames[::-1]
    L0 = pattern.edge_lengths
    err = max(float(np.max(np.abs(edge_lengths(f, pattern.edges) - L0) / L0)) for f in frames)
    parameter = (
        np.linspace(0.0, 1.0, len(frames)) if status == "ok" else np.full(len(frames), np.nan)
    )
    return Motion(frames, parameter, drivers, err, status, message)


def _place_flat(frames: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """Flat first; the flat frame replaced by the development at z = 0; a smooth rigid motion.

    frames : (K, V, 3) designed -> flat in the designed shape's gauge.
    """
    K = len(frames)
    target = np.column_stack([flat, np.zeros(len(flat))])
    src = frames[-1]
    sc, tc = src.mean(axis=0), target.mean(axis=0)
    rot, _ = Rotation.align_vectors(target - tc, src - sc)
    slerp = Slerp([0.0, 1.0], Rotation.concatenate([Rotation.identity(), rot]))
    out = np.empty_like(frames)
    for k, s in enumerate(np.linspace(0.0, 1.0, K)):  # s: 0 designed -> 1 flat
        c = sc + s * (tc - sc)
        out[k] = slerp([s])[0].apply(frames[k] - sc) + c
    out[-1] = target
    return out[::-1]
