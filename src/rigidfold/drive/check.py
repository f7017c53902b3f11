"""The independent check of the torque curve: OpenSees static analyses of the shell model.

At ``Settings.drive.check_states`` states along the motion (spread over s, each where the
driven crease is in control), the structure in that state, expressed in the base's frame,
is the shell model of ``rigidfold structure`` (:func:`rigidfold.structure.model.shell_mesh`:
every triangle ``ASDShellT3`` shells of an ``ElasticMembranePlateSection`` of the panels'
material and thickness; the two sides of a free crease tied in translation, a hinge):

* the base panel clamped: every node of its shells held (translations and rotations), the
  nodes tied to them following;
* self-weight: each shell's area x thickness x density x g, a third at each of its nodes;
  the hinge hardware along its crease, the point masses at their vertices; along -z;
* the hinges' springs: the moment each carries in that state (``k L (rho - rho_rest)``,
  lumped to the crease's nodes by their share of its length as in ``structure``) applied
  to the nodes on its two sides as couples about the crease (the held crease's too: the
  drive turns against its own spring). Their stiffness is left out: it would change the
  held moment only through the panels' elastic deformation next to the couples (on a
  3 x 2 Miura-ori with 3 N m/rad per metre, 3 % of the springs' part; 300: more than
  half), which the rigid panels of the torque curve do not have;
* the driven crease *held*: rotational springs about it of ``Settings.drive.check_hold``
  times the panels' plate rigidity per mean edge length. For a one-DOF mechanism held at one
  crease the moment they carry is fixed by equilibrium (virtual work along the mechanism's
  own mode, which strains nothing), not by their stiffness or the mesh.

The held crease's reaction moment ``sum k_s ((theta_right - theta_left) . t)`` (the torque
that turns it towards valley, as the curve's) is compared with the curve's torque without
friction, ``dU/ds / (drho/ds)``: it agrees when within ``Settings.drive.check_tolerance``
of the curve's peak (2 %). The analysis runs twice, the held crease ten times stiffer the
second time: in exact arithmetic the moment is the same (it does not depend on the
stiffness), so where the two differ by more than ``Settings.drive.check_spread`` of the
tolerance the model is near singular (the structure held at the crease keeps a
near-mechanism: :func:`held_conditioning` reports the rigid-folding constraints' smallest
singular value with the crease held), its solution is round-off, and that state decides
nothing; the check is *undecided* where no decided state disagrees.
Linear analysis (the panels' deflection under self-weight does not change the geometry
appreciably), MUMPS, the ``Transformation`` constraint handler.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.material import Material
from rigidfold.outcomes import Outcome
from rigidfold.runtime.quiet import native_quiet
from rigidfold.structure.model import ShellMesh, build_shells, build_spring, shell_mesh


class CheckStatus(Outcome):
    """The independent check's verdict."""

    AGREES = "agrees", "the OpenSees reaction moments agree with the torque curve"
    DISAGREES = (
        "disagrees",
        "an OpenSees reaction moment differs from the torque curve by more than the tolerance",
    )
    FAILED = "failed", "an OpenSees analysis failed"
    UNDECIDED = (
        "undecided",
        "the structure held at the driven crease keeps a near-mechanism, so its static "
        "analysis is ill-conditioned and confirms nothing (the built design is softer than its "
        "rigid motion)",
    )
    NOT_RUN = "not_run", "the independent check was not run"


@dataclass(frozen=True)
class CheckState:
    """One state of the check: ``s``, the held crease's reaction moment in OpenSees
    (``opensees_Nm``; ``stiffer_Nm`` with the held crease ten times as stiff), the curve's
    torque without friction there (``curve_Nm``), and the held structure's conditioning
    (:func:`held_conditioning`)."""

    s: float
    opensees_Nm: float
    curve_Nm: float
    conditioning: float = float("nan")
    stiffer_Nm: float = float("nan")

    @property
    def spread(self) -> float:
        """|the moment with the held crease ten times stiffer - the moment|: 0 in exact
        arithmetic (see the module's text), round-off where the model is near singular."""
        return abs(self.stiffer_Nm - self.opensees_Nm)

    @property
    def difference(self) -> float:
        return abs(self.opensees_Nm - self.curve_Nm)

    def to_dict(self) -> dict:
        return {
            "s": self.s,
            "opensees_Nm": self.opensees_Nm,
            "curve_Nm": self.curve_Nm,
            "difference_Nm": self.difference,
            "opensees_stiffer_hold_Nm": self.stiffer_Nm,
            "conditioning": self.conditioning,
        }


