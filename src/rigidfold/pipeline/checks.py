"""The one check pipeline of a solution, for ``rigidfold generate``'s run writer and the study
worker alike.

:func:`check_solution` runs the checks of an accepted solution as the options ask: the
development diagram (Step 8, always), the folding motion, the large deformation (Step 9),
the fit to the target and the deployability check's path, and returns its
:class:`~rigidfold.rundir.SolutionRecord` with what was computed (:class:`Checked`).
:func:`check_final` adds the final design as built, its thick panels and its structure
(``GenerateOptions.fabricate`` and ``.structure``, :mod:`rigidfold.pipeline.built`), whose files
go under the run's directory. Neither writes a solution file, the log or the summary: that
is the run writer's (:class:`rigidfold.pipeline.RunWriter`). A new check of a run is a field of
the record, its :class:`~rigidfold.rundir.Stage` where it can fail (:mod:`rigidfold.rundir.schema`)
and its computation here.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rigidfold.config import Settings
from rigidfold.deform import MotionStatus, Verification, verify
from rigidfold.drive import DriveResult
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate import Fabrication
from rigidfold.generate import GenerateOptions, Solution
from rigidfold.generate.case import Case
from rigidfold.mechanism.path import FoldingPath
from rigidfold.pipeline.built import deployment_drive, structure_check, thick_panels
from rigidfold.rundir.schema import NOT_DEVELOPED, FitStatus, SolutionRecord
from rigidfold.structure import StructureCheck


@dataclass(frozen=True, eq=False)
class Checked:
    """A solution checked by :func:`check_solution`.

    record : its :class:`~rigidfold.rundir.SolutionRecord` (the figures of every check that
    ran); verification : the results of Steps 8-9 and the motion
    (:class:`rigidfold.deform.Verification`), which its files are written from.
    """

    record: SolutionRecord
    verification: Verification

    @property
    def coords2d(self) -> np.ndarray:
        """(V, 2) float64: the development diagram (Step 8), metres."""
        return self.verification.development.coords2d

    @property
    def motion(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(frames (K, V, 3), fraction folded (K,)) of the folding motion, None unless it
        was traced."""
        return traced_motion(self.verification)


@dataclass(frozen=True, eq=False)
class Built:
    """The final design as built (:func:`check_final`).

    record : its record with the ``fabrication``, ``structure`` and ``drive`` figures (None
    where not asked); fabrication, structure, drive : the results themselves, None where not
    asked or where the check could not run (its figures then say why, status "error").
    """

    record: SolutionRecord
    fabrication: Fabrication | None = None
    structure: StructureCheck | None = None
    drive: DriveResult | None = None


def traced_motion(check: Verification) -> tuple[np.ndarray, np.ndarray] | None:
    """(frames (K, V, 3), parameter (K,)) of the folding motion, None unless it was traced."""
    if check.motion is None or check.motion.status is not MotionStatus.OK:
        return None
    return check.motion.frames, check.motion.parameter


def check_solution(
    solution: Solution,
    case: Case,
    options: GenerateOptions,
    *,
    motion: bool,
    deform: bool,
    path: FoldingPath | None = None,
) -> Checked:
    """Check one accepted ``solution`` of ``case``: Step 8; the folding motion with
    ``motion`` and Step 9 with ``deform`` (neither on a DOF-0 shape, which has no motion;
    Step 9's frame of strips of the panels with ``options.material``, supported at
    ``options.support_face``); the fit to the target (``max_abs_dz_m``, ``rms_dz_m``, and
    whether it is within ``dz``: ``Stage.FIT``) and the deployability check's path where it
    was traced (``solution.path``). The motion follows ``solution.path``, else ``path`` (the
    final design's, traced once by the pipeline), else it traces its own."""
    dof = solution.mechanism.dof
    pattern = solution.result.pattern
    settings = case.settings
    check = verify(
        pattern,
        run_deform=deform and dof > 0,
        run_motion=motion and dof > 0,
        dof=dof,
        path=solution.path or path,
        support_face=options.support_face,
        panel=options.frame_panel(settings),
        settings=settings,
    )
    fit = _fit(case.deviation(pattern.coords), settings)
    record = SolutionRecord.from_check(
        solution.step,
        dof,
        check,
        fit=fit,
        deployability=None if solution.path is None else solution.path.to_dict(),
    )
    return Checked(record, check)


