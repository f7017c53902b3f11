"""Thick panels of a design, checked over its deployment: the result and its verdict.

:func:`fabricate_panels` bevels every hinge for its fold range over the motion plus the
clearance angle (:mod:`rigidfold.fabricate.solids`), checks every pair of solids over the
whole motion (:mod:`rigidfold.fabricate.collision`), doubles the relief at a vertex where
two panels without a common hinge still come too close there (up to
``settings.fabricate.relief_rounds`` times), and gives the verdict
(:class:`FabricationStatus`). When the thickness fails, thinner ones are tried (halving,
then bisection, ``settings.fabricate.thickness_tries`` in all) to name one that passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.collision import Clearance, check_clearance
from rigidfold.fabricate.motion import PanelMotion
from rigidfold.fabricate.panels import Panels
from rigidfold.fabricate.progress import check_size, step
from rigidfold.fabricate.solids import Solids, bevel_angles, thicken
from rigidfold.material import material_named
from rigidfold.outcomes import Outcome


class FabricationStatus(Outcome):
    """The verdict on thick panels of a design (the first that applies, in this order)."""

    NOT_DEPLOYABLE = (
        "not_deployable",
        "the design has no folding motion from flat, so its thick panels cannot be checked",
    )
    PANEL_TRIMMED_AWAY = (
        "panel_trimmed_away",
        "a panel is trimmed away by its bevels and reliefs",
    )
    TOO_THIN = "too_thin", "a panel is thinner than the minimum thickness once bevelled"
    COLLISION = "collision", "thick panels collide during the deployment"
    COLLISION_FREE = (
        "collision_free",
        "the thick panels deploy from flat to the design without collision",
    )


@dataclass(frozen=True, eq=False)
class Fabrication:
    """Thick panels of a design and the check of their deployment.

    status : FabricationStatus; message : the detail, in words.
    solids : Solids; motion : PanelMotion, or None when the design has none (NOT_DEPLOYABLE);
    clearance : Clearance, the check (None without a motion).
    thickness, min_thickness : metres; clearance_angle : radians; density : kg/m^3.
    relief_rounds : times the reliefs were deepened; passing_thickness : a thinner thickness
    that passes where this one does not (None when it passes, or none was found);
    thickness_tries : {thickness: status value} of the thinner thicknesses tried.
    """

    status: FabricationStatus
    message: str
    solids: Solids
    motion: PanelMotion | None
    clearance: Clearance | None
    thickness: float
    min_thickness: float
    clearance_angle: float
    density: float
    relief_rounds: int
    passing_thickness: float | None = None
    thickness_tries: tuple[tuple[float, str], ...] = ()

    @property
    def ok(self) -> bool:
        return self.status is FabricationStatus.COLLISION_FREE

    @property
    def panels(self) -> Panels:
        return self.solids.panels

    @property
    def masses(self) -> np.ndarray:
        """(P,) float64: mass of each panel's solid, kg."""
        return self.solids.volumes * self.density

    @property
    def fold_range(self) -> tuple[np.ndarray, np.ndarray]:
        """((H,), (H,)) closing fold range of each hinge from flat to the design, radians."""
        if self.motion is not None:
            return self.motion.range
        closing = self.panels.closing(self.panels.pattern.fold_angles)
        return np.minimum(closing, 0.0), np.maximum(closing, 0.0)

    def last_line(self) -> str:
        """The command's last line: the verdict, where panels meet and a thickness that
        would pass."""
        t_mm = self.thickness * 1e3
        if self.ok:
            c = self.clearance
            assert c is not None
            return (
                f"collision-free: {self.panels.n} panels {t_mm:g} mm thick deploy from flat to "
                f"the design (smallest gap {c.min_gap * 1e3:.1f} mm, hinge margin "
                f"{math.degrees(c.hinge_margin):.2f} degrees, {c.frames} frames)"
            )
        text = f"{self.status.message} at {t_mm:g} mm: {self.message}"
        if self.passing_thickness is not None:
            text += f"; {self.passing_thickness * 1e3:.3g} mm would pass"
        elif self.status is not FabricationStatus.NOT_DEPLOYABLE:
            text += "; no thinner thickness tried passes"
        return text

    def to_dict(self) -> dict:
        s = self.solids
        p = s.panels
        _low, high = self.fold_range
        area = float(p.areas.sum())
        return {
            "status": self.status.value,
            "message": self.message,
            "thickness_m": self.thickness,
            "side": p.side,
            "min_thickness_m": self.min_thickness,
            "clearance_angle_deg": math.degrees(self.clearance_angle),
            "density_kg_m3": self.density,
            "panels": p.n,
            "hinges": p.n_hinges,
            "area_m2": area,
            "volume_m3": s.total_volume,
            "volume_share": s.total_volume / (area * self.thickness) if area > 0 else None,
            "trimming_loss": s.trimming_loss,
            "mass_kg": float(self.masses.sum()),
            "relief_vertices": int((s.relief > 0).sum()),
            "relief_rounds": self.relief_rounds,
            "largest_fold_deg": math.degrees(float(high.max(initial=0.0))),
            "smallest_bevel_deg": math.degrees(float(s.bevel.min(initial=math.pi / 2))),
            "thinnest_panel": int(np.argmin(s.depth)) if p.n else None,
            "thinnest_depth_m": float(s.depth.min(initial=math.inf)) if p.n else None,
            "motion": None if self.motion is None else self.motion.to_dict(),
            "check": None if self.clearance is None else self.clearance.to_dict(),
            "passing_thickness_m": self.passing_thickness,
            "thickness_tries": [{"thickness_m": t, "status": v} for t, v in self.thickness_tries],
            "per_panel": [
                {
                    "panel": k,
                    "area_m2": float(p.areas[k]),
                    "volume_m3": float(s.volumes[k]),
                    "mass_kg": float(self.masses[k]),
                    "depth_m": float(s.depth[k]),
                    "hinges": len(p.hinges_of[k]),
                }
                for k in range(p.n)
            ],
        }