@dataclass(frozen=True)
class DriveCheck:
    """The check: ``status``, the held crease ``edge``, the ``states``, the curve's peak
    (``peak_Nm``, frictionless, in control), the ``tolerance`` (a share of the peak), the
    largest difference as a share of the peak, the time it took, and what went wrong."""

    status: CheckStatus
    edge: int
    states: tuple[CheckState, ...]
    peak_Nm: float
    tolerance: float
    largest_share: float
    seconds: float
    message: str = ""

    def to_dict(self) -> dict:
        return {
            "status": self.status.value,
            "message": self.status.describe(self.message or None),
            "method": "OpenSees static analysis of the shell model, base clamped, "
            "self-weight, the driven crease held",
            "edge": self.edge,
            "peak_Nm": self.peak_Nm,
            "tolerance_share": self.tolerance,
            "largest_difference_share": self.largest_share,
            "seconds": self.seconds,
            "states": [c.to_dict() for c in self.states],
        }


def not_run(why: str, edge: int = -1) -> DriveCheck:
    """A :class:`DriveCheck` that did not run, and why."""
    nan = float("nan")
    return DriveCheck(CheckStatus.NOT_RUN, edge, (), nan, nan, nan, 0.0, why)


def pick_states(s: np.ndarray, ok: np.ndarray, count: int) -> np.ndarray:
    """(n,) int: ``count`` states spread over s (nearest to 0.1 .. 0.9) where the driven
    crease is in control (``ok`` (K,)), distinct; fewer where there are fewer."""
    good = np.flatnonzero(ok)
    chosen: list[int] = []
    for target in np.linspace(0.1, 0.9, count):
        left = [k for k in good.tolist() if k not in chosen]
        if not left:
            break
        chosen.append(min(left, key=lambda k: (abs(s[k] - target), k)))
    return np.asarray(sorted(chosen), dtype=np.int64)