def solution_record(solution: Solution, case: Case) -> SolutionRecord:
    """The record of an accepted ``solution`` of ``case`` whose checks are not run as it comes
    (``--check final``: every solution but the final design): its fit to the target and its
    deployability check's path where it was traced; Step 8 is not run, its figures say so
    (:data:`~rigidfold.rundir.schema.NOT_COMPUTED`, a stage that did not run), and neither is
    anything that needs the diagram."""
    pattern = solution.result.pattern
    return SolutionRecord(
        solution.step,
        solution.mechanism.dof,
        fit=_fit(case.deviation(pattern.coords), case.settings),
        development=dict(NOT_DEVELOPED),
        deployability=None if solution.path is None else solution.path.to_dict(),
    )


def _fit(dz: np.ndarray, settings: Settings) -> dict:
    """The fit of a solution whose vertices lie ``dz`` (V,) above the target, metres: the
    largest and RMS |dz|, and whether the largest is within the bound ``settings.design.dz``
    by ``dz_bound_tol`` of it (:class:`~rigidfold.rundir.schema.FitStatus`, ``Stage.FIT``)."""
    worst, bound = float(np.abs(dz).max()), settings.design.dz
    within = worst <= bound * (1 + settings.design.dz_bound_tol)
    return {
        "max_abs_dz_m": worst,
        "rms_dz_m": float(np.sqrt(np.mean(dz**2))),
        "status": (FitStatus.WITHIN if within else FitStatus.BEYOND).value,
        "message": f"max |z - target| {worst * 1e3:.4g} mm, bound dz {bound * 1e3:.4g} mm",
    }


def check_final(
    checked: Checked,
    solution: Solution,
    options: GenerateOptions,
    run_dir: Path,
    name: str,
) -> Built:
    """The final design (``solution``, ``checked`` by :func:`check_solution`) as built, as
    ``options`` ask: its thick panels (``options.fabricate``, over the motion it was traced
    along, or its folding path) into ``run_dir/final/thick/`` and its structure
    (``options.structure``) into ``run_dir/final/structure/`` and its deployment drive
    (``options.drive``) into ``run_dir/final/deploy/``, files named after ``name``
    (its solution file's stem). A check that cannot run on this design (RigidfoldError) is
    a failed stage with its message: the run still ends with its verdict, summary.json and
    report."""
    pattern = solution.result.pattern
    record, fab, st = checked.record, None, None
    if options.fabricate is not None:
        try:
            figures, fab = thick_panels(
                run_dir,
                name,
                pattern,
                checked.coords2d,
                options,
                frames=checked.motion,
                path=solution.path,
            )
        except RigidfoldError as exc:
            figures = _not_checked("the thick panels", exc)
        record = replace(record, fabrication=figures)
    if options.structure is not None:
        try:
            figures, st = structure_check(run_dir, name, pattern, options)
        except RigidfoldError as exc:
            figures = _not_checked("the structure", exc)
        record = replace(record, structure=figures)
    drive = None
    if options.drive is not None:
        try:
            figures, drive = deployment_drive(
                run_dir, name, options, frames=checked.motion, path=solution.path
            )
        except RigidfoldError as exc:
            figures = _not_checked("the deployment drive", exc)
        record = replace(record, drive=figures)
    return Built(record, fab, st, drive)


def _not_checked(what: str, exc: Exception) -> dict:
    """The figures of a check of the final design that could not run: status "error" and
    why (a failed :class:`~rigidfold.rundir.Stage` with this message)."""
    return {
        "status": "error",
        "message": f"{what} could not be checked: {' '.join(str(exc).split())}",
    }