def fabricate_panels(
    panels: Panels,
    motion: PanelMotion | None,
    thickness: float,
    *,
    clearance_angle: float | None = None,
    min_thickness: float | None = None,
    density: float | None = None,
    motion_message: str = "",
    settings: Settings = DEFAULTS,
    search: bool = True,
) -> Fabrication:
    """Thick panels of ``thickness`` metres for ``panels`` and their check over ``motion``
    (None: the design has none). ``clearance_angle`` (radians), ``min_thickness`` (metres)
    and ``density``: default from ``settings`` (``min_thickness``:
    ``fabricate_min_depth`` times the thickness). With ``search``, a failing thickness is
    followed by thinner tries (see the module's text)."""
    check_size(panels.n, settings=settings)
    thinnest = check_thickness(thickness, panels.pattern.coords, settings=settings)
    c, least, rho = fabrication_values(
        thickness,
        clearance_angle=clearance_angle,
        min_thickness=min_thickness,
        density=density,
        settings=settings,
    )
    result = _evaluate(panels, motion, thickness, c, least, rho, motion_message, settings)
    if result.ok or not search or motion is None:
        return result
    tries: list[tuple[float, str]] = []
    good, bad = None, thickness
    share = least / thickness
    for k in range(settings.fabricate.thickness_tries):
        trial = bad / 2 if good is None else 0.5 * (good + bad)
        if trial < thinnest:  # below what the solids resolve: no try tells anything
            break
        step(
            f"a thinner try, {trial * 1e3:.3g} mm ({k + 1} of "
            f"{settings.fabricate.thickness_tries})",
            panels.n,
            settings=settings,
        )
        got = _evaluate(panels, motion, trial, c, share * trial, rho, "", settings)
        tries.append((trial, got.status.value))
        if got.ok:
            good = trial
        else:
            bad = trial
    return Fabrication(
        **{
            **{f: getattr(result, f) for f in result.__dataclass_fields__},
            "passing_thickness": good,
            "thickness_tries": tuple(tries),
        }
    )


def check_thickness(
    thickness: float, coords: np.ndarray, *, settings: Settings = DEFAULTS
) -> float:
    """The thinnest panels built for a design of vertices ``coords`` (V, 3), metres:
    ``settings.fabricate.thinnest`` times its size (the diagonal of its box). ValueError (one
    line, naming the thickness) for a ``thickness`` below it, whose solids the geometry
    cannot resolve next to the design's size."""
    coords = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    size = float(np.linalg.norm(np.ptp(coords, axis=0))) if len(coords) else 0.0
    thinnest = settings.fabricate.thinnest * size
    if isinstance(thickness, int | float | np.number) and 0 < thickness < thinnest:
        raise RigidfoldError(
            f"thickness {thickness * 1e3:.3g} mm is too thin for a design {size:.3g} m across: "
            f"its solids cannot be resolved below {thinnest * 1e3:.3g} mm "
            f"({settings.fabricate.thinnest:g} of its size, Settings.fabricate.thinnest)"
        )
    return thinnest


