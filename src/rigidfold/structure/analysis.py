"""The shell model under load in OpenSees: static (linear or geometrically nonlinear) and the
first natural frequencies.

* **Linear static**: one load step, ``Linear`` algorithm, ``ShellDKGT`` elements.
* **Geometrically nonlinear**: ``ShellNLDKGT`` elements (corotational kinematics),
  ``Settings.structure.steps`` load steps with Newton iterations, a step that does not
  converge is halved up to ``structure_max_halvings`` times; the result is the last
  converged step and its load factor.
* **Frequencies**: ``eigen`` of the linear model without load, mass from the section's
  density times its thickness; f = sqrt(lambda) / 2 pi.

Constraints are imposed by the ``Transformation`` handler (the ties of
:mod:`rigidfold.structure.model` are exact); the static and the eigen analysis solve with
MUMPS (sparse: OpenSees's default band solver of ``eigen`` took 21 s for the 2048 shells of a
17 x 17 grid, MUMPS 2.2 s). What OpenSees prints is hidden
(:func:`rigidfold.runtime.quiet.native_quiet`). Stresses: the elements' stress resultants at their
Gauss points (N11, N22, N12, M11, M22, M12, Q13, Q23 per unit length) give the membrane and
bending stresses on both faces, sigma = N / t +- 6 M / t^2; the largest von Mises stress of
this plane stress state is reported.
"""

from __future__ import annotations

import atexit
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.material import Material
from rigidfold.runtime.quiet import native_quiet
from rigidfold.structure.model import ShellMesh, build_model


@dataclass(frozen=True, eq=False)
class ShellResponse:
    """What the shell model did under the loads.

    converged : the static analysis reached the full load (load_factor 1);
    load_factor : fraction of the loads carried at the last converged step;
    displacements : (N, 6) node displacements and rotations at that step;
    reactions : (k, 3) forces from the supports, newtons, one row per supported vertex
        (pinned, then clamped), summed over its nodes;
    applied : (N, 3) the nodal loads, newtons (before moving tied nodes' loads);
    frequencies : (m,) Hz, ascending (empty when not asked or the eigen solver failed);
    von_mises : (T,) largest von Mises stress of each element, Pa;
    hinge_rotation : (S,) rotation of each spring pair about the crease axis, radians.
    """

    converged: bool
    load_factor: float
    steps: int
    displacements: np.ndarray
    reactions: np.ndarray
    applied: np.ndarray
    frequencies: np.ndarray
    von_mises: np.ndarray
    hinge_rotation: np.ndarray
    message: str = ""
    wall_time: float = field(default=0.0, compare=False)


@dataclass(frozen=True, eq=False)
class ShellModel:
    """What the OpenSees model of a check is built from (:func:`build_model`'s inputs):
    mesh, material, thickness (m), hinge_stiffness (N m/rad per m), pinned (k,) and clamped
    (c,) int64 vertices."""

    mesh: ShellMesh
    material: Material
    thickness: float
    hinge_stiffness: float
    pinned: np.ndarray
    clamped: np.ndarray

    def build(self, ops, *, nonlinear: bool = False) -> np.ndarray:
        """The model in ``ops`` with the analysis's system of equations (MUMPS) and
        constraint handler; returns the ties (:func:`build_model`)."""
        ties = build_model(
            ops,
            self.mesh,
            self.material,
            self.thickness,
            hinge_stiffness=self.hinge_stiffness,
            pinned=self.pinned,
            clamped=self.clamped,
            nonlinear=nonlinear,
        )
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("Mumps")
        return ties

    @property
    def free_translations(self) -> int:
        """Translational DOFs of the model that are neither tied nor held: the most natural
        frequencies it has (its masses are on the translations)."""
        mesh = self.mesh
        supported = np.concatenate([self.pinned, self.clamped]).astype(np.int64)
        held = len(mesh.supported_nodes(self.pinned, self.clamped)[0])
        return 3 * (mesh.n_nodes - len(mesh.ties(supported)) - held)


_EXIT_QUIET: list[bool] = []


def _quiet_exit() -> None:
    """Hide what OpenSees prints while the process ends ("Process 0 Terminating", on file
    descriptor 2, after Python has finished) for scripts too (the command line does it for
    itself): at exit, descriptor 2 goes to the null device and ``sys.stderr`` to a copy of
    the former one, so that Python's own writes still show. Not with ``--verbose``
    (:func:`rigidfold.runtime.quiet.native_output_shown`)."""
    from rigidfold.runtime.quiet import native_output_shown

    if _EXIT_QUIET or native_output_shown():
        return
    _EXIT_QUIET.append(True)

    def silence() -> None:
        try:
            sys.stderr.flush()
            kept = os.dup(2)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 2)
            sys.stderr = os.fdopen(kept, "w", buffering=1)
        except (OSError, ValueError):
            return

    atexit.register(silence)


