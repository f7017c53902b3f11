"""3D, CAD and cut-sheet exports of a design: its folded form and development diagram.

:func:`export_design` writes them all into one directory; :mod:`~rigidfold.exports.mesh3d`
(OBJ, STL, PLY, GLB), :mod:`~rigidfold.exports.cutsheet` (DXF and SVG cut sheets in mm) and
:mod:`~rigidfold.exports.schedule` (panel and crease CSV tables) write one kind each, from the
layout of :mod:`~rigidfold.exports.sheet`. trimesh and ezdxf are imported only when a file
is written.
"""

from rigidfold.exports.cutsheet import (
    CONVENTIONS,
    LAYERS,
    check_convention,
    dxf_text,
    sheet_svg_text,
    write_dxf,
    write_sheet_svg,
)
from rigidfold.exports.design import (
    EXPORT_FORMATS,
    Design,
    export_design,
    parse_formats,
    read_design,
)
from rigidfold.exports.mesh3d import MESH_FORMATS, mesh_bytes, write_mesh
from rigidfold.exports.schedule import crease_rows, panel_rows, write_schedule
from rigidfold.exports.sheet import Sheet, layout_sheet, panel_loops

__all__ = [
    "CONVENTIONS",
    "EXPORT_FORMATS",
    "LAYERS",
    "MESH_FORMATS",
    "Design",
    "Sheet",
    "check_convention",
    "crease_rows",
    "dxf_text",
    "export_design",
    "layout_sheet",
    "mesh_bytes",
    "panel_loops",
    "panel_rows",
    "parse_formats",
    "read_design",
    "sheet_svg_text",
    "write_dxf",
    "write_mesh",
    "write_schedule",
    "write_sheet_svg",
]
