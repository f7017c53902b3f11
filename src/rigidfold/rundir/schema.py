"""The schema of a run directory: summary.json, log.jsonl and the solution files, read and
written through one set of types.

:class:`SolutionRecord` is one solution's checks (``summary.json``'s ``per_solution``; the
figures in its FOLD file), :class:`rigidfold.generate.Attempt` one solve (a line of
``log.jsonl``, of the shape :data:`LOG_SHAPE` made from it),
:class:`RunSummary` the whole of ``summary.json``. What the readers rely on is checked
against a shape first (:data:`SUMMARY_SHAPE`, :data:`LOG_SHAPE`, :func:`check_shape`), so a
damaged file is a one-line ValueError naming the file and the key. Both files carry
:data:`SCHEMA_VERSION` (summary.json's ``schema_version``, log.jsonl's first line), and a
run of another version is refused in one line (:func:`check_version`). :class:`Stage` and
:meth:`SolutionRecord.failed_stages` say, once for the writer, the report and the study,
which check of a solution failed.
"""

from __future__ import annotations

import dataclasses
import os
import typing
from dataclasses import dataclass, field, fields
from typing import Annotated, Any, TypedDict

import numpy as np

from rigidfold.deform import DeformStatus, MotionStatus, Verification
from rigidfold.develop import DevelopStatus
from rigidfold.drive import DriveStatus
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate import FabricationStatus
from rigidfold.generate import Attempt, Generation, Stop
from rigidfold.outcomes import Outcome
from rigidfold.rundir.json_shapes import (
    Finite,
    Nullable,
    Record,
    check_shape,
    received,
    record_shape,
)
from rigidfold.structure import StructureStatus

SCHEMA_VERSION = 5
"""The version of the files of a run directory this rigidfold writes and reads: summary.json's
``schema_version`` and the header line of log.jsonl (``{"schema_version": 5}``; 2: a
solution's ``fit`` has its ``status``; 3: a solution's ``development`` may be
:data:`NOT_COMPUTED`, the diagram drawn for the final design only; 4: a solution's ``drive``,
``generate --deploy``; 5: the counters under their :class:`RunSummary` names, ``n_lock``
and ``mean_f_accepted`` where version 4 wrote ``N_lock`` and ``mean_F_accepted``). A run of
another
version (0: written before rigidfold recorded one) is refused (:func:`check_version`), not
read through layers of old formats."""

LOG_FILE = "log.jsonl"
"""The attempt log of a run: JSON Lines, a header (``{"schema_version": N}``), then one line
per attempt (:meth:`rigidfold.generate.Attempt.to_dict`) appended as the run goes; an attempt
whose outcome changed later (backtracking) is appended again with the same ``index``, and
the last line of an index is its record."""


def check_version(version, file: str | os.PathLike) -> None:
    """RigidfoldError (one line naming ``file`` and both versions) unless ``version`` (None:
    the file has none, written before rigidfold recorded one) is :data:`SCHEMA_VERSION`."""
    if version == SCHEMA_VERSION and not isinstance(version, bool):
        return
    given = "0 (none recorded)" if version is None else received(version)
    raise RigidfoldError(
        f"'{file}' was written by run schema version {given}; this rigidfold reads version "
        f"{SCHEMA_VERSION}"
    )


NOT_COMPUTED = "not_computed"
"""The ``status`` of a stage's figures in a solution's record when the stage was not run on
it: the development diagram (Step 8) of a solution that is not the final design under
``--check final`` (:data:`NOT_DEVELOPED`). :meth:`SolutionRecord.ran` is False for it."""

NOT_DEVELOPED = {
    "status": NOT_COMPUTED,
    "message": "the development diagram is drawn for the final design only (--check all: for "
    "every solution; rigidfold develop FILE: for this one)",
}
"""The ``development`` figures of a solution whose diagram was not drawn."""

HISTORY_SHAPE = [
    Record(
        {k: float for k in ("load_factor", "mean_dl_mm", "max_dl_mm", "max_drho_fix_deg")},
        ("load_factor", "mean_dl_mm", "max_dl_mm", "max_drho_fix_deg"),
    )
]
"""The large-deformation history of a solution file (``deformation.history``)."""


