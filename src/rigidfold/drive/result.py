"""What the drive of a design found: :class:`DriveResult`, its verdict :class:`DriveStatus`,
its ``deploy.json`` (:meth:`DriveResult.to_dict`) and its last line
(:meth:`DriveResult.summary_line`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rigidfold.drive.actuators import Actuator
from rigidfold.drive.base import Below, Placement
from rigidfold.drive.check import CheckStatus, DriveCheck
from rigidfold.drive.equilibria import Equilibrium, Release
from rigidfold.drive.mass import Masses
from rigidfold.drive.options import DriveOptions
from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome

SCHEMA_VERSION = 1
"""The version of ``deploy.json``'s layout."""


class DriveStatus(Outcome):
    """The verdict of the drive (the first that applies, in this order)."""

    NO_DRIVE = (
        "no_drive",
        "no single crease, pair of creases or cable drives the whole motion: each loses "
        "control at a dead point, or a cable would have to push",
    )
    OVER_LIMIT = (
        "over_limit",
        "every drive of the whole motion needs more than the largest torque or tension allowed",
    )
    BELOW_GROUND = "below_ground", "a vertex passes below the ground during the motion"
    CHECK_FAILED = (
        "check_failed",
        "the independent OpenSees check does not confirm the torque curve",
    )
    DRIVEN = (
        "driven",
        "the named drive deploys the design from flat to built with every vertex above the ground",
    )

    @property
    def ok(self) -> bool:
        """Whether the command succeeds (exit 0)."""
        return self is DriveStatus.DRIVEN


def torque_text(value: float) -> str:
    """``1.84 kN m`` or ``312 N m``."""
    if not math.isfinite(value):
        return "unbounded"
    return f"{value / 1e3:.3g} kN m" if abs(value) >= 1e3 else f"{value:.3g} N m"


def force_text(value: float) -> str:
    """``3.1 kN`` or ``450 N``."""
    if not math.isfinite(value):
        return "unbounded"
    return f"{value / 1e3:.3g} kN" if abs(value) >= 1e3 else f"{value:.3g} N"


def effort_text(drive: Actuator) -> str:
    return force_text(drive.peak) if drive.kind == "cable" else torque_text(drive.peak)


