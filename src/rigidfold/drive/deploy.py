"""The drive of a design's deployment, in one call: :func:`deploy_design`.

Read the design (a FOLD file through :func:`rigidfold.exports.read_design`, or a
:class:`~rigidfold.exports.Design` at hand), check the options against it and its DOF
(every input checked before anything is computed or written), take its motion from flat
(:mod:`rigidfold.drive.motion`), its masses (:mod:`~rigidfold.drive.mass`) and energy
(:mod:`~rigidfold.drive.energy`) with every panel as the base, rank the bases
(:mod:`~rigidfold.drive.base`) and the drives of the chosen one
(:mod:`~rigidfold.drive.actuators`), the released structure
(:mod:`~rigidfold.drive.equilibria`), the ground, the independent check
(:mod:`~rigidfold.drive.check`), and write the files (:mod:`~rigidfold.drive.files`).

The named drive: the best crease of the ranking that drives the whole motion (no dead
point) within ``--max-torque``; else the best pair of creases (searched where the best
single crease has a dead point) within it; else the best cable that drives the whole motion
within ``--max-tension``; else the first of those that drives the whole motion, over the
limit; else the best crease away from its dead points (no drive).
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.drive import actuators as act
from rigidfold.drive.base import below_ground, lowest_points, rank_bases
from rigidfold.drive.check import HeldModel, check_curve, not_run, pick_states
from rigidfold.drive.energy import energy as energy_of
from rigidfold.drive.equilibria import equilibria, released
from rigidfold.drive.mass import design_masses, file_faces, polygon_sizes
from rigidfold.drive.motion import check_dof, drive_motion
from rigidfold.drive.options import AUTO, DriveOptions
from rigidfold.drive.result import DriveResult, verdict
from rigidfold.errors import RigidfoldError
from rigidfold.exports import Design
from rigidfold.fabricate.panels import Panels


def _read(
    design: Design | str | os.PathLike,
    options: DriveOptions,
    settings: Settings,
    also: Sequence[Path] = (),
    up: str = "z",
) -> tuple[Design, str, float, str]:
    """(the design, its source in words, the panels' thickness, where it came from)."""
    from rigidfold.exports import read_design
    from rigidfold.fabricate.files import recorded_thickness

    if isinstance(design, Design):
        source = "the design given"
        path = None
    else:
        path = Path(design)
        source = str(path)
        design = read_design(path, up=up, settings=settings)
    if options.thickness is not None:
        return design, source, options.thickness, options.thickness_from
    recorded = recorded_thickness(path, also) if path is not None else None
    if recorded is not None:
        t, where = recorded
        return design, source, t, f"recorded by fabricate in {where.name}"
    t = settings.structure.thickness
    return design, source, t, f"the default ({t * 1e3:g} mm: no thickness given or recorded)"


@one_blas_thread()  # the same rounding on every machine, and no BLAS threads contending
def deploy_design(
    design: Design | str | os.PathLike,
    options: DriveOptions | None = None,
    out_dir: str | os.PathLike | None = None,
    *,
    frames: tuple[np.ndarray, np.ndarray] | None = None,
    path=None,
    recorded_in: Sequence[str | os.PathLike] = (),
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> DriveResult:
    """The drive of ``design``'s deployment (see the module's text), its files written into
    ``out_dir`` when given (``deploy.json``, ``deploy.fold``, ``deploy.csv``,
    ``deploy.png``, all together: :func:`rigidfold.drive.files.write_drive`).

    design : a FOLD file or a :class:`~rigidfold.exports.Design`; options : the drive's
    (default :class:`DriveOptions`); frames : ((K, V, 3), fraction (K,)) the design's motion
    from flat at hand (a run's), instead of its file's; path : its folding path already
    traced; recorded_in : directories where ``rigidfold fabricate`` may have recorded the
    panels' thickness besides the design's own (a run's thick panels,
    :func:`rigidfold.pipeline.built.thick_dir_of`), read when ``options.thickness`` is None;
    up : the up axis the FOLD file is read with (:func:`rigidfold.io.read_fold`; motion
    frames are rigidfold's, z up: a file read otherwise has its motion traced).
    Raises RigidfoldError (one line, nothing written) for bad input: an index the design
    lacks, a design that is not DOF 1, a motion that does not reach flat.
    """
    options = DriveOptions() if options is None else options
    if not isinstance(options, DriveOptions):
        raise RigidfoldError(f"options must be DriveOptions, got {type(options).__name__}")
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    if out_dir is not None and not isinstance(design, Design):
        from rigidfold.drive.files import DEPLOY_FILES
        from rigidfold.io import refuse_replacing_inputs

        refuse_replacing_inputs([design], [Path(out_dir) / name for name in DEPLOY_FILES])
    also = [Path(p) for p in recorded_in]
    design, source, thickness, thickness_from = _read(design, options, settings, also, up)
    pattern = design.pattern
    panels = Panels(pattern, design.coords2d, "top")
    options.check_indices(pattern.n_vertices, panels.n)
    if not panels.n_hinges:
        raise RigidfoldError("the design has no hinge (no free crease between two panels)")
    check_dof(pattern, settings=settings)
    times["read"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    carrier = design if up == "z" else None  # frames of another up axis are not its motion
    motion = drive_motion(panels, carrier, frames=frames, path=path, settings=settings)
    times["motion"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    density = options.panel_density
    raw = design.data.raw if hasattr(design, "data") else None
    masses = design_masses(
        panels,
        thickness=thickness,
        density=density,
        hardware=options.hardware,
        point_masses=options.point_masses,
        owner=motion.owner,
        face_of=file_faces(pattern.n_faces, polygon_sizes(raw)),
    )
    g = settings.drive.gravity
    en = energy_of(
        motion,
        masses,
        gravity=g,
        stiffness=options.hinge_stiffness,
        friction=options.friction,
        rest=options.spring_rest,
        ground=options.ground,
    )
    s = en.s
    edges = panels.hinge_edges
    ok, still = act.control(en.rate, settings=settings)
    low = lowest_points(motion, en.ground)
    bases = rank_bases(en.powers(), en.rate, ok, still, edges, low, settings=settings)
    base_auto = options.base == AUTO
    base = bases[0].panel if base_auto else int(options.base)
    power = en.power(base)
    times["bases"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    ranking = act.crease_drives(en.rate, en.fold, power, s, edges, settings=settings)
    pair = None
    if ranking and not ranking[0].controls:
        pair = act.best_pair(ranking, en.rate, en.fold, edges, power, s, settings=settings)
    cables: list[act.Actuator] = []
    if options.cables:
        given = np.asarray(options.cables, dtype=np.int64)
        lengths = act.cable_lengths(motion.coords, given)
        cables += act.cable_drives(lengths, given, power, s, settings=settings)
    if options.cables_auto and settings.drive.auto_cables > 0:
        pairs = act.auto_cable_pairs(pattern, panels.vertices, settings)
        if options.cables:
            known = {tuple(sorted(c)) for c in options.cables}
            pairs = np.asarray(
                [p for p in pairs.tolist() if tuple(sorted(p)) not in known], dtype=np.int64
            ).reshape(-1, 2)
        cables += act.best_cables(
            motion.coords, pairs, power, s, settings.drive.auto_cables, settings=settings
        )
    drive, over = _named(ranking, pair, cables, options)
    times["drives"] = time.perf_counter() - t0
    slope = en.slope(base)
    u = en.total(base)
    below = tuple(below_ground(motion, base, en.ground, settings=settings))
    t0 = time.perf_counter()
    check = _check(pattern, motion, en, base, ranking, drive, ok, options, thickness, settings)
    times["check"] = time.perf_counter() - t0
    status, message = verdict(drive, below, check, over_limit=over)
    face_of = file_faces(pattern.n_faces, polygon_sizes(raw))
    base_faces = tuple(int(f) for f in np.unique(face_of[panels.triangles[base]]))
    result = DriveResult(
        status=status,
        message=message,
        source=source,
        pattern=pattern,
        options=options,
        thickness=thickness,
        density=density,
        thickness_from=thickness_from,
        s=s,
        u=u,
        u_gravity=en.gravity[base],
        u_spring=en.spring,
        slope=slope,
        friction=en.friction,
        coords=motion.in_base(base),
        base=base,
        base_faces=base_faces,
        base_auto=base_auto,
        masses=masses,
        drive=drive,
        ranking=tuple(ranking),
        pair=pair,
        cables=tuple(cables),
        bases=tuple(bases),
        sign_changes=tuple(act.zero_crossings(power, s)),
        brake_zones=tuple(act.zones(power, s, negative=True)),
        retract_brake_zones=tuple(act.zones(en.power(base, deploying=False), s, negative=False)),
        equilibria=tuple(equilibria(u, slope, s)),
        released=tuple(released(slope, en.friction, s)),
        ground=en.ground,
        below=below,
        check=check,
        motion=motion.to_dict(),
        gravity=g,
        seconds=times,
    )
    if out_dir is None:
        return result
    from dataclasses import replace

    from rigidfold.drive.files import write_drive

    written = write_drive(result, out_dir)
    return replace(result, written=tuple(str(p) for p in written))


def _named(
    ranking: list[act.Actuator],
    pair: act.Actuator | None,
    cables: list[act.Actuator],
    options: DriveOptions,
) -> tuple[act.Actuator | None, bool]:
    """(the named drive, whether it is over its limit): see the module's text."""

    def within(a: act.Actuator) -> bool:
        limit = options.max_tension if a.kind == "cable" else options.max_torque
        return limit is None or a.peak <= limit

    crease = next((a for a in ranking if a.controls), None)
    cable = min((c for c in cables if c.controls), key=lambda c: c.peak, default=None)
    controlling = [a for a in (crease, pair if pair and pair.controls else None, cable) if a]
    for a in controlling:
        if within(a):
            return a, False
    if controlling:
        return controlling[0], True
    return (ranking[0] if ranking and not ranking[0].still else None), False


def _check(pattern, motion, en, base, ranking, drive, ok, options, thickness, settings):
    """The independent check (:mod:`rigidfold.drive.check`) of the named crease, else the
    best crease that drives the whole motion, else the best of the ranking."""
    if not options.check:
        return not_run("--no-check")
    if drive is not None and drive.kind == "crease":
        chosen = drive
    else:
        chosen = next((a for a in ranking if a.controls), ranking[0] if ranking else None)
    if chosen is None or chosen.still:
        return not_run("no crease turns")
    panels = motion.panels
    edges = panels.hinge_edges
    h = int(np.flatnonzero(edges == chosen.ids[0])[0])
    slope = en.slope(base)
    with np.errstate(divide="ignore", invalid="ignore"):
        curve = slope / en.rate[:, h]
    in_control = ok[:, h]
    peak = float(np.abs(curve[in_control]).max(initial=0.0))
    states = pick_states(en.s, in_control, settings.drive.check_states)
    if len(states) < settings.drive.check_states:
        return not_run(
            f"crease {chosen.ids[0]} is in control at {len(states)} states only", chosen.ids[0]
        )
    coords = motion.in_base(base)
    rest = en.fold[-1] if options.spring_rest == "built" else np.zeros(len(edges))
    models = []
    for k in states.tolist():
        moment = -options.hinge_stiffness * en.length * (en.fold[k] - rest)
        model = HeldModel(
            coords=coords[k],
            base_faces=panels.triangles[base],
            edge=int(chosen.ids[0]),
            hinge_edges=edges,
            spring_moment=moment,
            hardware=options.hardware,
            point_masses=options.point_masses,
        )
        models.append((float(en.s[k]), model, float(curve[k])))
    return check_curve(
        pattern,
        models,
        material=options.material,
        thickness=thickness,
        density=options.panel_density,
        peak=peak,
        edge=int(chosen.ids[0]),
        settings=settings,
    )
