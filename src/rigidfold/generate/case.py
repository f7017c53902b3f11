"""A form-finding case: target surface + crease pattern + symmetry + settings (Step 1).

This is the entry point that validates user choices once, as typed values; the texts the CLI
and the study take are read by :mod:`rigidfold.generate.specs`, which calls it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Unpack

import numpy as np

from rigidfold import patterns
from rigidfold.config import DEFAULTS, DesignSettings, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern, geometry
from rigidfold.optimize import FormFindingProblem, OptimizeResult
from rigidfold.protocols import SymmetryPlane, TargetSurface
from rigidfold.surfaces import Surface, SurfaceSpec, surface_of


@dataclass(frozen=True, eq=False)
class Case:
    """Everything problem (6) needs, validated.

    surface : TargetSurface (a Surface); plan : the crease pattern in plan and how it was made
    (its spec, size, diagonals, edge length); pattern : CreasePattern (the plan lifted onto the
    target surface); planes : mirror planes (SymmetryPlane) used for constraint (9);
    settings : Settings; inputs : the files the pattern and the surface were read from (a
    FOLD or SVG pattern, a footprint file, a mesh or FOLD surface), which a run must never
    remove or replace; notes : what the case changed of the settings given, one sentence
    each (the sector-angle bounds widened to a drawn plan's angles).
    """

    surface: TargetSurface
    plan: patterns.Plan
    pattern: CreasePattern
    planes: tuple[SymmetryPlane, ...]
    settings: Settings
    inputs: tuple[Path, ...] = ()
    notes: tuple[str, ...] = ()

    @property
    def warnings(self) -> list[str]:
        """What looks like a slip, one sentence each (the case is built all the same): a plan
        with a side of ``settings.inputs.unit_warning_size`` metres or more, or a ``dz`` larger than
        the plan, given in millimetres rather than metres."""
        width, height = self.plan.box
        size, dz = f"{width:g} m x {height:g} m", self.settings.design.dz
        out = []
        if max(width, height) >= self.settings.inputs.unit_warning_size:
            out.append(
                f"the plan is {size}: sizes are in metres; for millimetres divide by 1000 "
                f"(--size {width / 1000:g}x{height / 1000:g})"
            )
        if dz > max(width, height):
            out.append(
                f"--dz {dz:g} m is larger than the plan ({size}): it is in metres (the default "
                f"{DEFAULTS.design.dz:g} m is {DEFAULTS.design.dz * 1000:g} mm)"
            )
        return out

    def problem(
        self, *, build_ipopt: bool = True, project_first: bool = False
    ) -> FormFindingProblem:
        """Build problem (6) for this case (``project_first``: see :class:`FormFindingProblem`)."""
        return FormFindingProblem(
            self.pattern,
            self.surface,
            planes=self.planes,
            settings=self.settings,
            build_ipopt=build_ipopt,
            project_first=project_first,
        )

    def deviation(self, coords: np.ndarray) -> np.ndarray:
        """z minus the target's height at each vertex's (x, y), metres.  (V, 3) -> (V,)"""
        height = self.surface.height(coords[:, 0], coords[:, 1])
        return coords[:, 2] - np.asarray(height, dtype=float)

    def metadata(self) -> dict:
        """JSON-serialisable description of the case: the surface, the pattern spec with its
        plan size, diagonals, edge length and footprint, the symmetry and the design bounds."""
        s = self.settings
        return {
            "surface": self.surface.metadata(),
            **self.plan.metadata(),
            "symmetry_planes": [str(p) for p in self.planes],
            "dz_m": s.design.dz,
            "theta_min_deg": math.degrees(s.design.theta_min),
            "theta_max_deg": math.degrees(s.design.theta_max),
            "rho_max_deg": None if s.design.rho_max is None else math.degrees(s.design.rho_max),
            "F_tol": s.design.f_tol,
        }


def make_case(
    surface: SurfaceSpec | Surface,
    pattern: patterns.PatternSpec | patterns.Plan,
    *,
    symmetric: bool = False,
    settings: Settings = DEFAULTS,
    **pattern_options: Unpack[patterns.PatternKeywords],
) -> Case:
    """Validate the user's choices and build the initial triangulated shape.

    surface : a :class:`rigidfold.surfaces.SurfaceSpec` (:func:`rigidfold.surfaces.surface_of`:
        bezier with its seed, dome, hp, expr with its expression, a mesh file, a FOLD file's
        3D shape) or a Surface. A named built-in surface is scaled to the bounding box of
        the pattern's plan (the paper's surfaces on the 3 m square); a mesh is placed with its
        plan's lower-left corner at (0, 0); an "expr" surface and a Surface object are used
        as they are.
    pattern : a :data:`rigidfold.patterns.PatternSpec` with its keywords
        (:func:`rigidfold.patterns.make_plan`, :class:`rigidfold.patterns.PatternKeywords`:
        ``size`` as (W, H) metres, ``diagonals``, ``edge_length``, ``scale``, ``up``,
        ``rigid_panels``), or a Plan made already (then only ``up``); ``up``, the up axis
        (``"z"`` or ``"y"``) of a FOLD pattern, is also that of a mesh or FOLD surface.
    ``symmetric`` imposes the surface's own mirror planes (9); a surface without any is
    refused. The texts the command line takes are read by :mod:`rigidfold.generate.specs`
    (:func:`~rigidfold.generate.specs.case_from_specs` reads and makes a case in one call).
    """
    up = pattern_options.get("up", "z")
    if isinstance(pattern, patterns.Plan):
        extra = sorted(set(pattern_options) - {"up"})
        if extra:
            raise TypeError(f"a Plan is made already: {', '.join(extra)} cannot change it")
        plan = pattern
    else:
        plan = patterns.make_plan(pattern, settings=settings, **pattern_options)
    if isinstance(surface, Surface):
        surf = surface
    elif isinstance(surface, SurfaceSpec):
        surf = surface_of(surface, box=plan.box, up=up, settings=settings)
    else:
        raise TypeError(
            f"a case's surface is a SurfaceSpec or a Surface, got {type(surface).__name__} "
            "(rigidfold.generate.specs.parse_surface_spec reads text)"
        )
    given = settings.design
    settings = widened_angle_bounds(plan, settings)
    notes: tuple[str, ...] = (
        () if settings.design is given else (_widened_note(given, settings.design),)
    )
    shape = patterns.build(plan, surf, settings=settings)
    check_sector_angles(shape, settings)
    held = _held_note(shape, settings)
    notes += () if held is None else (held,)
    planes = tuple(surf.mirror_planes) if symmetric else ()
    if symmetric and not planes:
        raise RigidfoldError(
            f"surface '{surf.name}' has no mirror planes; --symmetric needs a symmetric surface "
            "(dome or hp)"
        )
    return Case(surf, plan, shape, planes, settings, _input_files(plan.spec, surface), notes)


def widened_angle_bounds(plan: patterns.Plan, settings: Settings) -> Settings:
    """``settings`` with the sector-angle bounds widened to the plan's own angles where
    ``Settings.design.theta_widen`` asks it of this plan (``"files"``: a pattern read from a
    FOLD or SVG file; ``"all"``; ``"none"``) and the plan breaks them by more than
    ``theta_widen_tol``: theta_min to (1 - room) x its smallest angle, theta_max to its largest
    plus room x (pi - its largest), ``room`` = ``theta_widen_room``, the side it breaks only;
    else ``settings`` as they are.

    A design's sector angles are those of its flat pattern, so bounds that the drawn plan
    itself breaks could only be met by redrawing it: problem (6) would start by forcing every
    sliver of the drawing into the bounds (slow first solves, or no design within dz).
    """
    d = settings.design
    if d.theta_widen == "none" or (
        d.theta_widen == "files" and not isinstance(plan.spec, patterns.FilePattern)
    ):
        return settings
    angles = plan_corner_angles(plan)
    low, top = float(angles.min()), float(angles.max())
    room = d.theta_widen_room
    lo = (1 - room) * low if low < d.theta_min - d.theta_widen_tol else d.theta_min
    hi = top + room * (math.pi - top) if top > d.theta_max + d.theta_widen_tol else d.theta_max
    if lo == d.theta_min and hi == d.theta_max:
        return settings
    return settings.with_(theta_min=lo, theta_max=hi)


def _widened_note(given: DesignSettings, widened: DesignSettings) -> str:
    """One sentence: the sector-angle bounds, as given and as widened."""

    def bounds(d: DesignSettings) -> str:
        return f"[{math.degrees(d.theta_min):.4g}, {math.degrees(d.theta_max):.4g}]"

    return (
        f"the sector-angle bounds are {bounds(widened)} degrees (given: {bounds(given)}): "
        "the crease pattern's plan has angles outside those given, which a design could "
        "meet only by redrawing it (--theta-widen none keeps the bounds given)"
    )


def _held_note(shape: CreasePattern, settings: Settings) -> str | None:
    """One sentence, where triangles whose three vertices are corners of the plan (held on
    the surface by (8)) have angles there outside the sector-angle bounds: problem (6) keeps
    those angles as they are (:func:`rigidfold.optimize.nlp.held_faces`); else None."""
    corner = np.zeros(shape.n_vertices, dtype=bool)
    corner[shape.corners] = True
    held = corner[shape.faces].all(axis=1)
    lo, hi = settings.design.theta_min, settings.design.theta_max
    angles = shape.corner_angles[held]
    breaks = ((angles < lo) | (angles > hi)).any(axis=1)
    if not breaks.any():
        return None
    deg = np.degrees(angles[breaks])
    return (
        f"{int(breaks.sum())} triangle(s) with all three vertices at corners of the plan, "
        f"which stay on the target surface, have angles there of {deg.min():.3g} to "
        f"{deg.max():.4g} degrees, outside the sector-angle bounds "
        f"[{math.degrees(lo):.4g}, {math.degrees(hi):.4g}]: no shape can change them, and the "
        "design keeps them as they are"
    )


def plan_corner_angles(plan: patterns.Plan) -> np.ndarray:
    """The plan's sector angles as drawn, (F, 3) float64 radians (entry ``[f, k]`` at vertex
    ``plan.faces[f, k]``): a file's own (:attr:`rigidfold.patterns.Plan.drawn_angles`, in 3D
    for a folded FOLD file, whose projection is no flat pattern), else the flat plan's."""
    if plan.drawn_angles is not None:
        return plan.drawn_angles
    flat = np.column_stack([plan.xy, np.zeros(len(plan.xy))])
    return geometry.corner_angles(flat, plan.faces)


