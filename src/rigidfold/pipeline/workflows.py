"""The workflows behind the command line: read, compute, write, and return a result.

Each function takes validated library objects (or a file path, validated on reading), runs
the library, writes its files through the shared writers of :mod:`rigidfold.rundir` and
:mod:`rigidfold.io`, and returns a frozen result whose ``to_dict()`` is what ``--json``
prints. ``rigidfold.cli`` only parses arguments, calls these functions and prints.

=====================  ====================================================================
``analyze_file``       mechanism analysis of a FOLD shape (``rigidfold analyze``)
``develop_file``       Step 8 of a FOLD shape: FOLD with its diagram, and an SVG
``deform_file``        Steps 8-9 and the folding motion of a FOLD shape
``optimize_case``      one solve of problem (6): ``solution.fold`` and ``summary.json``
``export_file``        3D, CAD and cut-sheet files of a FOLD design (``rigidfold export``)
``report_run``         ``DIR/report.html`` and ``DIR/figures/`` of a generate run
                       (:mod:`rigidfold.pipeline.report`)
``structure``          supports and loads of a FOLD design (``rigidfold structure``)
``fabricate_file``     thick panels of a FOLD design, checked over its deployment, and their
                       solids, schedules and nested cut sheets (``rigidfold fabricate``)
=====================  ====================================================================
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.deform.check import Verification, verify
from rigidfold.develop import DevelopStatus
from rigidfold.drive import DriveOptions, DriveResult
from rigidfold.errors import RigidfoldError
from rigidfold.exports import (
    CONVENTIONS,
    EXPORT_FORMATS,
    Design,
    check_convention,
    check_formats,
    export_design,
    export_paths,
    read_design,
)
from rigidfold.fabricate import FabricateOptions, Fabrication, Panels, design_motion
from rigidfold.generate.case import Case, fixed_mask, shape_summary
from rigidfold.io import (
    FoldData,
    prepare_output_dir,
    read_fold,
    refuse_replacing_inputs,
    write_fold,
    write_json,
)
from rigidfold.material import Panel
from rigidfold.mechanism import Mechanism, analyze
from rigidfold.optimize import OptimizeResult, SolverName
from rigidfold.pipeline.report import RunReport as RunReport  # the command's, kept here
from rigidfold.pipeline.report import report_run as report_run
from rigidfold.pipeline.writer import write_checked_shape
from rigidfold.rundir import clear_earlier_run, earlier_run
from rigidfold.structure import StructureCheck, StructureStatus
from rigidfold.structure.design import (
    STRUCTURE_FILES,
    StructureOptions,
    plan_design,
    write_structure,
)

# ------------------------------------------------------------------------------ analyze
FLAT_NOTE = (
    "a flat state is singular: its first-order DOF overstates the rigid-folding DOF; for the "
    "folded-state answer, fold it slightly first (analyze a folded form of it), or run "
    "rigidfold generate or optimize on a target surface"
)
"""What ``analyze`` says of a flat sheet."""

UNITLESS_NOTE = (
    'the file gives no physical unit (frame_unit "unit" or none): its coordinates were read '
    "as metres"
)
"""What ``analyze`` says of a file without a physical unit."""


@dataclass(frozen=True, eq=False)
class ShapeAnalysis:
    """Mechanism analysis of a shape read from a FOLD file.

    file : str; data : FoldData (the file's pattern and edge numbering); mechanism : Mechanism.
    """

    file: str
    data: FoldData
    mechanism: Mechanism

    @property
    def flat(self) -> bool:
        """True for a flat sheet: every fold angle within ``settings.geometry.flat_angle`` of 0 (the
        pattern's settings). Its DOF is first-order only (:data:`FLAT_NOTE`)."""
        pattern = self.data.pattern
        return bool(np.all(np.abs(pattern.fold_angles) <= pattern.settings.geometry.flat_angle))

    @property
    def notes(self) -> list[str]:
        """What to know about the answer: :data:`UNITLESS_NOTE`, :data:`FLAT_NOTE`, when
        they apply."""
        notes = []
        if self.data.unitless:
            notes.append(UNITLESS_NOTE)
        if self.flat:
            notes.append(FLAT_NOTE)
        return notes

    @property
    def locked_edges(self) -> list[int]:
        """Locked creases that are edges of the file (indices into its ``edges_vertices``)."""
        return [e for e in self.mechanism.locked_creases.tolist() if e < self.data.n_file_edges]

    def fold_angles_deg(self, edges: np.ndarray) -> np.ndarray:
        """(k,) fold angles in degrees (valley > 0) of the given pattern edges."""
        return np.degrees(self.data.pattern.fold_angles[edges])

    def to_dict(self) -> dict:
        pattern, mech = self.data.pattern, self.mechanism
        n_file = self.data.n_file_edges
        return {
            "file": self.file,
            "vertices": pattern.n_vertices,
            "faces": pattern.n_faces,
            "free_creases": len(mech.hinges),
            "fixed_creases": len(pattern.fixed_creases),
            "dof": mech.dof,
            "locked_edges": self.locked_edges,
            "locked_vertex_pairs": [pattern.edges[e].tolist() for e in mech.locked_creases],
            "fold_angles_deg": np.round(self.fold_angles_deg(np.arange(n_file)), 6).tolist(),
            "unit": self.data.unit,
            "flat": self.flat,
            "notes": self.notes,
        }


def analyze_file(
    path: str | os.PathLike, *, up: str = "z", settings: Settings = DEFAULTS
) -> ShapeAnalysis:
    """DOF, locked creases and fold angles of the shape in a FOLD file (read with ``up``,
    see :func:`rigidfold.io.read_fold`). The DOF is first-order: for a flat sheet it
    overstates the rigid-folding DOF, which :attr:`ShapeAnalysis.flat` and ``notes`` say."""
    data = read_fold(path, up=up, settings=settings)
    return ShapeAnalysis(str(path), data, analyze(data.pattern, settings=settings))


# ------------------------------------------------------------------- develop and deform
@dataclass(frozen=True, eq=False)
class ShapeCheck:
    """Steps 8(-9) of a shape read from a FOLD file, and the files written.

    verification : Verification; written : the files, in the order written.
    """

    file: str
    verification: Verification
    written: tuple[Path, ...]
    section: dict | None = None

    def to_dict(self) -> dict:
        """The checked stage's figures at the top level (the deformation's when Step 9 ran,
        else the development's, without the load-step history), the others under their
        names; Step 9's frame section under ``frame_section`` when it ran."""
        figures = self.verification.to_dict()
        stage = "development" if figures["deformation"] is None else "deformation"
        top = {k: v for k, v in figures.pop(stage).items() if k != "history"}
        extra = {} if self.section is None else {"frame_section": self.section}
        return {**top, **{k: v for k, v in figures.items() if v is not None}, **extra}


def develop_file(
    path: str | os.PathLike,
    out: str | os.PathLike,
    *,
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> ShapeCheck:
    """Step 8 of a FOLD shape (read with ``up``): ``OUT/<name>.fold`` (the input, kept
    whole, plus rigidfold's development diagram as a ``creasePattern`` frame, its folded form
    and its figures; see :func:`rigidfold.io.round_trip_dict`) and ``OUT/<name>.svg``."""
    return _check_file(path, out, deform=False, up=up, settings=settings)


def deform_file(
    path: str | os.PathLike,
    out: str | os.PathLike,
    *,
    up: str = "z",
    panel: Panel | None = None,
    settings: Settings = DEFAULTS,
) -> ShapeCheck:
    """Steps 8-9 and the folding motion of a FOLD shape (read with ``up``):
    ``OUT/<name>.fold`` (the input, kept whole, plus rigidfold's development diagram, motion
    frames, folded form and figures), ``OUT/<name>.svg`` and ``OUT/<name>_deform.json``
    (every figure and the load-step history).

    panel : Step 9's frame as strips of these panels
    (:func:`rigidfold.deform.analysis.panel_section`); None: the paper's tubes."""
    if panel is not None and not isinstance(panel, Panel):
        raise RigidfoldError(f"panel must be a Panel or None, got {panel!r}")
    return _check_file(path, out, deform=True, up=up, settings=settings, panel=panel)


def _check_file(
    path,
    out,
    *,
    deform: bool,
    up: str,
    settings: Settings,
    panel: Panel | None = None,
) -> ShapeCheck:
    """Read, check and write back a FOLD shape. The output FOLD is the input document with
    rigidfold's frames (in metres, ``frame_unit: "m"``, z up) and ``rigidfold:`` keys added:
    nothing of the input is dropped or rewritten, so its unit, orientation, polygons and
    assignments stay as they were (:func:`rigidfold.io.round_trip_dict`)."""
    stem = Path(path).stem
    # the name in the files' text: bytes of a file name that are not UTF-8 shown as U+FFFD
    label = stem.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    names = [f"{stem}.fold", f"{stem}.svg"] + ([f"{stem}_deform.json"] if deform else [])
    # before any work: a file written must never replace the input
    refuse_replacing_inputs([path], [Path(out) / name for name in names])
    out_dir = prepare_output_dir(out)
    data = read_fold(path, up=up, settings=settings)
    check = verify(
        data.pattern,
        run_deform=deform,
        run_motion=deform,
        panel=panel,
        settings=settings,
    )
    written = write_checked_shape(
        out_dir / f"{stem}.fold",
        data.pattern,
        check,
        title=f"{label}: the folded form checked, triangulated (metres, z up)",
        metadata={},
        svg_title=f"{label}: development",
        source=data,
    )
    section = None
    if deform:
        section = {
            "kind": "tube",
            "diameter_m": settings.deformation.tube_diameter,
            "wall_m": settings.deformation.tube_wall,
            "E_Pa": settings.deformation.youngs_modulus,
            "nu": settings.deformation.poisson_ratio,
        }
        if panel is not None:
            section = {
                "kind": "panel",
                "material": panel.material.to_dict(),
                "thickness_m": panel.thickness,
            }
        written.append(
            write_json(
                out_dir / f"{stem}_deform.json", {**check.to_dict(), "frame_section": section}
            )
        )
    return ShapeCheck(str(path), check, tuple(written), section)


# ------------------------------------------------------------------------------ optimize
OPTIMIZE_FILES = ("solution.fold", "summary.json")
"""The files ``optimize_case`` writes into its directory."""


@dataclass(frozen=True, eq=False)
class OptimizeOutput:
    """One solve of problem (6): the result, ``summary.json``'s content, the files written."""

    result: OptimizeResult
    build_time: float
    report: dict
    written: tuple[Path, ...]

    def to_dict(self) -> dict:
        return self.report


def optimize_case(
    case: Case,
    out: str | os.PathLike,
    *,
    fixed: Sequence[int] = (),
    solver: SolverName = SolverName.IPOPT,
    overwrite: bool = False,
) -> OptimizeOutput:
    """Solve (6) once with the creases ``fixed`` (indices into the pattern's edges) fixed; write
    ``OUT/solution.fold`` and ``OUT/summary.json`` whatever the outcome.

    Before any work, ValueError when one of the files would replace one of ``case.inputs``,
    and when OUT holds them from an earlier run, unless ``overwrite`` (then they are removed
    first, like ``generate --overwrite``: :func:`rigidfold.rundir.clear_earlier_run`)."""
    refuse_replacing_inputs(case.inputs, [Path(out) / name for name in OPTIMIZE_FILES])
    out_dir = prepare_output_dir(out)
    clear_earlier_run(out_dir, overwrite=overwrite, inputs=case.inputs, names=OPTIMIZE_FILES)
    mask = fixed_mask(fixed, case.pattern)
    problem = case.problem(build_ipopt=solver == SolverName.IPOPT)
    result = problem.solve(fixed=mask, solver=solver)
    report = shape_summary(case, result, problem.build_time)
    fold = write_fold(
        out_dir / "solution.fold",
        result.pattern,
        title=f"rigidfold optimize: {case.surface.name} on pattern {case.plan.spec.text}",
        metadata={**case.metadata(), **result.to_dict()},
    )
    summary = write_json(out_dir / "summary.json", report)
    return OptimizeOutput(result, problem.build_time, report, (fold, summary))


# ------------------------------------------------------------------------------ export
@dataclass(frozen=True, eq=False)
class DesignExport:
    """The exports of a design read from a FOLD file.

    file : str; design : Design (the folded form and its development diagram, and where the
    diagram came from); formats : the formats written; convention : the SVG's; written : the
    files, in :data:`rigidfold.exports.EXPORT_FORMATS` order.
    """

    file: str
    design: Design
    formats: tuple[str, ...]
    convention: str
    written: tuple[Path, ...]

    @property
    def diagram_ok(self) -> bool:
        """False when the diagram was computed and Step 8 did not converge (the cut sheet
        then has flipped or overlapping facets)."""
        dev = self.design.development
        return dev is None or dev.status is DevelopStatus.CONVERGED

    def to_dict(self) -> dict:
        dev = self.design.development
        pattern = self.design.pattern
        return {
            "file": self.file,
            "formats": list(self.formats),
            "convention": self.convention,
            "diagram": self.design.diagram,
            "development": None if dev is None else dev.to_dict(),
            "vertices": pattern.n_vertices,
            "faces": pattern.n_faces,
            "panels": pattern.n_facets,
            "written": [str(p) for p in self.written],
        }


def export_file(
    path: str | os.PathLike,
    out: str | os.PathLike,
    *,
    formats: Sequence[str] = EXPORT_FORMATS,
    convention: str = CONVENTIONS[0],
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> DesignExport:
    """Export the design in a FOLD file (read with ``up``; its development diagram from its
    ``creasePattern`` frame, or computed: :func:`rigidfold.exports.read_design`) to
    ``OUT/<name>.*`` in ``formats`` (:func:`rigidfold.exports.check_formats`), the SVG cut
    sheet in ``convention`` (:func:`rigidfold.exports.export_design`)."""
    chosen = check_formats(formats)
    check_convention(convention)
    stem = Path(path).stem
    refuse_replacing_inputs([path], export_paths(out, chosen, name=stem))
    out_dir = prepare_output_dir(out)
    design = read_design(path, up=up, settings=settings)
    written = export_design(
        design.pattern,
        design.coords2d,
        out_dir,
        chosen,
        name=stem,
        title=f"{stem}: rigidfold design",
        convention=convention,
    )
    return DesignExport(str(path), design, chosen, convention, tuple(written))


# ----------------------------------------------------------------------------- structure
@dataclass(frozen=True, eq=False)
class StructureRun:
    """The structure check of a FOLD design and the files written.

    file : str; check : :class:`rigidfold.structure.StructureCheck`; written : the files.
    """

    file: str
    check: StructureCheck
    written: tuple[Path, ...]

    @property
    def status(self) -> StructureStatus:
        return self.check.status

    def to_dict(self) -> dict:
        return {
            "file": self.file,
            **self.check.to_dict(),
            "written": [str(p) for p in self.written],
        }


def structure(
    path: str | os.PathLike,
    out: str | os.PathLike,
    options: StructureOptions = StructureOptions(),  # noqa: B008 (frozen)
    *,
    up: str = "z",
    overwrite: bool = False,
    settings: Settings = DEFAULTS,
    progress: Callable[[str], None] | None = None,
) -> StructureRun:
    """Supports, loads and serviceability of the design in a FOLD file (read with ``up``)
    as ``options`` ask (:class:`rigidfold.structure.StructureOptions`, checked when made):
    ``OUT/structure.json`` and ``OUT/structure.png`` (:mod:`rigidfold.structure`). The
    indices and point loads are checked against the design before anything is written
    (ValueError, one line). ``progress`` is handed a line as each long step starts. An
    earlier run's files are refused unless ``overwrite``: then the new ones are written
    together, and only then is an earlier file not written again removed; a failed write
    leaves the earlier files as they were.
    """
    refuse_replacing_inputs([path], [Path(out) / name for name in STRUCTURE_FILES])
    data = read_fold(path, up=up, settings=settings)
    plan = plan_design(data.pattern, options, settings=settings, progress=progress)
    out_dir = prepare_output_dir(out)
    earlier = earlier_run(out_dir, overwrite=overwrite, inputs=(Path(path),), names=STRUCTURE_FILES)
    check = plan.check()
    written = write_structure(check, out_dir, str(path))
    earlier.remove(keep=written)  # the new files are in place: an earlier figure goes
    return StructureRun(str(path), check, tuple(written))


# ------------------------------------------------------------------------------ fabricate
@dataclass(frozen=True, eq=False)
class FabricateOutput:
    """Thick panels of a FOLD design and the files written.

    fabrication : rigidfold.fabricate.Fabrication (status, solids, check); design : Design;
    sheets : the cut sheets' summary; written : the files, in the order written.
    """

    file: str
    design: Design
    fabrication: Fabrication
    sheets: dict
    written: tuple[Path, ...]

    @property
    def ok(self) -> bool:
        return self.fabrication.ok

    def to_dict(self) -> dict:
        return {
            "file": self.file,
            **self.fabrication.to_dict(),
            "cut_sheets": self.sheets,
            "written": [str(p) for p in self.written],
        }


def fabricate_file(
    path: str | os.PathLike,
    out: str | os.PathLike,
    options: FabricateOptions,
    *,
    up: str = "z",
    overwrite: bool = False,
    settings: Settings = DEFAULTS,
) -> FabricateOutput:
    """Thick panels of the FOLD design ``path`` (``rigidfold fabricate``) as ``options``
    ask (:class:`rigidfold.fabricate.FabricateOptions`, checked when made): solids of
    ``options.thickness`` metres on ``options.side``, bevelled and relieved so that they
    deploy from flat to the design without collision, checked over its folding motion
    (:func:`rigidfold.fabricate.fabricate_panels`), and their files in OUT: the solids
    (GLB, STL, OBJ, 3DM), the hinge and vertex schedules, the cut sheets nested onto
    ``options.sheet`` (mm) stock, and ``NAME_fabricate.json``. The files are written
    whatever the verdict. Refused (ValueError, before anything is written) when one of them
    would replace ``path``, and when OUT holds an earlier fabricate's files of the same NAME
    (every cut sheet included), unless ``overwrite``: then the new files are written
    beside them and renamed into place together, and only then are the earlier run's
    files that were not written again removed, exactly those its ``NAME_fabricate.json``
    recorded (:func:`rigidfold.rundir.earlier_run`); a failed write (a full disk, the file
    size limit, named) leaves the earlier files as they were."""
    from rigidfold.fabricate.cutsheets import sheet_files
    from rigidfold.fabricate.files import (
        FABRICATE_JSON,
        SOLID_FILES,
        recorded_files,
        write_fabrication,
    )

    stem = Path(path).stem
    label = stem.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    names = [t.format(stem) for t in (*SOLID_FILES, FABRICATE_JSON)]
    sheets = sheet_files(out, stem)  # an earlier run's, recorded or not: refused
    refuse_replacing_inputs([path], [Path(out) / n for n in (*names, *sheets)])
    out_dir = prepare_output_dir(out)
    earlier = earlier_run(
        out_dir,
        overwrite=overwrite,
        inputs=(Path(path),),
        names=tuple(dict.fromkeys([*names, *recorded_files(out_dir, stem)])),
        others=tuple(sheets),
    )
    design = read_design(path, up=up, settings=settings)
    panels = Panels(design.pattern, design.coords2d, options.side)
    motion, message = design_motion(panels, design, up=up, settings=settings)
    fab = options.fabricate(panels, motion, motion_message=message, settings=settings)
    written, summary = write_fabrication(
        fab,
        out_dir,
        stem,
        source=str(path),
        title=options.title(label),
        label=label,
        sheet=options.sheet,
        gap=settings.fabricate.sheet_gap,
        settings=settings,
    )
    earlier.remove(keep=written)  # the new files are in place: the earlier run's others go
    return FabricateOutput(str(path), design, fab, summary, tuple(written))


# ------------------------------------------------------------------------------ deploy
def deploy_file(
    path: str | os.PathLike,
    out: str | os.PathLike,
    options: DriveOptions,
    *,
    up: str = "z",
    overwrite: bool = False,
    settings: Settings = DEFAULTS,
) -> DriveResult:
    """The drive of the deployment of the DOF-1 FOLD design ``path`` (``rigidfold deploy``)
    as ``options`` ask (:func:`rigidfold.drive.deploy_design`), its files
    (:data:`rigidfold.drive.DEPLOY_FILES`) written together into OUT. The files of an earlier
    drive in OUT are refused unless ``overwrite``; they are replaced only once the new ones
    are written (nothing is removed before), and replacing ``path`` is refused always."""
    from rigidfold.drive import DEPLOY_FILES, deploy_design

    refuse_replacing_inputs([path], [Path(out) / n for n in DEPLOY_FILES])
    out_dir = prepare_output_dir(out)
    if not overwrite:
        clear_earlier_run(out_dir, overwrite=False, inputs=(Path(path),), names=DEPLOY_FILES)
    return deploy_design(path, options, out_dir, up=up, settings=settings)