@dataclass(frozen=True, eq=False)
class DriveResult:
    """The drive of a design's deployment (see :func:`rigidfold.drive.deploy_design`).

    status, message : the verdict and its detail. source : the design, in words.
    pattern : the design; options : the options it ran with; thickness (m), density
    (kg/m^3) and thickness_from (where the thickness came from) of the panels.
    s (K,) : the states; u, u_gravity, u_spring, slope, friction (K,) : U, its parts, dU/ds
    and the friction's dissipation per unit of s with the base clamped (J).
    coords : (K, V, 3) the states with the base in its built pose (the motion as the builder
    sees it). base : the clamped panel; base_faces : its faces of the design file; base_auto :
    chosen by ``--base auto``. masses : the masses. drive : the named drive (None: none);
    ranking : every hinge as the single drive, lowest peak first; pair : the best pair (where
    the best single crease has a dead point); cables : the cables given and the best
    boundary ones. bases : every panel as the base, ranked. sign_changes : where P changes
    sign; brake_zones / retract_brake_zones : where the motion runs away deploying / folding
    back; equilibria, released : the released structure; ground (m) and below : the vertices
    that pass below it. check : the independent check. motion : the motion's figures.
    seconds : the time of each step.
    """

    status: DriveStatus
    message: str
    source: str
    pattern: CreasePattern = field(repr=False)
    options: DriveOptions
    thickness: float
    density: float
    thickness_from: str
    s: np.ndarray = field(repr=False)
    u: np.ndarray = field(repr=False)
    u_gravity: np.ndarray = field(repr=False)
    u_spring: np.ndarray = field(repr=False)
    slope: np.ndarray = field(repr=False)
    friction: np.ndarray = field(repr=False)
    coords: np.ndarray = field(repr=False)
    base: int
    base_faces: tuple[int, ...]
    base_auto: bool
    masses: Masses = field(repr=False)
    drive: Actuator | None
    ranking: tuple[Actuator, ...] = field(repr=False)
    pair: Actuator | None
    cables: tuple[Actuator, ...]
    bases: tuple[Placement, ...] = field(repr=False)
    sign_changes: tuple[float, ...]
    brake_zones: tuple[tuple[float, float], ...]
    retract_brake_zones: tuple[tuple[float, float], ...]
    equilibria: tuple[Equilibrium, ...]
    released: tuple[Release, ...]
    ground: float
    below: tuple[Below, ...]
    check: DriveCheck
    motion: dict
    gravity: float
    seconds: dict = field(default_factory=dict)
    written: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.status.ok

    def summary_line(self) -> str:
        """The last line of ``rigidfold deploy``: ``drive crease 217: peak 1.84 kN m at s =
        0.31; brake from s = 0.62; cable 4-77: peak 3.1 kN``."""
        parts = []
        d = self.drive
        if d is None:
            parts.append("no drive: the design's hinges do not move")
        else:
            head = "drive" if d.controls else "no drive controls the whole motion; best"
            if d.controls or not d.dead:
                parts.append(f"{head} {d.name}: peak {effort_text(d)} at s = {d.peak_s:.2f}")
            else:
                dead = ", ".join(f"{x:.2f}" for x in d.dead[:3])
                parts.append(
                    f"{head} {d.name}: peak {effort_text(d)} at s = {d.peak_s:.2f} away from "
                    f"its dead points (s = {dead})"
                )
        if self.brake_zones:
            a, b = self.brake_zones[0]
            text = f"brake from s = {a:.2f}" + (f" to {b:.2f}" if b < self.s[-1] else "")
            if len(self.brake_zones) > 1:
                text += f" (+{len(self.brake_zones) - 1} more zones)"
            parts.append(text)
        else:
            parts.append("no brake needed")
        cable = next((c for c in self.cables if c.controls and c is not d), None)
        if cable is not None:
            parts.append(f"{cable.name}: peak {force_text(cable.peak)}")
        if self.below:
            w = self.below[0]
            parts.append(
                f"vertex {w.vertex} passes {w.depth:.3g} m below the ground at s = {w.s:.2f}"
            )
        if self.status is DriveStatus.OVER_LIMIT:
            parts.append("over the limit")
        if self.check.status in (CheckStatus.DISAGREES, CheckStatus.FAILED):
            parts.append(f"check {self.check.status.value}")
        elif self.check.status is CheckStatus.UNDECIDED:
            parts.append("check undecided: the held structure keeps a near-mechanism")
        return "; ".join(parts)

    def states(self) -> list[dict]:
        """The rows of ``deploy.json``'s ``states`` (see :meth:`to_dict`)."""
        d = self.drive
        rows = []
        for k, s in enumerate(self.s.tolist()):
            row = {
                "s": s,
                "U_J": float(self.u[k]),
                "U_gravity_J": float(self.u_gravity[k]),
                "U_spring_J": float(self.u_spring[k]),
                "dU_ds_J": float(self.slope[k]),
                "friction_J": float(self.friction[k]),
            }
            if d is None or d.kind == "cable":
                row["drive_angle_deg"] = None
                row["drive_torque_Nm"] = None
                if d is not None:
                    row["drive_length_m"] = float(d.coordinate[k])
                    row["drive_tension_N"] = _finite(d.effort[k])
            elif d.kind == "pair":
                row["drive_angle_deg"] = [math.degrees(float(a)) for a in d.coordinate[:, k]]
                row["drive_torque_Nm"] = [_finite(t) for t in d.effort[:, k]]
            else:
                row["drive_angle_deg"] = math.degrees(float(d.coordinate[k]))
                row["drive_torque_Nm"] = _finite(d.effort[k])
            rows.append(row)
        return rows

    def to_dict(self) -> dict:
        """``deploy.json``: the keys of the issue's interface (``schema_version``,
        ``base_panel``, ``panel_mass_kg``, ``states``, ``drive``, ``ranking``, ``check``) and
        the rest of the figures."""
        d = self.drive
        return {
            "schema_version": SCHEMA_VERSION,
            "file": self.source,
            "status": self.status.value,
            "message": self.status.describe(self.message or None),
            "summary": self.summary_line(),
            "motion": self.motion,
            "panels": {
                "thickness_m": self.thickness,
                "thickness_from": self.thickness_from or "given",
                "material": self.options.material.to_dict(),
                "density_kg_m3": self.density,
                "gravity_m_s2": self.gravity,
                **self.masses.to_dict(),
            },
            "options": self.options.to_dict(),
            "base_panel": list(self.base_faces),
            "base": {
                "panel": self.base,
                "chosen": "auto" if self.base_auto else "given",
            },
            "panel_mass_kg": [float(m) for m in self.masses.face_kg],
            "states": self.states(),
            "drive": None if d is None else d.to_dict(),
            "ranking": [
                {
                    "edge": a.ids[0],
                    "peak_Nm": None if not np.isfinite(a.peak) else a.peak,
                    "peak_s": None if not np.isfinite(a.peak) else a.peak_s,
                    "dead_points": list(a.dead),
                    "controls": a.controls,
                    **({"still": True} if a.still else {}),
                }
                for a in self.ranking
            ],
            "pair": None if self.pair is None else self.pair.to_dict(),
            "cables": [c.to_dict() for c in self.cables],
            "bases": [p.to_dict() for p in self.bases],
            "dead_points": [] if d is None else list(d.dead),
            "sign_changes": list(self.sign_changes),
            "brake_zones": [list(z) for z in self.brake_zones],
            "retract_brake_zones": [list(z) for z in self.retract_brake_zones],
            "equilibria": [e.to_dict() for e in self.equilibria],
            "released": [{**r.to_dict(), "text": r.describe()} for r in self.released],
            "ground": {
                "z_m": self.ground,
                "clear": not self.below,
                "below": [b.to_dict() for b in self.below],
            },
            "check": self.check.to_dict(),
            "seconds": self.seconds,
            "written": list(self.written),
        }


def _finite(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def verdict(
    drive: Actuator | None,
    below: tuple[Below, ...],
    check: DriveCheck,
    *,
    over_limit: bool,
) -> tuple[DriveStatus, str]:
    """(status, detail) of a drive (see :class:`DriveStatus`)."""
    if drive is None or not drive.controls:
        detail = (
            ""
            if drive is None
            else f"best: {drive.name}, dead points at s = "
            + ", ".join(f"{x:.3f}" for x in drive.dead)
        )
        return DriveStatus.NO_DRIVE, detail
    if over_limit:
        return DriveStatus.OVER_LIMIT, f"best: {drive.name}, peak {effort_text(drive)}"
    if below:
        w = below[0]
        return (
            DriveStatus.BELOW_GROUND,
            f"vertex {w.vertex} passes {w.depth:.4g} m below at s = {w.s:.3f}"
            + (f" ({len(below)} vertices)" if len(below) > 1 else ""),
        )
    if check.status in (CheckStatus.DISAGREES, CheckStatus.FAILED):
        return DriveStatus.CHECK_FAILED, check.status.describe(check.message or None)
    return DriveStatus.DRIVEN, f"{drive.name}, peak {effort_text(drive)} at s = {drive.peak_s:.3f}"
