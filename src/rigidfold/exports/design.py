"""Every export of one design at once, and a design read back from a FOLD file.

A design is a folded form (:class:`rigidfold.mesh.CreasePattern`, metres, z up) and its
development diagram (Step 8, (V, 2) metres). :func:`export_design` writes the files of
:data:`EXPORT_FORMATS` for it into one directory, named after the design:

=======  ==================================================================================
format   files (``NAME`` = the ``name`` argument)
=======  ==================================================================================
obj      ``NAME.obj``: folded form, one group per panel (:mod:`rigidfold.exports.mesh3d`)
stl      ``NAME.stl``: folded form, binary
ply      ``NAME.ply``: folded form, binary, face property ``panel``
glb      ``NAME.glb``: folded form, glTF binary, one node per panel, y up
dxf      ``NAME_cutsheet.dxf``: cut sheet, mm at 1:1 (:mod:`rigidfold.exports.cutsheet`)
svg      ``NAME_cutsheet.svg``: cut sheet, mm at 1:1, in the chosen convention
csv      ``NAME_panels.csv`` and ``NAME_creases.csv``: the schedule
         (:mod:`rigidfold.exports.schedule`)
fold-os  ``NAME.os.fold``: folded form as Origami Simulator opens it (y up, assignments
         M V F B, no frames; :mod:`rigidfold.exports.fold_os`)
=======  ==================================================================================
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.develop import Development, develop
from rigidfold.errors import RigidfoldError
from rigidfold.exports.cutsheet import CONVENTIONS, check_convention, write_dxf, write_sheet_svg
from rigidfold.exports.fold_os import write_origami_simulator_fold
from rigidfold.exports.mesh3d import MESH_FORMATS, write_mesh
from rigidfold.exports.schedule import write_schedule
from rigidfold.exports.sheet import MARGIN_MM, layout_sheet
from rigidfold.io import DesignFrames, FoldData, prepare_output_dir, read_fold, read_frames
from rigidfold.mesh import CreasePattern

EXPORT_FORMATS = (*MESH_FORMATS, "dxf", "svg", "csv", "fold-os")
"""The formats of :func:`export_design` (and of ``rigidfold export --to``)."""

_FILES = {
    "dxf": ("{}_cutsheet.dxf",),
    "svg": ("{}_cutsheet.svg",),
    "csv": ("{}_panels.csv", "{}_creases.csv"),
    "fold-os": ("{}.os.fold",),
}


def check_formats(formats: Sequence[str]) -> tuple[str, ...]:
    """The formats asked for (names of :data:`EXPORT_FORMATS`; blanks are none), checked, in
    :data:`EXPORT_FORMATS` order without repeats. Raises RigidfoldError naming an unknown
    format, or when none is given (the command line reads ``--to obj,dxf`` into names:
    :func:`rigidfold.cli.units.parse_formats`)."""
    if isinstance(formats, str):
        raise RigidfoldError(f"formats must be a sequence of format names, got {formats!r}")
    wanted = {str(name) for name in formats} - {""}
    unknown = sorted(wanted - set(EXPORT_FORMATS))
    if unknown:
        raise RigidfoldError(
            f"unknown export format {unknown[0]!r}; choose from {', '.join(EXPORT_FORMATS)}"
        )
    if not wanted:
        raise RigidfoldError(f"no export format given; choose from {', '.join(EXPORT_FORMATS)}")
    return tuple(f for f in EXPORT_FORMATS if f in wanted)


def export_paths(
    out_dir: str | os.PathLike, formats: Sequence[str] = EXPORT_FORMATS, *, name: str
) -> list[Path]:
    """The files :func:`export_design` writes into ``out_dir`` for ``formats`` (see
    :func:`check_formats`) and the stem ``name``, in :data:`EXPORT_FORMATS` order."""
    out = Path(out_dir)
    return [
        out / template.format(name) for fmt in check_formats(formats) for template in _files(fmt)
    ]


def _files(fmt: str) -> tuple[str, ...]:
    """The file names of one format, ``{}`` standing for the design's name."""
    return (f"{{}}.{fmt}",) if fmt in MESH_FORMATS else _FILES[fmt]


