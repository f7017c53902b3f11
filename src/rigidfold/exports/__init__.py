"""3D, CAD and cut-sheet exports of a design: its folded form and development diagram.

:func:`export_design` writes them all into one directory; :mod:`~rigidfold.exports.mesh3d`
(OBJ, STL, PLY, GLB), :mod:`~rigidfold.exports.cutsheet` (DXF and SVG cut sheets in mm),
:mod:`~rigidfold.exports.schedule` (panel and crease CSV tables), from the layout of
:mod:`~rigidfold.exports.sheet`, and :mod:`~rigidfold.exports.fold_os` (the FOLD file that
Origami Simulator opens) write one kind each. trimesh and ezdxf are imported only when a file
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
    check_formats,
    export_design,
    export_paths,
    read_design,
)
from rigidfold.exports.fold_os import origami_simulator_fold, write_origami_simulator_fold
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
    "check_formats",
    "crease_rows",
    "dxf_text",
    "export_design",
    "export_paths",
    "layout_sheet",
    "mesh_bytes",
    "origami_simulator_fold",
    "panel_loops",
    "panel_rows",
    "read_design",
    "sheet_svg_text",
    "write_dxf",
    "write_mesh",
    "write_origami_simulator_fold",
    "write_schedule",
    "write_sheet_svg",
]
