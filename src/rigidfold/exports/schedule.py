"""The panel and hinge schedule of a design: two CSV tables.

Two files rather than one with sections, so that each opens as one table in a spreadsheet
or ``csv.DictReader``. Lengths and areas are those of the development diagram (what is cut;
equal to the folded form's up to the diagram's error D), fold angles those of the folded
form. They are computed from the :class:`rigidfold.exports.sheet.Sheet` (the diagram turned
and moved, which keeps lengths and areas).

``panels`` (one row per panel, a facet of the pattern: triangles joined by fixed creases):

==============  ===================================================================
``panel``       panel index K (the ``panel_K`` group of the 3D files)
``vertices``    vertex indices of its outline, counter-clockwise, space-separated;
                ``" | "`` between loops when the panel has a hole
``triangles``   number of triangles in it
``area_m2``     its area in the development diagram, m^2
==============  ===================================================================

``creases`` (one row per edge of the pattern, boundary edges included):

=================  ================================================================
``crease``         edge index E (as in the FOLD file's ``edges_vertices`` and the labels
                   of the cut sheet)
``vertex_a/b``     its two vertex indices
``length_m``       its length in the development diagram, m
``fold_angle_deg``  signed fold angle in degrees, valley positive (0 on the boundary)
``assignment``     ``M`` mountain, ``V`` valley, ``flat`` (a free crease flat in the design),
                   ``fixed`` (inside a panel) or ``boundary``
``panel_left``     panel on the left of vertex_a -> vertex_b, -1 for none
``panel_right``    panel on the right, -1 for none
=================  ================================================================
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from rigidfold.develop.diagram import signed_areas
from rigidfold.exports.sheet import MM_PER_M, Sheet
from rigidfold.io.files import atomic_write

ASSIGNMENT_WORDS = {"M": "M", "V": "V", "F": "flat", "J": "fixed", "B": "boundary"}
"""The schedule's word for each assignment letter."""

PANEL_COLUMNS = ("panel", "vertices", "triangles", "area_m2")
CREASE_COLUMNS = (
    "crease",
    "vertex_a",
    "vertex_b",
    "length_m",
    "fold_angle_deg",
    "assignment",
    "panel_left",
    "panel_right",
)


def panel_rows(sheet: Sheet) -> list[dict]:
    """One dict per panel (:data:`PANEL_COLUMNS`)."""
    pattern = sheet.pattern
    areas = np.bincount(
        pattern.facets,
        weights=signed_areas(sheet.xy, pattern.faces) / MM_PER_M**2,
        minlength=pattern.n_facets,
    )
    triangles = np.bincount(pattern.facets, minlength=pattern.n_facets)
    return [
        {
            "panel": k,
            "vertices": " | ".join(" ".join(map(str, loop.tolist())) for loop in loops),
            "triangles": int(triangles[k]),
            "area_m2": float(areas[k]),
        }
        for k, loops in enumerate(sheet.panel_loops)
    ]


def crease_rows(sheet: Sheet) -> list[dict]:
    """One dict per edge (:data:`CREASE_COLUMNS`)."""
    pattern = sheet.pattern
    lengths = sheet.lengths / MM_PER_M
    ef = pattern.edge_faces
    side = np.where(ef >= 0, pattern.facets[np.maximum(ef, 0)], -1)
    return [
        {
            "crease": e,
            "vertex_a": int(u),
            "vertex_b": int(v),
            "length_m": float(lengths[e]),
            "fold_angle_deg": float(sheet.fold_angles_deg[e]),
            "assignment": ASSIGNMENT_WORDS[sheet.assignment[e]],
            "panel_left": int(side[e, 0]),
            "panel_right": int(side[e, 1]),
        }
        for e, (u, v) in enumerate(pattern.edges.tolist())
    ]


def csv_text(rows: list[dict], columns: tuple[str, ...]) -> str:
    """CSV text with a header line; floats written with 17 significant digits."""
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: f"{v:.17g}" if isinstance(v, float) else v for k, v in row.items()})
    return stream.getvalue()


def write_schedule(
    panels_path: str | os.PathLike,
    creases_path: str | os.PathLike,
    sheet: Sheet,
) -> list[Path]:
    """Write the panel and crease tables of the design laid out on ``sheet`` atomically
    (:func:`rigidfold.io.atomic_write`). Returns [panels_path, creases_path]."""
    return [
        atomic_write(panels_path, csv_text(panel_rows(sheet), PANEL_COLUMNS)),
        atomic_write(creases_path, csv_text(crease_rows(sheet), CREASE_COLUMNS)),
    ]