@native_quiet()
def solve_shell(
    mesh: ShellMesh,
    material: Material,
    thickness: float,
    forces: np.ndarray,
    *,
    pinned: np.ndarray,
    clamped: np.ndarray,
    hinge_stiffness: float = 0.0,
    nonlinear: bool = False,
    modes: int = 0,
    settings: Settings = DEFAULTS,
    progress: Callable[[str], None] | None = None,
) -> ShellResponse:
    """Static analysis of the shell model under nodal ``forces`` (N, 3) newtons, then
    ``modes`` natural frequencies of the unloaded linear model (at most as many as it has:
    the note says so)."""
    import openseespy.opensees as ops  # heavy: only when an analysis runs

    _quiet_exit()
    t0 = time.perf_counter()
    model = ShellModel(
        mesh,
        material,
        float(thickness),
        float(hinge_stiffness),
        np.asarray(pinned, dtype=np.int64),
        np.asarray(clamped, dtype=np.int64),
    )
    ties = model.build(ops, nonlinear=nonlinear)
    moved = np.array(forces, dtype=np.float64)
    np.add.at(moved, ties[:, 0], moved[ties[:, 1]])
    moved[ties[:, 1]] = 0.0
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for i in np.flatnonzero(np.any(moved != 0, axis=1)):
        ops.load(int(i) + 1, *map(float, moved[i]), 0.0, 0.0, 0.0)
    ops.test("NormDispIncr", float(settings.structure.tol), int(settings.structure.max_iter), 0)
    steps = settings.structure.steps if nonlinear else 1
    ops.algorithm("Newton" if nonlinear else "Linear")
    ops.integrator("LoadControl", 1.0 / steps)
    ops.analysis("Static")
    lam, step, halvings, done = 0.0, 1.0 / steps, 0, 0
    message = ""
    while lam < 1.0 - 1e-12:
        inc = min(step, 1.0 - lam)
        ops.integrator("LoadControl", inc)
        if ops.analyze(1) != 0:
            halvings += 1
            if not nonlinear or halvings > settings.structure.max_halvings:
                message = f"no convergence at load factor {lam:.4g}"
                break
            step = inc / 2
            continue
        lam += inc
        done += 1
    n = mesh.n_nodes
    disp = np.array([ops.nodeDisp(i + 1) for i in range(n)], dtype=np.float64).reshape(n, 6)
    if not message and not np.all(np.isfinite(disp)):
        message = "the displacements are not finite numbers (the loads or stiffness overflow)"
    converged = not message
    ops.reactions()
    nodes, _, shares = mesh.supported_nodes(model.pinned, model.clamped)
    held = np.array([ops.nodeReaction(int(i) + 1)[:3] for i in nodes]).reshape(-1, 3)
    reactions = shares.T @ held
    with np.errstate(over="ignore", invalid="ignore"):
        von_mises = _von_mises(ops, mesh.n_elements, model.thickness)
    rotation = _hinge_rotations(mesh, disp)
    frequencies = np.zeros(0)
    if modes > 0:
        if progress is not None:
            progress(f"natural frequencies ({modes} asked)")
        frequencies, note = _frequencies(ops, model, modes)
        message = "; ".join(m for m in (message, note) if m)
    ops.wipe()
    return ShellResponse(
        converged=converged,
        load_factor=lam,
        steps=done,
        displacements=disp,
        reactions=reactions,
        applied=np.asarray(forces, dtype=np.float64),
        frequencies=frequencies,
        von_mises=von_mises,
        hinge_rotation=rotation,
        message=message,
        wall_time=time.perf_counter() - t0,
    )


def _von_mises(ops, n_elements: int, thickness: float) -> np.ndarray:
    """(T,) each element's largest von Mises stress over its Gauss points and both faces."""
    out = np.zeros(n_elements)
    t = np.float64(thickness)
    for e in range(n_elements):
        r = np.asarray(ops.eleResponse(e + 1, "stresses"), dtype=np.float64).reshape(-1, 8)
        N, M = r[:, :3], r[:, 3:6]
        worst = 0.0
        for sign in (1.0, -1.0):
            s = N / t + sign * 6.0 * M / t**2
            vm = np.sqrt(s[:, 0] ** 2 - s[:, 0] * s[:, 1] + s[:, 1] ** 2 + 3 * s[:, 2] ** 2)
            worst = max(worst, float(vm.max(initial=0.0)))
        out[e] = worst
    return out


def _hinge_rotations(mesh: ShellMesh, disp: np.ndarray) -> np.ndarray:
    """(S,) relative rotation (right minus left) of each spring pair about its crease axis."""
    if not len(mesh.springs):
        return np.zeros(0)
    theta = disp[:, 3:]
    rel = theta[mesh.springs[:, 1]] - theta[mesh.springs[:, 0]]
    return np.einsum("ij,ij->i", rel, mesh.spring_axis)


def _frequencies(ops, model: ShellModel, modes: int) -> tuple[np.ndarray, str]:
    """The first ``modes`` natural frequencies (Hz) of the linear model, at most half as
    many as it has free translations (:attr:`ShellModel.free_translations`: OpenSees's
    ARPACK needs room for about twice the modes asked; on a 3 x 3 plate of 27, 18 were
    computed, 20 failed), and a note when fewer were computed or the eigen solver failed."""
    if model.material.density <= 0:
        return np.zeros(0), "no frequencies: the material has no density"
    free = model.free_translations
    most = free // 2
    if most < 1:
        return np.zeros(0), "no frequencies: the supports hold every node"
    k = min(modes, most)
    note = (
        f"{k} frequencies, {modes} asked: the model has {free} free translations, at most "
        "half as many modes are computed"
        if k < modes
        else ""
    )
    model.build(ops)
    ops.algorithm("Linear")
    ops.integrator("LoadControl", 0.0)
    ops.analysis("Static")
    try:
        lam = ops.eigen(k)
    except Exception:  # OpenSees raises a bare OpenSeesError, its text on the hidden stderr
        return np.zeros(0), f"no frequencies: the eigen solver failed for {k} modes"
    lam = np.asarray(lam if isinstance(lam, list) else [lam], dtype=np.float64)
    if not len(lam) or not np.all(np.isfinite(lam)):
        return np.zeros(0), f"no frequencies: the eigen solver failed for {k} modes"
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * math.pi), note
