"""The motion a drive deploys: the design's rigid motion from flat (s = 0) to built (s = 1),
refined so that no hinge turns more than ``Settings.drive.max_step`` between two states (and
the motion, as a curve in the space of all coordinates, not more than ``max_turn`` from one
chord to the next, where the frames are the design file's).

Where the motion comes from, in order:

1. the motion frames the design's file carries (the frames ``rigidfold generate`` writes,
   each with its fraction folded, :func:`rigidfold.fabricate.motion.file_frames`) or frames
   given, when they are a rigid motion of the design from flat
   (:func:`rigidfold.fabricate.motion.motion_evidence`: evidence, checked, never trusted).
   Between two of them too far apart, states are inserted by re-solving the rigid-folding
   constraints: a predictor-corrector continuation along them from the later frame back
   to the earlier (the tangent projected onto the null space of the constraint Jacobian,
   the corrector of least norm, :func:`rigidfold.mechanism.rigid_folding.correct`), in
   steps of the frames' chord over their number, so that every inserted state keeps the
   edge lengths and the fixed creases to ``drive_refine_tol`` and lies on the motion's own
   branch (a linear blend of the two frames projected onto the constraints may not, near
   the flat state where the branches meet; none is a blend of coordinates). An inserted
   state's s is the frames' fractions interpolated by its chord length within the
   interval;
2. else (none, not a rigid motion, or a state that cannot be re-solved) the design's
   folding path traced by the library and sampled that finely, as ``fabricate`` does
   (:func:`rigidfold.fabricate.motion.design_motion`), its first state (the path's flat
   end, within ``path_flat_tol`` of flat) replaced by the flat sheet itself, the
   development diagram, as the motion frames of a design file start.

The design must be a one-degree-of-freedom mechanism: a design of another DOF has no single
drive, and is refused (:func:`check_dof`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.exports import Design
from rigidfold.fabricate.motion import (
    PanelMotion,
    closing_angles,
    design_motion,
    file_frames,
    motion_evidence,
    panel_motion,
)
from rigidfold.fabricate.panels import Panels
from rigidfold.mesh.geometry import angle_change, best_fit, rigid_motions

MAX_STATES = 4000
"""Most states a refined motion has (as ``fabricate``'s traced motion)."""


@dataclass(frozen=True, eq=False)
class DriveMotion:
    """The refined motion, flat first, each panel moving rigidly.

    panels : Panels of the design (side ``"top"``, so that a hinge's closing angle is its
        fold angle, valley positive).
    motion : PanelMotion, its ``fraction`` the states' s (K,) from 0 (flat) to 1 (built).
    source : where the motion comes from, in words.
    """

    panels: Panels
    motion: PanelMotion
    source: str

    @property
    def s(self) -> np.ndarray:
        """(K,) float64: the states' s, rising from 0 (flat) to 1 (built)."""
        return self.motion.fraction

    @property
    def n_states(self) -> int:
        return len(self.s)

    @cached_property
    def owner(self) -> np.ndarray:
        """(V,) int: a panel each vertex belongs to (it moves with it)."""
        owner = np.full(self.panels.pattern.n_vertices, -1, dtype=np.int64)
        for k, verts in reversed(list(enumerate(self.panels.vertices))):
            owner[verts] = k
        return owner

    @cached_property
    def coords(self) -> np.ndarray:
        """(K, V, 3) float64: the vertices at each state, in the frame the motion was given
        (each moved with its panel from the design: ``R x + t``)."""
        x0 = self.panels.pattern.coords
        r = self.motion.rotations[:, self.owner]
        t = self.motion.translations[:, self.owner]
        return np.einsum("kvij,vj->kvi", r, x0) + t

    @cached_property
    def fold(self) -> np.ndarray:
        """(K, H) float64: each hinge's fold angle (valley positive, radians) at each state,
        measured on the hinge's two triangles and followed continuously from flat (each step
        taken modulo 2 pi, :func:`rigidfold.mesh.geometry.angle_change`)."""
        pattern = self.panels.pattern
        edges = self.panels.hinge_edges
        raw = fold_angles_along(pattern, self.coords, edges)
        if not len(raw):
            return raw
        steps = angle_change(raw[1:], raw[:-1])
        start = angle_change(raw[:1], np.zeros_like(raw[:1]))
        return np.concatenate([start, start + np.cumsum(steps, axis=0)])

    def in_base(self, base: int) -> np.ndarray:
        """(K, V, 3) float64: the vertices at each state with panel ``base`` held in its
        built pose (the motion as the builder sees it)."""
        r = self.motion.rotations[:, base]
        t = self.motion.translations[:, base]
        return np.einsum("kji,kvj->kvi", r, self.coords - t[:, None])

    def to_dict(self) -> dict:
        return {
            "states": self.n_states,
            "source": self.source,
            "largest_step_deg": math.degrees(self.largest_step),
        }

    @property
    def largest_step(self) -> float:
        """Largest turn of one hinge between two states, radians."""
        fold = self.fold
        if len(fold) < 2 or not fold.shape[1]:
            return 0.0
        return float(np.abs(np.diff(fold, axis=0)).max())


def fold_angles_along(pattern, coords: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(K, n) float64: the fold angle (FOLD convention, valley positive, in (-pi, pi]) of each
    of ``edges`` (n,) interior edges at each of ``coords`` (K, V, 3), from the normals of the
    two triangles at the edge (:func:`rigidfold.mesh.geometry.fold_angles`)."""
    faces = pattern.faces
    ef = pattern.edge_faces[edges]
    e = pattern.edges[edges]

    def normals(f: np.ndarray) -> np.ndarray:
        p = coords[:, faces[f]]  # (K, n, 3, 3)
        n = np.cross(p[:, :, 1] - p[:, :, 0], p[:, :, 2] - p[:, :, 0])
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    na, nb = normals(ef[:, 0]), normals(ef[:, 1])
    t = coords[:, e[:, 1]] - coords[:, e[:, 0]]
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    sin = -np.einsum("kni,kni->kn", np.cross(na, nb), t)
    cos = np.einsum("kni,kni->kn", na, nb)
    return np.arctan2(sin, cos)


def check_dof(pattern, *, settings: Settings = DEFAULTS) -> int:
    """The design's DOF (:func:`rigidfold.mechanism.analyze`); RigidfoldError, one line
    naming it, unless it is 1."""
    from rigidfold.mechanism.analysis import analyze

    dof = analyze(pattern, settings=settings).dof
    if dof != 1:
        raise RigidfoldError(
            f"the design has DOF {dof}, not 1: "
            + (
                "it does not move, so no drive deploys it"
                if dof == 0
                else "no single drive controls its motion (reduce it to DOF 1 first)"
            )
        )
    return dof


def refine_frames(
    panels: Panels,
    frames: np.ndarray,
    fraction: np.ndarray,
    *,
    settings: Settings = DEFAULTS,
) -> tuple[np.ndarray, np.ndarray] | None:
    """(states (K', V, 3), s (K',)): ``frames`` (K, V, 3) at ``fraction`` (K,), a rigid motion
    of ``panels``' design, with states inserted between two frames where a hinge turns more
    than ``settings.drive.max_step``, or the motion turns more than ``settings.drive.
    max_turn`` from one chord to the next, in the space of all coordinates (see the module's
    text), every frame held at the design's support triangle; None where a state cannot be
    re-solved onto the constraints."""
    from rigidfold.frame.model import default_support_face
    from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints

    pattern = panels.pattern
    face = default_support_face(pattern)
    cons = RigidFoldingConstraints(pattern, face)
    held = best_fit(np.asarray(frames, dtype=np.float64), pattern.coords, pattern.faces[face])
    fold = fold_angles_along(pattern, held, panels.hinge_edges)
    turn = (
        np.abs(angle_change(fold[1:], fold[:-1])).max(axis=1, initial=0.0)
        if len(fold) > 1
        else np.zeros(0)
    )
    step = settings.drive.max_step
    parts = np.maximum(np.ceil(turn / step).astype(np.int64), 1)
    if 1 + int(parts.sum()) > MAX_STATES:
        return None
    loose = settings.with_(path_corrector_iter=3 * settings.path.corrector_iter)
    max_turn = settings.drive.max_turn
    states = [held[0]]
    s = [float(fraction[0])]
    for k, n in enumerate(parts.tolist()):
        a, b = held[k], held[k + 1]
        inside: list[np.ndarray] = [a, b]
        for _ in range(3):  # more steps where a hinge still turns too far in one
            between = _continue(cons, b, a, n, loose) if n > 1 else []
            if between is None:
                return None
            inside = [a, *between[::-1], b]
            f = fold_angles_along(pattern, np.asarray(inside), panels.hinge_edges)
            largest = float(np.abs(angle_change(f[1:], f[:-1])).max(initial=0.0))
            turn = _largest_turn(np.asarray(inside))
            if largest <= step * (1 + 1e-9) and turn <= max_turn * (1 + 1e-9):
                break
            n = math.ceil(n * max(largest / step, turn / max_turn, 1.0)) + 1
        if len(states) + len(inside) > MAX_STATES:
            return None
        chord = np.linalg.norm(
            np.diff(np.asarray(inside), axis=0).reshape(len(inside) - 1, -1), axis=1
        )
        total = float(chord.sum())
        m = len(inside) - 1
        where = np.cumsum(chord) / total if total > 0 else np.linspace(1 / m, 1.0, m)
        s0, s1 = float(fraction[k]), float(fraction[k + 1])
        states.extend(inside[1:])
        s.extend((s0 + (s1 - s0) * where).tolist())
    return np.asarray(states), np.asarray(s)


def _largest_turn(states: np.ndarray) -> float:
    """The largest angle, radians, between two successive chords of ``states`` (K, V, 3)
    (the motion's turn in the space of all coordinates from one state to the next)."""
    chords = np.diff(states, axis=0).reshape(len(states) - 1, -1)
    if len(chords) < 2:
        return 0.0
    size = np.linalg.norm(chords, axis=1)
    cos = np.einsum("ij,ij->i", chords[1:], chords[:-1]) / (size[1:] * size[:-1])
    return float(np.arccos(np.clip(cos, -1.0, 1.0)).max())


def _continue(cons, start: np.ndarray, end: np.ndarray, n: int, settings: Settings):
    """The states (each (V, 3)) from ``start`` towards ``end`` (both on the constraints,
    (V, 3)) of a predictor-corrector continuation along the constraints' one-dimensional
    manifold in steps of 1/n of their chord (the last two sharing what is left), until
    ``end`` is within one step: the tangent
    the projection of the last onto the null space of J (the first: towards ``end``), the
    corrector of least norm. None where a step does not converge or does not come closer
    (at most ``3 n`` steps). It goes from the later frame to the earlier, so that it never
    starts at the flat state, where the manifold branches."""
    from rigidfold.mechanism.rigid_folding import System, correct

    x = start.ravel() / cons.scale
    goal = end.ravel() / cons.scale
    h = float(np.linalg.norm(goal - x)) / n
    if not h > 0:
        return []
    t = (goal - x) / (n * h)
    # pseudo-arclength ([J; t^T], corrections across the tangent) where J has n - 1 rows, as
    # the trace does; least norm where its rows are redundant (self-stressed)
    mode = "augmented" if cons.n_rows == cons.n - 1 else "projection"
    out: list[np.ndarray] = []
    system = None  # the corrector's last factors serve the next tangent, as in the trace
    while (left := float(np.linalg.norm(goal - x))) > h * (1 + 1e-9):
        if len(out) >= 3 * n:
            return None
        try:
            if system is None or mode == "augmented":
                J, J_rho = cons.jacobian(x)
                system = System(J, J_rho, mode, t, settings)
            t_new = system.direction(t, cons.free_angles(x))
        except RuntimeError:
            return None
        if not np.isfinite(t_new).all():
            return None
        t = t_new if float(t_new @ (goal - x)) >= 0 else -t_new
        # within two steps of the end, halve what is left: no last step much shorter
        step = x + min(h, left / 2) * t
        y, ok, _, system = correct(cons, step, mode, t, settings)
        if not ok or not np.linalg.norm(goal - y) < np.linalg.norm(goal - x):
            return None
        x = y
        out.append(y.reshape(-1, 3) * cons.scale)
    return out


def drive_motion(
    panels: Panels,
    design: Design | None = None,
    *,
    frames: tuple[np.ndarray, np.ndarray] | None = None,
    path=None,
    settings: Settings = DEFAULTS,
) -> DriveMotion:
    """The refined motion of ``panels``' design (see the module's text): from ``frames``
    ((K, V, 3), fraction (K,)) when given, else from the design file's frames, else traced.
    ``path``: the design's folding path already traced. RigidfoldError (one line) when the
    design has no motion from flat."""
    carried = frames
    if carried is None and design is not None:
        carried = file_frames(design)
    rejected = ""
    if carried is not None:
        shapes, fraction = (np.asarray(a, dtype=np.float64) for a in carried)
        why = motion_evidence(panels, shapes, fraction, settings=settings)
        if not why:
            refined = refine_frames(panels, shapes, fraction, settings=settings)
            if refined is not None:
                states, s = _increasing(*refined)
                where = "the given" if frames is not None else "the design file's"
                source = f"{where} {len(shapes)} frames refined to {len(s)} states"
                return _settled(panels, states, s, source, settings)
            rejected = f" (the {len(shapes)} frames could not be refined)"
        else:
            rejected = f" (the {len(shapes)} frames are not its motion: {why})"
    fine = settings.with_(fabricate_frame_step=settings.drive.max_step)
    motion, message = design_motion(panels, None, path=path, settings=fine)
    if motion is None:
        raise RigidfoldError(f"the design's motion does not reach the flat state: {message}")
    if motion.largest_step > settings.drive.max_step * (1 + 1e-9):
        message += (
            f" (a hinge turns {math.degrees(motion.largest_step):.3g} degrees between two of "
            f"its {MAX_STATES} states at most)"
        )
    rotations, translations = _flat_start(panels, motion, settings)
    s = np.asarray(motion.fraction, dtype=np.float64)
    keep = _strictly_rising(s)
    closing = closing_angles(panels, rotations)
    traced = DriveMotion(
        panels, PanelMotion(rotations[keep], translations[keep], s[keep], closing[keep], ""), ""
    )
    return _settled(panels, traced.coords, s[keep], f"{message}{rejected}", settings)


def settle(panels: Panels, states: np.ndarray, *, settings: Settings = DEFAULTS) -> np.ndarray:
    """(K, V, 3): ``states`` (K, V, 3), a motion on the rigid-folding constraints to
    ``path_tol``, each corrected onto them to ``drive_refine_tol`` (held at the design's
    support triangle): where the constraints have a near flex (a singular value sigma near
    0 besides the motion's own), a residual r leaves a state anywhere within r / sigma
    along it, and the energy's differences between states wander with it (a 12 m x 8 m
    roof: sigma 1e-8, the torque's sign flipping from one state to the next). A square
    system (no redundant row) is corrected across the motion's chord (pseudo-arclength,
    Newton's quadratic rate to 1e-15); else, or where that fails (the flat state, where the
    manifold branches), by the least-norm corrector to ``path_tol``; a state neither
    corrects is kept."""
    from rigidfold.frame.model import default_support_face
    from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints, correct

    pattern = panels.pattern
    face = default_support_face(pattern)
    cons = RigidFoldingConstraints(pattern, face)
    held = best_fit(np.asarray(states, dtype=np.float64), pattern.coords, pattern.faces[face])
    iters = 3 * settings.path.corrector_iter
    tight = settings.with_(path_tol=settings.drive.refine_tol, path_corrector_iter=iters)
    loose = settings.with_(path_corrector_iter=iters)
    square = cons.n_rows == cons.n - 1
    out = held.copy()
    for k in range(len(held)):
        x = held[k].ravel() / cons.scale
        y, ok = x, False
        if square and len(held) > 1:
            chord = (held[min(k + 1, len(held) - 1)] - held[max(k - 1, 0)]).ravel()
            size = float(np.linalg.norm(chord))
            if size > 0:
                try:
                    y, ok, _, _ = correct(cons, x, "augmented", chord / size, tight)
                except RuntimeError:
                    ok = False
        if not ok:
            y, ok, _, _ = correct(cons, x, "projection", None, loose)
        if ok:
            out[k] = y.reshape(-1, 3) * cons.scale
    return out


def _settled(
    panels: Panels, states: np.ndarray, s: np.ndarray, source: str, settings: Settings
) -> DriveMotion:
    """The :class:`DriveMotion` of ``states`` (K, V, 3) at ``s`` (K,), each :func:`settle`d."""
    fine = settle(panels, states, settings=settings)
    return DriveMotion(panels, panel_motion(panels, fine, s, source), source)


def _flat_start(
    panels: Panels, motion: PanelMotion, settings: Settings
) -> tuple[np.ndarray, np.ndarray]:
    """(rotations, translations) of ``motion`` with its first state, the traced path's flat
    end (every hinge within ``path_flat_tol`` of flat), replaced by the flat sheet itself
    (the development diagram at z = 0, each panel fitted onto it), as the design file's
    motion starts: the flat sheet lies on the ground. Kept as traced where the development
    is not a rigid placement of the panels (within ``fabricate_frame_tol``)."""
    pattern = panels.pattern
    flat = np.column_stack([panels.coords2d, np.zeros(pattern.n_vertices)])
    r, t = rigid_motions(pattern.coords, flat[None], panels.vertices)
    size = float(np.linalg.norm(np.ptp(pattern.coords, axis=0))) or 1.0
    worst = 0.0
    for k, verts in enumerate(panels.vertices):
        moved = pattern.coords[verts] @ r[0, k].T + t[0, k]
        worst = max(worst, float(np.abs(moved - flat[verts]).max()))
    rotations, translations = motion.rotations.copy(), motion.translations.copy()
    if worst <= settings.fabricate.frame_tol * size:
        rotations[0], translations[0] = r[0], t[0]
    return rotations, translations


def _strictly_rising(s: np.ndarray) -> np.ndarray:
    """(k,) int: the indices of ``s`` (K,) kept so that it rises strictly (a state at the
    s of the one before it is left out)."""
    keep = [0]
    for i in range(1, len(s)):
        if s[i] > s[keep[-1]]:
            keep.append(i)
    return np.asarray(keep, dtype=np.int64)


def _increasing(states: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = _strictly_rising(s)
    return states[keep], s[keep]
