"""Steps 8 and 9 of one shape: development diagram, large-deformation check, folding motion.

:func:`verify` is what ``rigidfold generate`` runs for every accepted solution and what
``rigidfold deform`` runs on a FOLD file. The development (Step 8) always runs; the
OpenSees analysis only when asked; the motion is traced from the development when the
development converged. Every stage's failure is a status in the result, never an exception.

Two stages judge whether the shape folds flat, each its own way: the OpenSees analysis
drives the frame's nodes vertically to the plane in equal load steps (whatever path that
forces, the members deform as they must), the motion tracer follows a rigid-folding path
(steepest descent of the folding measure; a 1-DOF shape's one path). :class:`Verdicts`
states both and, when they differ, why.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rigidfold.config import DEFAULTS, Settings
from rigidfold.deform.analysis import DeformResult, deform
from rigidfold.deform.motion import Motion, MotionStatus, folding_motion
from rigidfold.develop import Development, DevelopStatus, develop
from rigidfold.mechanism.path import FoldingPath
from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome

if TYPE_CHECKING:
    from rigidfold.material import Panel


class Agreement(Outcome):
    """Whether the large-deformation analysis and the folding motion agree."""

    AGREE = "agree", "the large-deformation analysis and the folding motion agree"
    DIFFER = "differ", "the large-deformation analysis and the folding motion differ"


@dataclass(frozen=True)
class Verdicts:
    """The two verdicts on whether a shape folds flat, side by side.

    plane : the OpenSees frame reached the plane (Step 9); motion : the folding motion was
    traced from the plane to the design; reason : why they differ, one sentence ("" when
    they agree).
    """

    plane: bool
    motion: bool
    reason: str

    @property
    def agreement(self) -> Agreement:
        return Agreement.AGREE if self.plane == self.motion else Agreement.DIFFER

    @property
    def line(self) -> str:
        """Both verdicts in one line, and why they differ when they do."""
        plane = "reached the plane" if self.plane else "did not reach the plane"
        motion = "traced" if self.motion else "not traced"
        head = f"large deformation {plane}, folding motion {motion}"
        if self.agreement is Agreement.AGREE:
            return f"{head}: they agree"
        return f"{head}: they differ, because {self.reason}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "reached_plane": self.plane,
            "motion_traced": self.motion,
            "agreement": self.agreement.value,
            "reason": self.reason,
            "line": self.line,
        }


def compare(
    development: Development,
    deformation: DeformResult,
    motion: Motion,
    settings: Settings = DEFAULTS,
) -> Verdicts:
    """The verdicts of the OpenSees analysis and the folding motion on one shape and, when
    they differ, the reason, from what the stages found: how far the development diagram is
    from the shape (against ``motion_length_tol``), the mechanism's DOF and whether its one
    path turns back (the motion finds both out when it fails), the message of the analysis,
    and how much the frame deformed on its way to the plane (max |dl|, max |drho_fix|)."""
    plane, traced = deformation.reached_plane, motion.status is MotionStatus.OK
    strain = (
        f"max |dl| = {deformation.max_dl_mm:.3g} mm, max |drho_fix| = "
        f"{deformation.max_drho_fix_deg:.3g} deg"
    )
    if plane == traced:
        reason = ""
    elif traced:
        reason = (
            "a rigid-folding path to the plane exists (traced, max |dl|/l = "
            f"{motion.max_length_error:.2g}), while the OpenSees analysis, which drives the "
            "frame's nodes vertically to the plane rather than along that path, did not get "
            f"there: {deformation.message} ({strain})"
        )
    else:
        why, how = _not_traced(development, motion, settings)
        reason = (
            f"{why}, while the OpenSees frame, its nodes driven vertically to the plane, got "
            f"there{how} ({strain})"
        )
    return Verdicts(plane, traced, reason)


def _not_traced(development: Development, motion: Motion, settings: Settings) -> tuple[str, str]:
    """(why the folding motion was not traced, how the OpenSees frame got to the plane
    instead: "" or " along another") for :func:`compare`."""
    error, tol = development.max_length_error, settings.deformation.motion_length_tol
    if error > tol:
        return (
            "the shape is not developable within the motion's tolerance (its development's "
            f"max |dl|/l = {error:.2g} > motion_length_tol = {tol:g}), so no rigid-folding path "
            "reaches the plane",
            "",
        )
    if motion.status is MotionStatus.CUT:
        return "the run's time limit ended the motion's trace before the plane", ""
    if motion.dof == 0:
        return (
            "the shape has no mechanism (DOF 0 with its fixed creases), so no rigid-folding "
            "path leaves it",
            "",
        )
    if motion.dof == 1 and motion.turned_back:
        return "the shape's one rigid-folding path turns back before the plane", ""
    if motion.dof == 1:
        return (
            "the motion tracer could not follow the shape's one folding path to the plane (see "
            "its message)",
            "",
        )
    many = "several" if motion.dof is None else str(motion.dof)
    return (
        f"with {many} DOF the folding path is not unique: the motion tracer follows one "
        "(steepest descent of the folding measure) and could not continue it",
        " along another",
    )


@dataclass
class Verification:
    """Results of Steps 8-9 for one shape; ``deformation`` / ``motion`` None when not run;
    ``settings`` those they ran with."""

    development: Development
    deformation: DeformResult | None
    motion: Motion | None
    times: dict
    settings: Settings = DEFAULTS

    @property
    def verdicts(self) -> Verdicts | None:
        """The large-deformation analysis's and the motion's verdicts side by side
        (:func:`compare`); None unless both ran."""
        if self.deformation is None or self.motion is None:
            return None
        return compare(self.development, self.deformation, self.motion, self.settings)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures of every stage (for log.jsonl, summary.json and the CLI)."""
        verdicts = self.verdicts
        out: dict[str, Any] = {
            "development": self.development.to_dict(),
            "deformation": None if self.deformation is None else self.deformation.to_dict(),
            "motion": None if self.motion is None else self.motion.to_dict(),
            "verdicts": None if verdicts is None else verdicts.to_dict(),
            "time_s": dict(self.times),
        }
        if self.deformation is not None:
            out["deformation"]["history"] = self.deformation.history
        return out


