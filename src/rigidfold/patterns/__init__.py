"""Crease patterns in plan (the paper's, grids, footprint meshes, FOLD and SVG files), lifted
onto a surface. Which pattern a case takes is a :data:`PatternSpec` (read from the command
line's text by :mod:`rigidfold.generate.specs`), whose plan :func:`make_plan` makes."""

from __future__ import annotations

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern
from rigidfold.patterns.files import FILE_FORMATS, PatternFile, read_pattern_file
from rigidfold.patterns.footprint import (
    check_footprint,
    footprint_mesh,
    footprint_points,
    read_footprint,
)
from rigidfold.patterns.grids import DIAGONALS, grid, grid11, pattern1, pattern1p, pattern2
from rigidfold.patterns.miura import miura
from rigidfold.patterns.spec import (
    DEFAULT_SIZE,
    FORMS,
    PATTERN_TYPES,
    PATTERNS,
    FilePattern,
    GridPattern,
    MeshPattern,
    PaperPattern,
    PatternKeywords,
    PatternSpec,
    Plan,
    PlanKeywords,
    check_size,
    given_options,
    make_plan,
    refuse_options,
)
from rigidfold.protocols import TargetSurface


def build(
    pattern: PatternSpec | Plan, surface: TargetSurface, *, settings: Settings = DEFAULTS
) -> CreasePattern:
    """Crease pattern ``pattern`` with each vertex lifted onto ``surface`` (Step 1).

    pattern : a :class:`Plan` or a :data:`PatternSpec` for :func:`make_plan` (its default
        size, diagonals and edge length);
    surface : a :class:`rigidfold.surfaces.Surface` (any ``TargetSurface``; its optional
        ``check_finite(x, y)`` is called first);
    settings : the pattern's tolerances (:attr:`CreasePattern.settings`).
    """
    plan = pattern if isinstance(pattern, Plan) else make_plan(pattern, settings=settings)
    xy = plan.xy
    check = getattr(surface, "check_finite", None)
    if check is not None:
        check(xy[:, 0], xy[:, 1])
    z = np.broadcast_to(np.asarray(surface.height(xy[:, 0], xy[:, 1]), dtype=float), len(xy))
    if not np.isfinite(z).all():
        bad = int(np.flatnonzero(~np.isfinite(z))[0])
        raise RigidfoldError(
            f"surface {surface!r} is not finite at (x, y) = ({xy[bad, 0]:g}, {xy[bad, 1]:g})"
        )
    return CreasePattern.from_faces(
        np.column_stack([xy, z]), plan.faces, plan.fixed, settings=settings
    )


__all__ = [
    "DEFAULT_SIZE",
    "DIAGONALS",
    "FILE_FORMATS",
    "FORMS",
    "PATTERNS",
    "PATTERN_TYPES",
    "FilePattern",
    "GridPattern",
    "MeshPattern",
    "PaperPattern",
    "PatternFile",
    "PatternKeywords",
    "PatternSpec",
    "Plan",
    "PlanKeywords",
    "build",
    "check_footprint",
    "check_size",
    "footprint_mesh",
    "footprint_points",
    "given_options",
    "grid",
    "grid11",
    "make_plan",
    "miura",
    "pattern1",
    "pattern1p",
    "pattern2",
    "read_footprint",
    "read_pattern_file",
    "refuse_options",
]