def fabrication_values(
    thickness: float,
    *,
    clearance_angle: float | None = None,
    min_thickness: float | None = None,
    density: float | None = None,
    settings: Settings = DEFAULTS,
) -> tuple[float, float, float]:
    """(clearance angle in radians, minimum thickness in metres, density in kg/m^3) of thick
    panels ``thickness`` metres thick, each None taken from ``settings`` (the minimum
    thickness: ``fabricate.min_depth`` times the thickness); ValueError (one line, naming
    what was received) for a thickness that is not a positive number, an angle outside
    [0, 90) degrees, a density that is not positive, a minimum thickness outside
    [0, thickness]."""
    if (
        isinstance(thickness, bool)
        or not isinstance(thickness, int | float | np.number)
        or not (math.isfinite(thickness) and thickness > 0)
    ):
        raise RigidfoldError(f"thickness must be a positive number of metres, got {thickness!r}")
    c = settings.fabricate.clearance_angle if clearance_angle is None else clearance_angle
    if isinstance(c, bool) or not (isinstance(c, int | float | np.number) and 0 <= c < math.pi / 2):
        shown = f"{math.degrees(c):g}" if isinstance(c, int | float | np.number) else repr(c)
        raise RigidfoldError(f"clearance angle must lie in [0, 90) degrees, got {shown}")
    # one density per material: the default is that of the default panels' material
    rho = density if density is not None else material_named(settings.structure.material).density
    if (
        isinstance(rho, bool)
        or not isinstance(rho, int | float | np.number)
        or not (math.isfinite(rho) and rho > 0)
    ):
        raise RigidfoldError(f"density must be a positive number of kg/m^3, got {rho!r}")
    least = settings.fabricate.min_depth * thickness if min_thickness is None else min_thickness
    if (
        isinstance(least, bool)
        or not isinstance(least, int | float | np.number)
        or not (math.isfinite(least) and 0 <= least <= thickness)
    ):
        raise RigidfoldError(
            f"the minimum thickness must lie from 0 to the thickness ({thickness * 1e3:g} mm), "
            f"got {least!r} m"
        )
    return float(c), float(least), float(rho)


def _evaluate(
    panels: Panels,
    motion: PanelMotion | None,
    thickness: float,
    clearance_angle: float,
    min_thickness: float,
    density: float,
    motion_message: str,
    settings: Settings,
) -> Fabrication:
    """One thickness: solids, check (deepening reliefs as needed) and verdict."""
    if motion is not None:
        high = motion.range[1]
    else:
        high = np.maximum(panels.closing(panels.pattern.fold_angles), 0.0)
    bevel = bevel_angles(high, clearance_angle)
    relief = np.zeros(panels.pattern.n_vertices)
    relief[panels.relief_vertices] = settings.fabricate.vertex_relief * thickness
    rounds = 0
    frames = 0 if motion is None else motion.n_frames
    step(
        f"solids of {panels.n} panels {thickness * 1e3:.3g} mm thick and their check over "
        f"{frames} frames",
        panels.n,
        settings=settings,
    )
    solids = thicken(panels, thickness, bevel, relief)
    around = [h for h, (a, b) in enumerate(solids.hinge_limits[1]) if a or b]
    if around:  # pieces reaching around a hinge's axis touch the neighbour at its ends
        ends = panels.hinge_vertices[around].ravel()
        relief[ends] = np.maximum(relief[ends], settings.fabricate.vertex_relief * thickness)
    while True:
        if rounds or around:
            solids = thicken(panels, thickness, bevel, relief)
        check = None
        if motion is not None:
            check = check_clearance(
                solids,
                motion,
                clearance=settings.fabricate.clearance(thickness),
                subdivisions=settings.fabricate.subdivisions,
            )
        if check is None or check.collision_free or rounds >= settings.fabricate.relief_rounds:
            break
        vertices = {m.vertex for m in check.meetings if m.kind == "gap" and m.vertex >= 0}
        if not vertices:
            break
        relief[sorted(vertices)] = np.maximum(relief[sorted(vertices)] * 2, thickness)
        rounds += 1
    status, message = _verdict(solids, check, min_thickness, motion_message, settings)
    return Fabrication(
        status=status,
        message=message,
        solids=solids,
        motion=motion,
        clearance=check,
        thickness=thickness,
        min_thickness=min_thickness,
        clearance_angle=clearance_angle,
        density=density,
        relief_rounds=rounds,
    )