def verify(
    pattern: CreasePattern,
    *,
    run_deform: bool = True,
    run_motion: bool = True,
    support_face: int | None = None,
    dof: int | None = None,
    path: FoldingPath | None = None,
    panel: Panel | None = None,
    deadline: float | None = None,
    settings: Settings = DEFAULTS,
) -> Verification:
    """Development (Step 8), large-deformation check (Step 9) and motion of one shape.

    ``dof``, ``path``: the shape's DOF and traced folding path where they are known
    (:func:`rigidfold.deform.folding_motion` traces the path otherwise). ``panel``: Step 9's
    frame as strips of these panels (:func:`rigidfold.deform.analysis.panel_section`)
    instead of the paper's tubes. ``deadline`` (of ``time.monotonic()``): the motion's trace
    ends there (:attr:`rigidfold.deform.MotionStatus.CUT`)."""
    times = {}
    t0 = time.perf_counter()
    development = develop(pattern, settings=settings)
    times["develop"] = time.perf_counter() - t0
    deformation = None
    if run_deform:
        t0 = time.perf_counter()
        deformation = deform(
            pattern,
            support_face=support_face,
            material=None if panel is None else panel.material,
            thickness=None if panel is None else panel.thickness,
            settings=settings,
        )
        times["deform"] = time.perf_counter() - t0
    motion = None
    if run_motion and development.status is DevelopStatus.CONVERGED:
        t0 = time.perf_counter()
        motion = folding_motion(
            pattern,
            development.coords2d,
            support_face=support_face,
            dof=dof,
            path=path,
            deadline=deadline,
            settings=settings,
        )
        times["motion"] = time.perf_counter() - t0
    return Verification(development, deformation, motion, times, settings)
