"""The final design as built: its thick panels and its structure, run by the run writer.

``rigidfold generate --thickness T`` (``GenerateOptions.fabricate``, a
:class:`~rigidfold.fabricate.FabricateOptions`) makes the final design's thick panels
(:func:`rigidfold.fabricate.fabricate_panels`) from the motion the run traced, checks them
over it and writes their files into ``DIR/final/thick/`` (:func:`thick_panels`);
``--structure`` (``GenerateOptions.structure``, a
:class:`~rigidfold.structure.StructureOptions`) checks the final design on its supports
under load (:func:`rigidfold.structure.check_design`) and writes ``DIR/final/structure/``
(:func:`structure_check`). Each returns the figures that the final design's
:class:`~rigidfold.rundir.SolutionRecord` keeps (``fabrication``, ``structure``), with the
files named relative to the run's directory, and the result itself.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from rigidfold.drive import DriveResult
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate import Fabrication, FabricationStatus, Panels
from rigidfold.fabricate.build import check_thickness
from rigidfold.fabricate.motion import design_motion
from rigidfold.generate import GenerateOptions
from rigidfold.io import prepare_output_dir
from rigidfold.mechanism.path import FoldingPath
from rigidfold.mesh import CreasePattern
from rigidfold.rundir.layout import FINAL_DIR
from rigidfold.structure import StructureCheck, check_design, write_structure

THICK_DIR = Path(FINAL_DIR) / "thick"
"""Where the thick panels' files go in the run's directory."""

STRUCTURE_DIR = Path(FINAL_DIR) / "structure"
"""Where the structure check's files go in the run's directory."""


def thick_dir_of(design: str | Path) -> Path | None:
    """The thick panels' directory (:data:`THICK_DIR`) of the run whose solution file is
    ``design`` (``DIR/solutions/NAME.fold``: ``DIR/final/thick``); None for another file."""
    design = Path(design)
    return design.parent.parent / THICK_DIR if design.parent.name == "solutions" else None


def check_built_options(pattern: CreasePattern, options: GenerateOptions) -> None:
    """ValueError (one line) for supports, support candidates, clamped vertices, actuators
    or point loads that ``pattern`` (the run's crease pattern: every solution has its
    vertices and edges) lacks, and for an actuator that is not one of its free creases (a
    run only fixes more), and for thick panels too thin for the design's size
    (:func:`rigidfold.fabricate.build.check_thickness`), before the run starts."""
    if options.fabricate is not None:
        check_thickness(options.fabricate.thickness, pattern.coords, settings=pattern.settings)
    st = options.structure
    if st is None:
        return
    st.check_indices(pattern.n_vertices, pattern.n_edges)
    free = set(pattern.free_creases.tolist())
    fixed = [e for e in sorted(set(st.actuators)) if e not in free]
    if fixed:
        raise RigidfoldError(f"actuator {fixed[0]} is not a free crease of the crease pattern")


def thick_panels(
    run_dir: Path,
    name: str,
    pattern: CreasePattern,
    coords2d: np.ndarray,
    options: GenerateOptions,
    *,
    frames: tuple[np.ndarray, np.ndarray] | None = None,
    path: FoldingPath | None = None,
) -> tuple[dict, Fabrication]:
    """Thick panels of the design ``pattern`` (development ``coords2d`` (V, 2)) as
    ``options.fabricate`` asks (the density, unless it gives one, that of
    ``options.panel_material``), checked over the run's traced motion (``frames``: (frames
    (K, V, 3), fraction (K,))) or its folding ``path`` (traced again only when neither
    serves); their files (:func:`rigidfold.fabricate.files.write_fabrication`) in
    ``run_dir/final/thick/`` named after ``name``, the cut sheets nested onto its sheet.
    Returns (the record's figures, the result)."""
    from rigidfold.fabricate.files import write_fabrication

    fabricate = options.fabricate
    assert fabricate is not None
    settings = pattern.settings
    t0 = time.perf_counter()
    panels = Panels(pattern, coords2d, fabricate.side)
    motion, message = design_motion(panels, frames=frames, path=path, settings=settings)
    fab = fabricate.fabricate(
        panels,
        motion,
        density=options.panel_material.density,
        motion_message=message,
        settings=settings,
    )
    out = prepare_output_dir(run_dir / THICK_DIR, within=run_dir)
    written, sheets = write_fabrication(
        fab,
        out,
        name,
        source=f"solutions/{name}.fold",
        title=fabricate.title(name),
        label=name,
        sheet=fabricate.sheet,
        gap=settings.fabricate.sheet_gap,
        settings=settings,
    )
    return _fabrication_figures(fab, run_dir, written, sheets, time.perf_counter() - t0), fab


def _fabrication_figures(
    fab: Fabrication, run_dir: Path, written: list[Path], sheets: dict, seconds: float
) -> dict:
    """What the record keeps of thick panels (see :data:`rigidfold.rundir.schema.SUMMARY_SHAPE`):
    the verdict, the slab and what was trimmed, the closest pair of panels (the worst
    meeting where they collide, else the smallest gap) and the files."""
    full = fab.to_dict()
    c = fab.clearance
    closest = None
    if c is not None and c.meetings and fab.status is FabricationStatus.COLLISION:
        m = c.meetings[0]
        closest = {
            "panels": [int(m.panels[0]), int(m.panels[1])],
            "fraction": float(m.fraction),
            "kind": m.kind,
            "gap_m": float(m.amount) if m.kind != "hinge" else None,
            "detail": m.describe(),
        }
    elif c is not None and np.isfinite(c.min_gap):
        a, b = (int(k) for k in c.gap_panels)
        closest = {
            "panels": [a, b],
            "fraction": float(c.gap_fraction),
            "kind": "gap",
            "gap_m": float(c.min_gap),
            "detail": (
                f"panels {a} and {b} come within {c.min_gap * 1e3:.1f} mm at "
                f"{100 * c.gap_fraction:.0f}% folded"
            ),
        }
    files = [str(p.relative_to(run_dir)) for p in written]
    solids = next((f for f in files if f.endswith("_solids.obj")), None)
    keep = (
        "status thickness_m side min_thickness_m clearance_angle_deg density_kg_m3 panels "
        "hinges area_m2 volume_m3 volume_share trimming_loss mass_kg relief_vertices "
        "largest_fold_deg smallest_bevel_deg thinnest_panel thinnest_depth_m "
        "passing_thickness_m motion"
    ).split()
    return {
        **{k: full[k] for k in keep},
        "message": fab.last_line(),
        "min_gap_m": None if c is None or not np.isfinite(c.min_gap) else c.min_gap,
        "required_gap_m": None if c is None else c.clearance,
        "hinge_margin_deg": None if c is None else full["check"]["hinge_margin_deg"],
        "frames_checked": None if c is None else c.frames,
        "pairs_meeting": 0 if c is None else len(c.meetings),
        "closest": closest,
        "cut_sheets": sheets.get("sheets"),
        "solids": solids,
        "files": files,
        "time_s": seconds,
    }


def structure_check(
    run_dir: Path, name: str, pattern: CreasePattern, options: GenerateOptions
) -> tuple[dict, StructureCheck]:
    """The structure check of the design ``pattern`` as ``options.structure`` asks
    (:func:`rigidfold.structure.check_design`) and its files (``structure.json``,
    ``structure.png``) in ``run_dir/final/structure/``. Returns (the record's figures, the
    check)."""
    assert options.structure is not None
    t0 = time.perf_counter()
    check = check_design(pattern, options.structure, settings=pattern.settings)
    out = prepare_output_dir(run_dir / STRUCTURE_DIR, within=run_dir)
    written = write_structure(check, out, f"solutions/{name}.fold")
    files = [str(p.relative_to(run_dir)) for p in written]
    full = check.to_dict()
    full.pop("hinges", None)  # per crease: in structure.json
    return {
        **full,
        "figure": next((f for f in files if f.endswith(".png")), None),
        "files": files,
        "time_s": time.perf_counter() - t0,
    }, check


DRIVE_DIR = Path(FINAL_DIR) / "deploy"
"""Where ``generate --deploy`` writes the final design's drive (``rigidfold deploy``'s
files)."""


def deployment_drive(
    run_dir: Path,
    name: str,
    options: GenerateOptions,
    *,
    frames: tuple[np.ndarray, np.ndarray] | None = None,
    path: FoldingPath | None = None,
) -> tuple[dict, DriveResult]:
    """The drive of the final design's deployment (``options.drive``, its panels of the
    run's ``--thickness`` and ``--material`` unless it gives its own), along the motion the
    run traced (``frames``: (frames (K, V, 3), fraction (K,))) or its folding ``path``:
    :func:`rigidfold.drive.deploy_design` on ``solutions/NAME.fold``, its files in
    ``run_dir/final/deploy/``. Returns (the record's figures, the result)."""
    from rigidfold.drive import deploy_design

    drive = options.drive
    assert drive is not None
    if drive.thickness is None and options.panel_thickness is not None:
        drive = drive.replace(
            thickness=options.panel_thickness, thickness_from="the run's --thickness"
        )
    if options.material is not None:
        drive = drive.replace(material=options.material)
    t0 = time.perf_counter()
    design = run_dir / "solutions" / f"{name}.fold"
    result = deploy_design(
        design, drive, run_dir / DRIVE_DIR, frames=frames, path=path, recorded_in=()
    )
    data = result.to_dict()
    figures = {
        "status": result.status.value,
        "message": result.summary_line(),
        "drive": data["drive"],
        "base_panel": data["base_panel"],
        "files": [str(Path(p).relative_to(run_dir)) for p in result.written],
        "seconds": time.perf_counter() - t0,
    }
    return figures, result