def _verdict(
    solids: Solids,
    check: Clearance | None,
    min_thickness: float,
    motion_message: str,
    settings: Settings,
) -> tuple[FabricationStatus, str]:
    p = solids.panels
    if check is None:
        return FabricationStatus.NOT_DEPLOYABLE, motion_message or "no folding motion"
    t = solids.thickness
    share = solids.volumes / np.maximum(p.areas * t, 1e-300)
    faces = solids.empty_faces
    emptied = p.label[faces]  # the panel of each triangle trimmed away completely
    low = share < settings.fabricate.trimmed_away
    gone = sorted(set(emptied.tolist()) | set(np.flatnonzero(low).tolist()))
    if gone:
        # the panel that lost the most of its volume, in the words of what it lost
        k = min(gone, key=lambda j: (share[j], j))
        if low[k]:
            what = (
                f"panel {k} keeps {100 * share[k]:.0f}% of its area x thickness (less than "
                f"{100 * settings.fabricate.trimmed_away:g}%)"
            )
        else:
            n = int((emptied == k).sum())
            what = (
                f"panel {k} has {n} of its {len(p.triangles[k])} triangles trimmed away completely"
            )
        return FabricationStatus.PANEL_TRIMMED_AWAY, what + (
            f" ({len(gone) - 1} more panels)" if len(gone) > 1 else ""
        )
    thin = np.flatnonzero(solids.depth < min_thickness * (1 - 1e-9))
    if len(thin):
        k = int(thin[np.argmin(solids.depth[thin])])
        return FabricationStatus.TOO_THIN, (
            f"panel {k} is {solids.depth[k] * 1e3:.1f} mm deep at most, below the minimum "
            f"{min_thickness * 1e3:g} mm" + (f" ({len(thin)} panels)" if len(thin) > 1 else "")
        )
    if not check.collision_free:
        if check.meetings:
            worst = check.meetings[0]
            more = len(check.meetings) - 1
            return FabricationStatus.COLLISION, worst.describe() + (
                f" ({more} more pairs)" if more else ""
            )
        return FabricationStatus.COLLISION, (
            f"the gap between panels {check.gap_panels[0]} and {check.gap_panels[1]} is proven "
            f"only down to {check.bound * 1e3:.2f} mm near {100 * check.gap_fraction:.0f}% "
            f"folded, below the clearance {check.clearance * 1e3:g} mm"
        )
    return FabricationStatus.COLLISION_FREE, (
        f"smallest gap {check.min_gap * 1e3:.1f} mm between panels {check.gap_panels[0]} and "
        f"{check.gap_panels[1]} at {100 * check.gap_fraction:.0f}% folded"
    )


def check_sheet(
    sheet: tuple[float, float], *, settings: Settings = DEFAULTS, shown: object = None
) -> tuple[float, float]:
    """A stock sheet ``(width, height)`` in mm as floats, each positive, finite and at most
    ``settings.limits.max_sheet_size``. Raises RigidfoldError naming what was received
    (``shown``, where given: the text it was read from)."""
    said = sheet if shown is None else shown
    try:
        w, h = (float(x) for x in sheet)
        if any(isinstance(x, bool | str) for x in sheet):
            raise TypeError
    except (TypeError, ValueError):
        w = h = math.nan
    if not all(math.isfinite(x) and x > 0 for x in (w, h)):
        raise RigidfoldError(f"sheet must be (width, height) in millimetres, got {said!r}")
    most = settings.limits.max_sheet_size
    if max(w, h) > most:
        raise RigidfoldError(
            f"sheet must be at most {most:g} mm each way (Settings.limits.max_sheet_size), "
            f"got {said!r}"
        )
    return w, h