def held_conditioning(pattern, coords: np.ndarray, edge: int, *, iterations: int = 30) -> float:
    """The smallest singular value over the largest of the rigid-folding constraints
    (:class:`rigidfold.mechanism.rigid_folding.RigidFoldingConstraints`: the edge lengths,
    the fixed creases, the gauge) of ``pattern`` at ``coords`` (V, 3) with free crease
    ``edge``'s fold angle held too: 0 where it is singular (the crease does not hold the
    motion), small where the held structure keeps a near-mechanism. By inverse and direct
    power iteration on ``A^T A`` (a sparse LU), ``iterations`` steps each."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from rigidfold.frame.model import default_support_face
    from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints

    shape = pattern.with_coords(coords)
    cons = RigidFoldingConstraints(shape, default_support_face(shape))
    J, J_rho = cons.jacobian(cons.x0)
    row = int(np.flatnonzero(cons.free == edge)[0])
    A = sp.vstack([J, J_rho[row]]).tocsc()
    normal = (A.T @ A).tocsc()
    start = np.cos(np.arange(cons.n) * 0.7 + 0.3)  # any vector, the same every time
    try:
        lu = spla.splu(normal)
    except RuntimeError:  # exactly singular
        return 0.0
    x = start / np.linalg.norm(start)
    low = 0.0
    for _ in range(iterations):
        y = lu.solve(x)
        size = float(np.linalg.norm(y))
        if not np.isfinite(size) or size == 0:
            return 0.0
        low, x = 1.0 / size, y / size
    x = start / np.linalg.norm(start)
    high = 0.0
    for _ in range(iterations):
        y = normal @ x
        high = float(np.linalg.norm(y))
        x = y / high
    return float(np.sqrt(max(low, 0.0) / high)) if high > 0 else 0.0


@dataclass(frozen=True)
class HeldModel:
    """What one state's analysis is made of.

    coords : (V, 3) the state in the base's frame; base_faces : (k,) the base panel's
    triangles; edge : the held crease; hinge_edges (H,) and spring_moment (H,): the hinges
    (the held one among them) and the moment their springs carry there (N m, on rho);
    hardware : kg per metre of hinge; point_masses : (vertex, kg).
    """

    coords: np.ndarray
    base_faces: np.ndarray
    edge: int
    hinge_edges: np.ndarray
    spring_moment: np.ndarray
    hardware: float
    point_masses: tuple[tuple[int, float], ...]


def _ties(mesh: ShellMesh, fixed: np.ndarray) -> np.ndarray:
    """(K, 2) (retained, constrained) translation ties of ``mesh`` (:meth:`ShellMesh.ties`)
    with every group that has a ``fixed`` node (N,) bool retained at it, fixed nodes never
    constrained."""
    ties = mesh.ties(np.zeros(0, dtype=np.int64))
    groups: dict[int, list[int]] = {}
    for r, c in ties.tolist():
        groups.setdefault(r, [r]).append(c)
    out = []
    for members in groups.values():
        held = [m for m in members if fixed[m]]
        root = held[0] if held else members[0]
        out += [(root, m) for m in members if m != root and not fixed[m]]
    return np.asarray(out, dtype=np.int64).reshape(-1, 2)


@native_quiet()
def held_moment(
    pattern,
    model: HeldModel,
    material: Material,
    thickness: float,
    density: float,
    *,
    stiffer: float = 1.0,
    settings: Settings = DEFAULTS,
) -> tuple[float, str]:
    """(the held crease's reaction moment, N m, or NaN; what went wrong, or ""): one
    OpenSees static analysis (see the module's text) of ``pattern`` at ``model.coords``,
    the held crease ``stiffer`` times as stiff as ``Settings.drive.check_hold`` says."""
    import openseespy.opensees as ops

    from rigidfold.structure.analysis import _quiet_exit  # OpenSees's goodbye hidden at exit

    _quiet_exit()
    shape = pattern.with_coords(model.coords)
    mesh = shell_mesh(shape, settings.drive.check_subdivisions)
    g = settings.drive.gravity
    n = mesh.n_nodes
    fixed = np.zeros(n, dtype=bool)
    on_base = np.isin(mesh.triangle_face, model.base_faces)
    fixed[np.unique(mesh.triangles[on_base])] = True
    ties = _ties(mesh, fixed)
    build_shells(ops, mesh, material, thickness, density)
    rigidity = material.plate_rigidity(thickness)
    hold = stiffer * settings.drive.check_hold * rigidity / float(np.mean(shape.edge_lengths))
    moment_of = dict(zip(model.hinge_edges.tolist(), model.spring_moment.tolist(), strict=True))
    length = shape.edge_lengths
    tag, held = mesh.n_elements, []
    couples = np.zeros((n, 3))
    for s_, ((a, b), axis) in enumerate(zip(mesh.springs, mesh.spring_axis, strict=True)):
        e = int(mesh.spring_crease[s_])
        share = float(mesh.spring_length[s_])
        if e not in moment_of:
            continue
        q = moment_of[e] * share / float(length[e])  # this node pair's part, on rho
        couples[b] -= q * axis
        couples[a] += q * axis
        if e != model.edge:  # a spring's moment, not its stiffness (see the module's text)
            continue
        k = hold * share
        tag += 1
        build_spring(ops, tag, s_ + 1, a, b, axis, k)
        if e == model.edge:
            held.append((int(a), int(b), axis, k))
    for node in np.flatnonzero(fixed).tolist():
        ops.fix(node + 1, 1, 1, 1, 1, 1, 1)
    for r, c in ties:
        ops.equalDOF(int(r) + 1, int(c) + 1, 1, 2, 3)
    forces = np.zeros((n, 3))
    weight = mesh.triangle_areas * thickness * density * g
    np.add.at(forces[:, 2], mesh.triangles.ravel(), -np.repeat(weight / 3, 3))
    if model.hardware > 0:  # half of each hinge's hardware at each end (its centroid the middle)
        for e in model.hinge_edges.tolist():
            half = 0.5 * model.hardware * float(length[e]) * g
            for v in shape.edges[e].tolist():
                forces[int(mesh.vertex_nodes(v)[0]), 2] -= half
    for vertex, kg in model.point_masses:
        forces[int(mesh.vertex_nodes(vertex)[0]), 2] -= kg * g
    np.add.at(forces, ties[:, 0], forces[ties[:, 1]])
    forces[ties[:, 1]] = 0.0
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    loaded = np.any(forces != 0, axis=1) | np.any(couples != 0, axis=1)
    for node in np.flatnonzero(loaded).tolist():
        ops.load(node + 1, *map(float, forces[node]), *map(float, couples[node]))
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("Mumps")
    ops.test("NormDispIncr", 1e-12, 10, 0)
    ops.algorithm("Linear")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        ops.wipe()
        return float("nan"), "the static analysis did not converge"
    total = 0.0
    for a, b, axis, k in held:
        ra = np.asarray(ops.nodeDisp(a + 1)[3:], dtype=np.float64)
        rb = np.asarray(ops.nodeDisp(b + 1)[3:], dtype=np.float64)
        total += k * float((rb - ra) @ axis)
    ops.wipe()
    if not np.isfinite(total):
        return float("nan"), "the displacements are not finite numbers"
    return total, ""


def check_curve(
    pattern,
    models: list[tuple[float, HeldModel, float]],
    *,
    material: Material,
    thickness: float,
    density: float,
    peak: float,
    edge: int,
    settings: Settings = DEFAULTS,
) -> DriveCheck:
    """The check at each ``(s, model, curve torque)`` of ``models``: its verdict against
    ``peak`` (the frictionless curve's peak, N m) of crease ``edge``."""
    t0 = time.perf_counter()
    tol = settings.drive.check_tolerance
    states, notes = [], []
    for s, model, curve in models:
        moment, why = held_moment(pattern, model, material, thickness, density, settings=settings)
        again, why2 = held_moment(
            pattern, model, material, thickness, density, stiffer=10.0, settings=settings
        )
        cond = held_conditioning(pattern, model.coords, model.edge)
        states.append(CheckState(float(s), float(moment), float(curve), cond, float(again)))
        if why or why2:
            notes.append(f"s = {s:.3f}: {why or why2}")
    seconds = time.perf_counter() - t0
    if notes:
        return DriveCheck(
            CheckStatus.FAILED, edge, tuple(states), peak, tol, float("nan"), seconds, notes[0]
        )
    steady = settings.drive.check_spread * tol * peak
    decided = [c for c in states if c.spread <= steady]
    soft = [c for c in states if c.spread > steady]
    worst = max((c.difference for c in decided), default=0.0)
    share = worst / peak if peak > 0 else (0.0 if worst == 0 else float("inf"))
    detail = f"largest difference {100 * share:.3g} % of the peak {peak:.4g} N m"
    if share > tol:
        status = CheckStatus.DISAGREES
    elif soft:
        status = CheckStatus.UNDECIDED
        least = min(soft, key=lambda c: c.conditioning)
        detail = (
            f"at {len(soft)} of {len(states)} states the reaction moment changes by more "
            f"than {100 * settings.drive.check_spread * tol:.3g} % of the peak with the held "
            f"crease ten times stiffer (the held structure's smallest singular value "
            f"{least.conditioning:.2g} of its largest at s = {least.s:.3f})"
            + (f"; at the others, {detail}" if decided else "")
        )
    else:
        status = CheckStatus.AGREES
    return DriveCheck(status, edge, tuple(states), peak, tol, share, seconds, detail)