def export_design(
    pattern: CreasePattern,
    coords2d: np.ndarray,
    out_dir: str | os.PathLike,
    formats: Sequence[str] = EXPORT_FORMATS,
    *,
    name: str = "design",
    title: str = "",
    convention: str = CONVENTIONS[0],
    margin_mm: float = MARGIN_MM,
) -> list[Path]:
    """Write the exports of one design into ``out_dir`` (created when missing).

    Parameters
    ----------
    pattern : CreasePattern
        The folded form: coords (V, 3) metres, faces (F, 3), edges (E, 2), fixed creases.
    coords2d : (V, 2) float
        Its development diagram, metres (e.g. ``rigidfold.develop.develop(pattern)``).
    out_dir : path
        Output directory.
    formats : sequence of str
        Some of :data:`EXPORT_FORMATS` (see :func:`check_formats`); default all.
    name : str
        Stem of the files (see the module's table); a plain file name.
    title : str
        Title written into the OBJ header and the SVG.
    convention : str
        The cut sheet SVG's convention (:data:`rigidfold.exports.cutsheet.CONVENTIONS`).
    margin_mm : float
        Margin around the cut sheet, mm.

    Returns
    -------
    list of Path
        The files written, in :data:`EXPORT_FORMATS` order.

    Raises
    ------
    ValueError
        For an unknown format or convention, a ``name`` that is not a plain file name,
        ``coords2d`` that is not a finite (V, 2) array, or a file that cannot be written.
    """
    chosen = check_formats(formats)
    check_convention(convention)
    if not name or Path(name).name != name or name in (".", ".."):
        raise RigidfoldError(f"name must be a plain file name, got {name!r}")
    sheet = layout_sheet(pattern, coords2d, margin_mm=margin_mm)
    out = prepare_output_dir(out_dir)
    written: list[Path] = []
    for fmt in chosen:
        paths = [out / template.format(name) for template in _files(fmt)]
        if fmt in MESH_FORMATS:
            written.append(write_mesh(paths[0], pattern, title=title))
        elif fmt == "dxf":
            written.append(write_dxf(paths[0], sheet))
        elif fmt == "svg":
            written.append(write_sheet_svg(paths[0], sheet, title=title, convention=convention))
        elif fmt == "csv":
            written += write_schedule(paths[0], paths[1], sheet)
        else:
            written.append(write_origami_simulator_fold(paths[0], pattern, title=title))
    return written


@dataclass(frozen=True, eq=False)
class Design:
    """A design read from a FOLD file.

    data : FoldData
        The file's frame 0, the folded form (:func:`rigidfold.io.read_fold`).
    coords2d : (V, 2) float64
        Its development diagram, metres.
    diagram : str
        Where the diagram came from: ``"frame K"`` (the file's ``creasePattern`` frame K,
        as rigidfold writes it) or ``"computed"`` (Step 8 run on reading).
    development : Development or None
        Step 8's result when the diagram was computed, else None.
    frames : DesignFrames
        The file's frames (:func:`rigidfold.io.read_frames`: its diagram and motion), read
        once with the file.
    """

    data: FoldData
    coords2d: np.ndarray
    diagram: str
    development: Development | None
    frames: DesignFrames | None = None

    @property
    def pattern(self) -> CreasePattern:
        return self.data.pattern


def read_design(path: str | os.PathLike, *, up: str = "z", settings: Settings = DEFAULTS) -> Design:
    """Read a design from a FOLD file: its folded form (frame 0, read with ``up``, see
    :func:`rigidfold.io.read_fold`) and its development diagram.

    The diagram is the last ``creasePattern`` frame whose model is the folded form's (the
    same vertices, edges and faces: the frame that ``rigidfold generate``, ``develop`` and
    ``deform`` write, in metres, z up); a file without one gets its diagram from
    :func:`rigidfold.develop.develop`. Raises ValueError for an unreadable file, or a
    computed diagram with non-finite coordinates.
    """
    data = read_fold(path, up=up, settings=settings)
    frames = read_frames(data.raw, data.pattern.n_vertices, str(path))
    if frames.diagram is not None:
        return Design(data, frames.diagram.copy(), f"frame {frames.diagram_frame}", None, frames)
    development = develop(data.pattern, settings=settings)
    if not np.isfinite(development.coords2d).all():
        raise RigidfoldError(
            f"{path}: the development diagram could not be computed ({development.message})"
        )
    return Design(data, development.coords2d, "computed", development, frames)
