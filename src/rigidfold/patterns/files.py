"""Crease patterns drawn in other tools: FOLD files and SVG drawings, read as plans.

A FOLD file (Origami Simulator, Rabbit Ear, a CAD exporter, rigidfold itself) gives its
``vertices_coords`` in plan: a flat crease pattern as drawn, a 3D folded form by its
projection onto the xy plane (``up="y"`` first turns a y-up file). An SVG drawing in Origami
Simulator's colours (:mod:`rigidfold.io.svg_read`) gives its lines, split where they cross.
Polygon faces are triangulated; the diagonals added are free creases, or fixed creases when
the faces are rigid panels (``rigid_panels``). ``"J"`` edges and edges marked in
``edges_rigidfold:fixed`` of a FOLD file start as fixed creases.

Every length is metres. A file with a physical unit (FOLD ``frame_unit``, SVG ``width`` in
mm, cm, in or pt) keeps its size. A drawing without one is scaled to fit inside ``size``
(default 3 m x 3 m) with its aspect ratio kept, or by ``scale`` metres per drawing unit.
Then the plan is translated so that the lower-left corner of its bounding box is at (0, 0).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.fold import read_fold
from rigidfold.mesh import geometry
from rigidfold.mesh.triangulate import orient_up, triangulate_polygons
from rigidfold.patterns.grids import DEFAULT_SIZE, check_extent

if TYPE_CHECKING:
    from rigidfold.io.svg_read import SvgDrawing

FILE_FORMATS = {".fold": "FOLD", ".svg": "SVG"}
"""File name suffixes read as crease patterns, and their formats."""


@dataclass(frozen=True, eq=False)
class PatternFile:
    """A crease pattern read from a file, in metres, placed at (0, 0).

    xy : (V, 2) float64 plan vertices, the lower-left corner of their bounding box at (0, 0);
    faces : (F, 3) int64 triangles, counter-clockwise seen from +z;
    fixed : (k, 2) int64 vertex pairs of the crease lines that start fixed;
    source : dict, what was read and how: file name, format, unit, metres per unit, up axis,
        rigid panels, and the size the drawing was fitted into (None when not fitted);
    sector_angles : (F, 3) float64 radians, the corner angles of ``faces`` in the file's own
        coordinates (a folded FOLD file's in 3D, not those of its projection): the panels'
        angles as their designer drew them.
    """

    xy: np.ndarray
    faces: np.ndarray
    fixed: np.ndarray
    source: dict
    sector_angles: np.ndarray


def read_pattern_file(
    path: str | os.PathLike,
    *,
    size: tuple[float, float] | None = None,
    scale: float | None = None,
    up: str = "z",
    rigid_panels: bool = False,
    settings: Settings = DEFAULTS,
) -> PatternFile:
    """The plan of a FOLD or SVG crease pattern; a one-line ValueError naming the file if bad.

    path : a ``.fold`` or ``.svg`` file;
    size : (W, H) metres that a drawing without units is fitted into (default 3 x 3);
    scale : metres per unit of a drawing without units (instead of fitting it into ``size``);
    up : the up axis of a FOLD file (``"z"`` or ``"y"``; an SVG drawing is a plan already);
    rigid_panels : the diagonals added to triangulate polygon faces are fixed creases (the
        faces are rigid flat panels) instead of free ones;
    settings : the tolerances of reading and triangulating (``triangulation_area_tol``,
        ``degenerate_area``, ``plan_area_tol``) and the plan's bounds (``min_pattern_size``,
        ``max_coordinate``; an SVG drawing's triangles, counted before its faces are
        triangulated, ``max_pattern_faces``).
    """
    path = Path(path)
    kind = FILE_FORMATS.get(path.suffix.lower())
    if kind is None:
        raise RigidfoldError(
            f"a crease pattern file is {' or '.join(FILE_FORMATS)}, got {os.fspath(path)!r}"
        )
    if kind == "FOLD":
        data = read_fold(path, up=up, rigid_panels=rigid_panels, settings=settings)
        xy = data.pattern.coords[:, :2]
        faces = data.pattern.faces
        fixed = data.pattern.edges[data.pattern.fixed]
        angles = data.pattern.corner_angles  # in 3D for a folded form
        unit, per_unit = data.unit, data.scale
        plan, fitted, per_unit = _scaled(xy, path, unit, per_unit, size, scale, settings)
    else:
        from rigidfold.io.svg_read import read_svg

        drawing = read_svg(path, settings=settings)
        unit, per_unit = drawing.unit, drawing.scale
        xy = drawing.xy * per_unit
        # the extent is checked before the faces are triangulated (where it could overflow)
        plan, fitted, per_unit = _scaled(xy, path, unit, per_unit, size, scale, settings)
        count = sum(len(polygon) - 2 for polygon in drawing.polygons)  # n - 2 per polygon
        if count > settings.limits.max_pattern_faces:
            raise RigidfoldError(
                f"{path}: its {len(drawing.polygons)} faces make {count} triangles, more than "
                f"{settings.limits.max_pattern_faces} (Settings.limits.max_pattern_faces)"
            )
        coords = np.column_stack([xy, np.zeros(len(xy))])
        triangles, diagonals = _triangulate_drawing(path, drawing, coords, settings)
        faces = orient_up(coords, triangles)
        angles = geometry.corner_angles(coords, faces)
        fixed = np.asarray(diagonals if rigid_panels else [], dtype=np.int64).reshape(-1, 2)
    xy = plan
    _check_unfolded(xy, faces, path, settings)
    source = {
        "file": path.name,
        "format": kind,
        "unit": unit,
        "metres_per_unit": per_unit,
        "up": up if kind == "FOLD" else None,
        "rigid_panels": rigid_panels,
        "fitted_into_m": fitted,
    }
    faces = np.asarray(faces, dtype=np.int64)
    return PatternFile(xy - xy.min(axis=0), faces, fixed, source, np.asarray(angles, dtype=float))


def _triangulate_drawing(
    path: Path, drawing: SvgDrawing, coords: np.ndarray, settings: Settings
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """:func:`triangulate_polygons` of the faces of an SVG drawing; a face that cannot be
    cut into triangles (degenerate: points of it nearly on one line or nearly one point) is
    refused in one line naming its corners in the file's coordinates and its shortest side,
    the lines that make it degenerate."""
    from rigidfold.io.svg_planar import at

    polygons = drawing.polygons
    tol = settings.geometry.triangulation_area_tol
    try:
        return triangulate_polygons(coords, polygons, area_tol=tol)
    except RigidfoldError:
        pass

    def refused(polygon: list[int]) -> bool:
        try:
            triangulate_polygons(coords, [polygon], area_tol=tol)
        except RigidfoldError:
            return True
        return False

    xy = drawing.xy[next(p for p in polygons if refused(p))]
    side = np.linalg.norm(np.roll(xy, -1, axis=0) - xy, axis=1)
    k = int(np.argmin(side))
    shown = ", ".join(at(p) for p in xy[:_SHOWN])
    more = f" and {len(xy) - _SHOWN} more" if len(xy) > _SHOWN else ""
    raise RigidfoldError(
        f"{path}: the face with corners {shown}{more} (drawing units, y down) cannot be cut "
        "into triangles: it is degenerate or nearly so, its shortest side, from "
        f"{at(xy[k])} to {at(xy[(k + 1) % len(xy)])}, {side[k]:.3g} long; lines drawn to "
        "one point that miss each other by that much are joined with a larger "
        "Settings.inputs.svg_merge_tol"
    )


_SHOWN = 8
"""How many corners of a degenerate face a message names."""


def _scaled(
    xy: np.ndarray,
    path: Path,
    unit: str,
    per_unit: float,
    size: tuple[float, float] | None,
    scale: float | None,
    settings: Settings,
) -> tuple[np.ndarray, list[float] | None, float]:
    """(plan in metres, the size fitted into or None, metres per file unit) of a plan read
    in metres (a drawing without units: one metre per unit); the plan's extent is checked
    (:func:`~rigidfold.patterns.grids.check_extent`) before it is scaled."""
    width, height = (float(v) for v in np.ptp(xy, axis=0))
    if unit != "unit":
        if size is not None or scale is not None:
            raise RigidfoldError(
                f"{path} is drawn in {unit} ({width:.6g} m x {height:.6g} m): --size and "
                "--scale are for drawings without units"
            )
        check_extent(width, height, f"{path} (drawn in {unit})", settings)
        return xy, None, per_unit
    if size is not None and scale is not None:
        raise RigidfoldError(f"{path}: give --size or --scale, not both")
    if scale is not None:
        if not (np.isfinite(scale) and scale > 0):
            raise RigidfoldError(f"a scale is metres per drawing unit, > 0, got {scale!r}")
        check_extent(width * scale, height * scale, f"{path} at --scale {scale:g}", settings)
        return xy * scale, None, float(scale)
    box = DEFAULT_SIZE if size is None else size
    factor = float(min(box[0] / width, box[1] / height))
    check_extent(width * factor, height * factor, f"{path} fitted into --size", settings)
    return xy * factor, list(box), factor


def _check_unfolded(xy: np.ndarray, faces: np.ndarray, path: Path, settings: Settings) -> None:
    """ValueError when a triangle is upside down or edge-on in plan: a folded form whose
    faces overlap in plan, which cannot be lifted onto a surface z = f(x, y)."""
    area = geometry.plan_face_areas(xy, faces)
    longest = float(np.ptp(xy, axis=0).max())
    bad = np.flatnonzero(area <= settings.geometry.degenerate_area * longest**2)
    if bad.size:
        f = int(bad[0])
        how = "upside down (the sheet overlaps itself)" if area[f] < 0 else "vertical (edge-on)"
        raise RigidfoldError(
            f"{path}: face {f} {tuple(faces[f].tolist())} is {how} in plan: a folded form "
            "cannot be lifted onto a surface z = f(x, y); give its crease pattern"
        )