DESIGN_SHAPE = Record(
    {
        "rigidfold:step": int,
        "rigidfold:dof": int,
        "rigidfold:deformation": Nullable(Record({"history": Nullable(HISTORY_SHAPE)})),
    }
)
"""What the report reads of rigidfold's keys in a solution file (see :data:`SUMMARY_SHAPE`)."""


LOG_SHAPE = record_shape(Attempt)
"""The shape of each attempt line of ``log.jsonl`` (see :data:`SUMMARY_SHAPE`), made from
:class:`rigidfold.generate.Attempt`, which the line is read into (:func:`record_shape`: each
field's shape from its type, those without a default required)."""

LOG_NAN_FIELDS = tuple(
    name for name, hint in typing.get_type_hints(Attempt).items() if hint is float
)
"""The fields of :class:`~rigidfold.generate.Attempt` that are floats, never None: a NaN of
theirs is written as null and read back as NaN."""


class Stage(Outcome):
    """A check of a solution after generation; the message says how it fails."""

    DEVELOPMENT = "development", "development diagram (Step 8) failed"
    MOTION = "motion", "folding motion not traced"
    DEFORMATION = "deformation", "large deformation (Step 9) did not reach the plane"
    FABRICATION = (
        "fabrication",
        "thick panels collide, are trimmed away or cannot be checked over the motion",
    )
    STRUCTURE = "structure", "the structure check failed"
    DRIVE = "drive", "no single crease, pair or cable drives the deployment within the limits"
    FIT = "fit", "the design lies farther from the target surface than dz allows"


class FitStatus(Outcome):
    """How far a solution lies from its target surface (:data:`Stage.FIT`): its largest
    |z - target| within the bound ``Settings.design.dz``, by ``dz_bound_tol`` of it."""

    WITHIN = "within", "within dz of the target surface"
    BEYOND = "beyond", "farther from the target surface than dz"


@dataclass(frozen=True)
class StageRule:
    """How a :class:`Stage` is judged and shown.

    passing : the status its figures pass with, a member of its result's
    :class:`~rigidfold.outcomes.Outcome` enum (whose values its ``status`` holds); name : its
    name among the report's checks (:meth:`rigidfold.rundir.RunData.checks`); detailed : its
    figures' ``message`` says more than the :class:`Stage` message (in the verdict and the
    report).
    """

    passing: Outcome
    name: str
    detailed: bool = False


STAGES: dict[Stage, StageRule] = {
    Stage.DEVELOPMENT: StageRule(DevelopStatus.CONVERGED, "development"),
    Stage.MOTION: StageRule(MotionStatus.OK, "folding motion"),
    Stage.DEFORMATION: StageRule(DeformStatus.REACHED_PLANE, "large deformation"),
    Stage.FABRICATION: StageRule(FabricationStatus.COLLISION_FREE, "thick panels", True),
    Stage.STRUCTURE: StageRule(StructureStatus.PASSED, "structure", True),
    Stage.DRIVE: StageRule(DriveStatus.DRIVEN, "deployment drive", True),
    Stage.FIT: StageRule(FitStatus.WITHIN, "fit to the target", True),
}
"""Every :class:`Stage`'s rule: the one place that says when a check of a solution passes."""


class DevelopmentFigures(TypedDict, total=False):
    """What is read of a solution's ``development``: Step 8's figures
    (:meth:`rigidfold.develop.Development.to_dict`), or :data:`NOT_DEVELOPED`."""

    status: str | None
    D: float | None
    flipped: int | None
    overlaps: int | None


class MotionFigures(TypedDict, total=False):
    """What is read of a solution's ``motion`` (:meth:`rigidfold.deform.Motion.to_dict`)."""

    status: str | None
    max_length_error: float | None


class DeployabilityFigures(TypedDict, total=False):
    """What is read of a solution's ``deployability``, its folding path
    (:meth:`rigidfold.mechanism.path.FoldingPath.to_dict`)."""

    status: str | None
    deploys: bool | None


class DeformationFigures(TypedDict, total=False):
    """What is read of a solution's ``deformation``, Step 9's figures
    (:meth:`rigidfold.deform.DeformResult.to_dict`)."""

    status: str | None
    reached_plane: bool | None
    mean_dl_mm: float | None
    max_dl_mm: float | None
    mean_drho_fix_deg: float | None
    max_drho_fix_deg: float | None


