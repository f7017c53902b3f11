"""The paper's crease patterns, lifted onto a target surface."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mesh import CreasePattern
from rigidfold.patterns.grids import grid11, pattern1, pattern1p, pattern2
from rigidfold.patterns.miura import miura
from rigidfold.protocols import TargetSurface

PATTERNS: dict[str, Callable[[], tuple[np.ndarray, np.ndarray]]] = {
    "1": pattern1,
    "1p": pattern1p,
    "2": pattern2,
    "11": grid11,
}
"""Pattern name -> function returning plan vertices (V, 2) and triangles (F, 3)."""


def plan(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Plan vertices (V, 2) and CCW triangles (F, 3) of a named pattern."""
    key = str(name)
    if key not in PATTERNS:
        raise ValueError(f"unknown pattern {name!r} (choose from {', '.join(PATTERNS)})")
    return PATTERNS[key]()


def build(name: str, surface: TargetSurface, *, settings: Settings = DEFAULTS) -> CreasePattern:
    """Crease pattern ``name`` with each vertex lifted onto ``surface`` (Step 1).

    surface : a :class:`rigidfold.surfaces.Surface` (any ``TargetSurface``; its optional
        ``check_finite(x, y)`` is called first);
    settings : the pattern's tolerances (:attr:`CreasePattern.settings`).
    """
    xy, faces = plan(name)
    check = getattr(surface, "check_finite", None)
    if check is not None:
        check(xy[:, 0], xy[:, 1])
    z = np.broadcast_to(np.asarray(surface.height(xy[:, 0], xy[:, 1]), dtype=float), len(xy))
    if not np.isfinite(z).all():
        bad = int(np.flatnonzero(~np.isfinite(z))[0])
        raise ValueError(
            f"surface {surface!r} is not finite at (x, y) = ({xy[bad, 0]:g}, {xy[bad, 1]:g})"
        )
    return CreasePattern.from_faces(np.column_stack([xy, z]), faces, settings=settings)


__all__ = ["PATTERNS", "build", "grid11", "miura", "pattern1", "pattern1p", "pattern2", "plan"]
