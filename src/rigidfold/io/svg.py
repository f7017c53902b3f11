"""SVG drawing of a crease pattern (a development diagram or the plan of a shape).

Mountain folds red, valley folds blue, the boundary black, fixed creases grey dashed, flat
free creases light grey. The assignment comes from the 3D shape (or is given, e.g. a FOLD
file's own letters); the positions from the 2D coordinates drawn.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rigidfold.io.files import atomic_write
from rigidfold.io.fold import edge_assignments
from rigidfold.mesh import CreasePattern

STYLE = {
    "B": 'stroke="#000000" stroke-width="1.6"',
    "M": 'stroke="#d62728" stroke-width="1.2"',
    "V": 'stroke="#1f77b4" stroke-width="1.2"',
    "J": 'stroke="#888888" stroke-width="0.8" stroke-dasharray="4 3"',
    "F": 'stroke="#cccccc" stroke-width="0.8"',
}


def svg_text(
    pattern: CreasePattern,
    coords2d: np.ndarray,
    *,
    width_px: float = 600.0,
    title: str = "",
    assignment: list[str] | None = None,
) -> str:
    """SVG document drawing the edges of ``pattern`` at ``coords2d`` (V, 2), y upwards.

    ``assignment`` : E letters of :data:`STYLE` (default: :func:`edge_assignments` of the
    shape); ``"U"`` (unassigned) is drawn as ``"F"``.
    """
    xy = np.asarray(coords2d, dtype=float)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = max(float((hi - lo).max()), 1e-12)
    margin = 20.0
    scale = (width_px - 2 * margin) / span
    height_px = (hi[1] - lo[1]) * scale + 2 * margin
    px = (xy[:, 0] - lo[0]) * scale + margin
    py = height_px - ((xy[:, 1] - lo[1]) * scale + margin)
    lines = []
    kinds = [
        "F" if a == "U" else a
        for a in (edge_assignments(pattern) if assignment is None else assignment)
    ]
    order = sorted(range(pattern.n_edges), key=lambda e: "FJMVB".index(kinds[e]))
    for e in order:
        u, v = pattern.edges[e]
        lines.append(
            f'<line x1="{px[u]:.2f}" y1="{py[u]:.2f}" x2="{px[v]:.2f}" y2="{py[v]:.2f}" '
            f'{STYLE[kinds[e]]} stroke-linecap="round"/>'
        )
    head = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width_px:.0f}" '
        f'height="{height_px:.0f}" viewBox="0 0 {width_px:.0f} {height_px:.0f}">'
    )
    body = [f"<title>{_escape(title)}</title>"] if title else []
    return (
        "\n".join(
            [head, *body, '<rect width="100%" height="100%" fill="white"/>', *lines, "</svg>"]
        )
        + "\n"
    )


def write_svg(
    path: str | os.PathLike, pattern: CreasePattern, coords2d: np.ndarray, **kwargs
) -> Path:
    """Write :func:`svg_text` atomically (:func:`rigidfold.io.atomic_write`).

    Raises ValueError ``"cannot write '<path>': <reason>"`` when the file cannot be written.
    """
    return atomic_write(path, svg_text(pattern, coords2d, **kwargs))


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