class VerdictsFigures(TypedDict, total=False):
    """What is read of a solution's ``verdicts`` (:meth:`rigidfold.deform.Verdicts.to_dict`)."""

    agreement: str | None
    reason: str | None


class FitFigures(TypedDict, total=False):
    """What is read of a solution's ``fit`` to its target (:data:`Stage.FIT`)."""

    max_abs_dz_m: float | None
    status: str | None
    message: str | None


class ClosestPair(TypedDict, total=False):
    """The closest pair of thick panels over the motion (``fabrication.closest``)."""

    panels: tuple[int, int] | None
    fraction: float | None
    detail: str | None


class FabricationFigures(TypedDict, total=False):
    """What is read of a solution's ``fabrication``, its thick panels
    (:func:`rigidfold.pipeline.built.thick_panels`)."""

    status: str | None
    message: str | None
    thickness_m: float | None
    panels: int | None
    min_gap_m: float | None
    trimming_loss: float | None
    closest: ClosestPair | None
    solids: str | None


class StructureFigures(TypedDict, total=False):
    """What is read of a solution's ``structure``, the check under load."""

    status: str | None
    message: str | None
    max_displacement_m: float | None
    allowed_displacement_m: float | None
    frequencies_Hz: list[Finite] | None
    figure: str | None


class DriveFigures(TypedDict, total=False):
    """What is read of a solution's ``drive``, the deployment drive (``generate --deploy``)."""

    status: str | None
    message: str | None
    files: list[str] | None