def check_sector_angles(shape: CreasePattern, settings: Settings = DEFAULTS) -> None:
    """Refuse an initial shape with more than ``settings.inputs.theta_far_share`` of its sector
    angles far outside [theta_min, theta_max] (below theta_min / 2 or above
    (theta_max + pi) / 2), before any problem is built: one line saying how many angles lie
    below and above the bounds, the smallest and the largest, and which options move the
    bounds. Raises ValueError."""
    angles = shape.corner_angles
    lo, hi = settings.design.theta_min, settings.design.theta_max
    far = (angles < lo / 2) | (angles > (hi + math.pi) / 2)
    if far.sum() <= settings.inputs.theta_far_share * angles.size:
        return
    deg = np.degrees(angles)
    below, above = int((angles < lo).sum()), int((angles > hi).sum())
    parts = []
    if below:
        parts.append(f"{below} below {math.degrees(lo):g} degrees (the smallest {deg.min():.2g})")
    if above:
        parts.append(f"{above} above {math.degrees(hi):g} degrees (the largest {deg.max():.4g})")
    raise RigidfoldError(
        f"the crease pattern's initial shape has {below + above} of {angles.size} sector angles "
        f"outside the bounds [{math.degrees(lo):g}, {math.degrees(hi):g}] degrees: "
        f"{' and '.join(parts)}; {int(far.sum())} of them are far outside (more than "
        f"{settings.inputs.theta_far_share:.0%} of the angles, "
        "Settings.inputs.theta_far_share), which problem "
        "(6) cannot bring inside: allow them with --theta-min DEG / --theta-max DEG, or choose "
        "a pattern without such slivers"
    )


