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
from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern
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
    remove or replace.
    """

    surface: TargetSurface
    plan: patterns.Plan
    pattern: CreasePattern
    planes: tuple[SymmetryPlane, ...]
    settings: Settings
    inputs: tuple[Path, ...] = ()

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

    def problem(self, *, build_ipopt: bool = True) -> FormFindingProblem:
        """Build problem (6) for this case."""
        return FormFindingProblem(
            self.pattern,
            self.surface,
            planes=self.planes,
            settings=self.settings,
            build_ipopt=build_ipopt,
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
    shape = patterns.build(plan, surf, settings=settings)
    settings = pattern_angle_bounds(shape, settings)  # the shape's tolerances are the same
    check_sector_angles(shape, settings)
    planes = tuple(surf.mirror_planes) if symmetric else ()
    if symmetric and not planes:
        raise RigidfoldError(
            f"surface '{surf.name}' has no mirror planes; --symmetric needs a symmetric surface "
            "(dome or hp)"
        )
    return Case(surf, plan, shape, planes, settings, _input_files(plan.spec, surface))


def pattern_angle_bounds(shape: CreasePattern, settings: Settings) -> Settings:
    """``settings`` with the sector-angle bounds widened to the initial shape's own angles
    where ``Settings.design.theta_from_pattern`` asks: where it has angles below theta_min,
    that bound goes to 0.9 of its smallest; where above theta_max, that one to its largest
    plus a tenth of what is left to 180 degrees (so the start lies strictly inside); else
    ``settings`` as they are."""
    d = settings.design
    if not d.theta_from_pattern:
        return settings
    low, top = float(shape.corner_angles.min()), float(shape.corner_angles.max())
    lo = 0.9 * low if low < d.theta_min else d.theta_min
    hi = top + 0.1 * (math.pi - top) if top > d.theta_max else d.theta_max
    if lo == d.theta_min and hi == d.theta_max:
        return settings
    return settings.with_(theta_min=lo, theta_max=hi)


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