@dataclass(frozen=True)
class SolutionRecord:
    """The checks of one accepted solution: an entry of ``summary.json``'s ``per_solution``.

    step, dof : int (None in a damaged file); fit : ``max_abs_dz_m``, ``rms_dz_m``, its
    ``status`` (:class:`FitStatus`) and ``message``;
    development, motion, deformation, verdicts : each stage's figures (its ``to_dict()``;
    None where it did not run); deployability : the folding path's
    (:meth:`rigidfold.mechanism.path.FoldingPath.to_dict`), None where it was not traced;
    time_s : seconds per stage. The keys of a stage's figures that are read are declared
    once, in its TypedDict (``Annotated[dict | None, DevelopmentFigures]``, ...), which
    makes their shape (:data:`SOLUTION_SHAPE`).
    """

    step: int | None = None
    dof: int | None = None
    fit: Annotated[dict | None, FitFigures] = None
    development: Annotated[dict | None, DevelopmentFigures] = None
    deformation: Annotated[dict | None, DeformationFigures] = None
    motion: Annotated[dict | None, MotionFigures] = None
    verdicts: Annotated[dict | None, VerdictsFigures] = None
    time_s: dict = field(default_factory=dict)
    deployability: Annotated[dict | None, DeployabilityFigures] = None
    fabrication: Annotated[dict | None, FabricationFigures] = None
    structure: Annotated[dict | None, StructureFigures] = None
    drive: Annotated[dict | None, DriveFigures] = None

    @classmethod
    def from_check(
        cls,
        step: int,
        dof: int,
        check: Verification,
        *,
        fit: dict | None = None,
        deployability: dict | None = None,
    ) -> SolutionRecord:
        """The record of Steps 8-9 run on a solution (:func:`rigidfold.deform.verify`)."""
        figures = check.to_dict()
        return cls(
            step=step,
            dof=dof,
            fit=fit,
            development=figures["development"],
            deformation=figures["deformation"],
            motion=figures["motion"],
            verdicts=figures["verdicts"],
            time_s=figures["time_s"],
            deployability=deployability,
        )

    @classmethod
    def from_dict(cls, data: dict) -> SolutionRecord:
        """A record of ``summary.json`` (checked with :data:`SUMMARY_SHAPE`); keys of
        other versions are ignored, missing ones are None."""
        known = _known_fields(cls, data)
        known["time_s"] = dict(known.get("time_s", {}))
        return cls(**known)

    def to_dict(self, *, history: bool = True) -> dict:
        """The record as JSON values; ``history=False`` leaves out the large-deformation
        history (``summary.json`` keeps it in the solution's FOLD file only)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        if not history and self.deformation is not None:
            out["deformation"] = {k: v for k, v in self.deformation.items() if k != "history"}
        return out

    def ran(self, stage: Stage) -> bool:
        """Whether ``stage`` ran on this solution: its figures are there and do not say
        :data:`NOT_COMPUTED` (the development ran unless its figures say so: a record read
        back without them counts it as run, as written before it could be skipped)."""
        figures = getattr(self, stage.value)
        if figures is None:
            return stage is Stage.DEVELOPMENT
        return not (isinstance(figures, dict) and figures.get("status") == NOT_COMPUTED)

    def status(self, stage: Stage) -> Outcome | str | None:
        """The status of ``stage`` as a member of its result's enum (that of
        ``STAGES[stage].passing``), as text where it is none of them (``"error"``: a check
        of the final design that could not run); None where the stage did not run (or its
        figures have no status)."""
        value = (getattr(self, stage.value) or {}).get("status") if self.ran(stage) else None
        if not isinstance(value, str):
            return None
        try:
            return type(STAGES[stage].passing)(value)
        except ValueError:
            return value

    def passed(self, stage: Stage) -> bool | None:
        """Whether ``stage`` passed (its status is ``STAGES[stage].passing``: the development
        converged, the motion was traced, the frame reached the plane, the thick panels
        deploy without collision, the structure check passed); None where it did not run."""
        if not self.ran(stage):
            return None
        return self.status(stage) is STAGES[stage].passing

    def detail(self, stage: Stage) -> str:
        """The words of a stage that says more than its :class:`Stage` message (its figures'
        ``message``, where ``STAGES[stage].detailed``), "" for the others."""
        if not STAGES[stage].detailed:
            return ""
        return str((getattr(self, stage.value) or {}).get("message") or "")

    def failed_stages(self) -> list[Stage]:
        """The stages that ran on this solution and failed, in :class:`Stage` order."""
        return [stage for stage in Stage if self.passed(stage) is False]


SOLUTION_SHAPE = record_shape(SolutionRecord, null_is_default=True)
"""The shape of an entry of summary.json's ``per_solution`` (:data:`SUMMARY_SHAPE`), made
from :class:`SolutionRecord`: a null field is read as its default."""


def aggregate(records: list[SolutionRecord] | tuple[SolutionRecord, ...]) -> dict:
    """The run-wide figures over the solutions' records (means and maxima of what ran):
    ``summary.json``'s ``development``, ``deformation``, ``motion``, ``fabrication`` and
    ``structure``, the study's figures of a run and the report's checks
    (:meth:`rigidfold.rundir.RunData.checks`). A figure that a record read back holds as null
    is left out."""
    dev = [r.development or {} for r in records]
    deformed = [r.deformation for r in records if r.deformation is not None]
    motions = [r.motion for r in records if r.motion is not None]
    built = [r.fabrication for r in records if r.fabrication is not None]
    loaded = [r.structure for r in records if r.structure is not None]

    def stat(values, fn):
        return float(fn(values)) if values else None

    def known(figures: list[dict], key: str) -> list:
        return [f[key] for f in figures if f.get(key) is not None]

    def count(stage: Stage) -> int:  # the records on which ``stage`` passed
        return sum(r.passed(stage) is True for r in records)

    return {
        "development": {
            "mean_D": stat(known(dev, "D"), np.mean),
            "max_D": stat(known(dev, "D"), np.max),
            "flipped": sum(max(n, 0) for n in known(dev, "flipped")),
            "overlaps": sum(max(n, 0) for n in known(dev, "overlaps")),
        },
        "deformation": {
            "checked": len(deformed),
            "reached_plane": sum(bool(d.get("reached_plane")) for d in deformed),
            "mean_dl_mm": stat(known(deformed, "mean_dl_mm"), np.mean),
            "max_dl_mm": stat(known(deformed, "max_dl_mm"), np.max),
            "mean_drho_fix_deg": stat(known(deformed, "mean_drho_fix_deg"), np.mean),
            "max_drho_fix_deg": stat(known(deformed, "max_drho_fix_deg"), np.max),
        },
        "motion": {
            "traced": count(Stage.MOTION),
            "max_length_error": stat(known(motions, "max_length_error"), np.max),
        },
        "fabrication": {
            "checked": len(built),
            "collision_free": count(Stage.FABRICATION),
            "min_gap_m": stat(known(built, "min_gap_m"), np.min),
            "max_trimming_loss": stat(known(built, "trimming_loss"), np.max),
        },
        "structure": {
            "checked": len(loaded),
            "passed": count(Stage.STRUCTURE),
            "max_displacement_m": stat(known(loaded, "max_displacement_m"), np.max),
        },
    }


def _known_fields(record: type, data: dict) -> dict:
    """The fields of the dataclass ``record`` that ``data`` (JSON checked with its shape)
    holds, a null one of a field with a default read as that default (:func:`record_shape`
    with ``null_is_default``); keys of other versions are ignored."""
    out = {}
    for f in fields(record):
        if f.name not in data:
            continue
        value = data[f.name]
        if value is None and f.default is not dataclasses.MISSING:
            value = f.default
        elif value is None and f.default_factory is not dataclasses.MISSING:
            value = f.default_factory()
        out[f.name] = value
    return out


class MarginFigures(TypedDict, total=False):
    """What is read of summary.json's ``dof_margin``
    (:meth:`rigidfold.mechanism.margin.DofMargin.to_dict`)."""

    clear: bool | None
    message: str | None


class SurfaceMeta(TypedDict, total=False):
    """What is read of the case's ``surface`` (its target surface, rebuilt by the report)."""

    name: str | None
    plan_box_m: tuple[Finite, Finite] | None
    control_heights: list[list[Finite]] | None
    expression: str | None