def _input_files(pattern: patterns.PatternSpec, surface: SurfaceSpec | Surface) -> tuple[Path, ...]:
    """The files named by a pattern spec (``FILE.fold``, ``FILE.svg``, ``mesh:FILE``) and a
    surface spec (``mesh:FILE``, ``fold:FILE``); specs were validated by reading them."""
    files = []
    if isinstance(pattern, patterns.FilePattern):
        files.append(pattern.path)
    elif isinstance(pattern, patterns.MeshPattern) and pattern.file is not None:
        files.append(pattern.file)
    if isinstance(surface, SurfaceSpec) and surface.path is not None:
        files.append(surface.path)
    return tuple(files)


def fixed_mask(fixed: Sequence[int], pattern: CreasePattern) -> np.ndarray:
    """The (E,) bool mask of the crease lines ``fixed`` (indices into the pattern's edges,
    ``optimize --fixed``), every index checked."""
    mask = np.zeros(pattern.n_edges, dtype=bool)
    for e in fixed:
        if isinstance(e, bool) or not isinstance(e, int | np.integer):
            raise RigidfoldError(f"--fixed expects edge indices, got {e!r}")
        if not 0 <= e < pattern.n_edges:
            raise RigidfoldError(f"--fixed edge {e} out of range 0..{pattern.n_edges - 1}")
        if pattern.is_boundary_edge[e]:
            raise RigidfoldError(f"--fixed edge {e} is a boundary edge, not a crease line")
        mask[e] = True
    return mask


def shape_summary(case: Case, result: OptimizeResult, build_time: float) -> dict:
    """summary.json content: solver figures, sizes and shape measures of a solution."""
    shape = result.pattern
    dz = case.deviation(shape.coords)
    angles = np.degrees(shape.corner_angles)
    free = shape.free_creases
    return {
        **result.to_dict(),
        "build_time_s": build_time,
        "V": shape.n_vertices,
        "E": shape.n_edges,
        "F_faces": shape.n_faces,
        "facets": shape.n_facets,
        "fixed_creases": shape.fixed_creases.tolist(),
        "generic_dof": shape.generic_dof,
        "max_abs_dz_m": float(np.abs(dz).max()),
        "min_sector_angle_deg": float(angles.min()),
        "max_sector_angle_deg": float(angles.max()),
        "max_abs_fold_angle_deg": float(np.degrees(np.abs(shape.fold_angles[free])).max())
        if len(free)
        else 0.0,
        "case": case.metadata(),
    }