class CaseMeta(TypedDict, total=False):
    """What is read of summary.json's ``case`` (:meth:`rigidfold.generate.case.Case.metadata`)."""

    surface: SurfaceMeta | None
    F_tol: float | None
    dz_m: float | None


class OptionsMeta(TypedDict, total=False):
    """What is read of summary.json's ``options``."""

    target_dof: int | None


class VerdictRecord(TypedDict):
    """summary.json's ``verdict`` (:meth:`rigidfold.pipeline.verdict.RunVerdict.to_dict`)."""

    outcome: str
    message: str


@dataclass(frozen=True, eq=False, kw_only=True)
class RunSummary:
    """``summary.json``: made by the run writer (:meth:`from_run`), written by
    :meth:`to_dict`, read back by :meth:`from_dict` (checked with :data:`SUMMARY_SHAPE`
    first). Its fields in the order of the file, each under its own name (the name of
    :meth:`rigidfold.generate.Generation.to_dict`'s key and of the study's column,
    :class:`rigidfold.study.RunRow`); the file's ``schema_version`` (:data:`SCHEMA_VERSION`)
    and the run-wide figures (:func:`aggregate` of ``per_solution``) are written, not held.
    The fields without a default (``stop``, ``stop_reason``, ``final_dof``, ``n_lock``,
    ``per_solution``, ``case``, ``solutions``) are the keys a summary must have.

    stop, stop_reason : how the run ended (:class:`rigidfold.generate.Stop` value and words);
    initial_dof, final_dof, lowest_dof, n_reduce, n_lock, n_exceed, n_path, n_backtrack,
    n_rigid : the paper's counters, N_path, the solutions retracted by backtracking and
    the second-order rigid ones (None in a file without them); deploy_check : whether the
    deployability check ran; final_step, final_deploys : the final design's step and
    whether its path reaches the flat state; dof_margin, n_solutions, n_solves (the solves
    computed), n_repeats (attempts that repeat an earlier one, ``Attempt.solve_from``), n_skipped,
    mean_f_accepted, mean_f_all_solves, numerics, time_s : the run's other figures
    (:meth:`rigidfold.generate.Generation.to_dict`; ``time_s`` with the checks' stages);
    per_solution : the solutions' records; options, case : the generate options and the
    case's metadata as written; solutions : the solution files, relative to the run's
    directory; verdict : the verdict's dict, None while the run goes on; exports : the
    final design's files, relative to the run's directory; target_surface : the file in
    the run's directory that holds a mesh target's fitted spline (``TARGET_FILE``), None
    for other targets.
    """

    stop: str
    stop_reason: str
    initial_dof: int | None = None
    final_dof: int | None
    lowest_dof: int | None = None
    n_reduce: int | None = None
    n_lock: int | None
    n_exceed: int | None = None
    n_path: int | None = None
    n_backtrack: int | None = None
    n_rigid: int | None = None
    deploy_check: bool = False
    final_step: int | None = None
    final_deploys: bool | None = None
    dof_margin: Annotated[dict | None, MarginFigures] = None
    n_solutions: int | None = None
    n_solves: int | None = None
    n_repeats: int | None = None
    n_skipped: int | None = None
    mean_f_accepted: float | None = None
    mean_f_all_solves: float | None = None
    numerics: dict | None = None
    time_s: dict = field(default_factory=dict)
    per_solution: Annotated[tuple[SolutionRecord, ...], [SOLUTION_SHAPE]]
    options: Annotated[dict, OptionsMeta] = field(default_factory=dict)
    case: Annotated[dict, CaseMeta]
    solutions: tuple[str, ...]
    verdict: Annotated[dict | None, VerdictRecord] = None
    exports: tuple[str, ...] = ()
    target_surface: str | None = None

    @classmethod
    def from_run(
        cls,
        run: Generation,
        records: list[SolutionRecord],
        *,
        stage_times: dict[str, float],
        **given: Any,
    ) -> RunSummary:
        """The summary of ``run`` as it stands: its counters and figures
        (:meth:`rigidfold.generate.Generation.to_dict`), ``stage_times`` (the checks' seconds)
        added to its ``time_s``, the solutions' ``records`` and the other fields ``given``."""
        produced = run.to_dict()
        produced["time_s"] = produced["time_s"] | stage_times
        names = [f.name for f in fields(cls)]
        return cls(
            **{n: produced[n] for n in names if n in produced},
            per_solution=tuple(records),
            **given,
        )

    def to_dict(self) -> dict:
        """``summary.json``'s content: ``schema_version``, the fields under their keys and,
        before ``per_solution`` (its records without the large-deformation history), the
        run-wide figures (:func:`aggregate`); tuples as lists."""
        out: dict = {"schema_version": SCHEMA_VERSION}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "per_solution":
                out |= aggregate(self.per_solution)
                value = [r.to_dict(history=False) for r in self.per_solution]
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: dict, file: str | os.PathLike) -> RunSummary:
        """The summary in ``data``, the JSON of ``file``: ValueError (one line, naming the
        file and the key) when what is read does not have the shape it must have, or (naming
        the versions) when it was written by another :data:`SCHEMA_VERSION`. A key it lacks
        (but the required ones of :data:`SUMMARY_SHAPE`) takes its field's default."""
        if "schema_version" in data:  # another version may have other keys
            check_version(data["schema_version"], file)
        missing = [k for k in SUMMARY_SHAPE.required if k not in data]
        if missing:
            raise RigidfoldError(
                f"{str(file)!r} is not the summary of rigidfold generate (no {', '.join(missing)})"
            )
        check_version(data.get("schema_version"), file)  # a summary made before versions
        check_shape(data, SUMMARY_SHAPE, file)
        known = _known_fields(cls, data)
        return cls(
            **known
            | {
                "per_solution": tuple(SolutionRecord.from_dict(r) for r in data["per_solution"]),
                "solutions": tuple(known["solutions"]),
                "exports": tuple(known.get("exports", ())),
            }
        )

    @property
    def target_dof(self) -> int | None:
        return self.options.get("target_dof")

    @property
    def running(self) -> bool:
        return self.stop == Stop.RUNNING


SUMMARY_SHAPE = record_shape(RunSummary, null_is_default=True)
"""What the readers rely on of ``summary.json`` and the shape it must have
(:func:`check_shape`), made from :class:`RunSummary` (:func:`record_shape`): each field under
its name, of the shape of its type (a solution's stage figures and the case's keys: of their
TypedDicts, :class:`DevelopmentFigures`, ..., :class:`CaseMeta`), the fields without a
default required, the others also null (read as their default)."""
