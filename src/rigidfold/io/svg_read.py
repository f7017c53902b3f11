"""Reading crease patterns drawn as SVG in Origami Simulator's colour convention.

Origami Simulator (https://origamisimulator.org, ``js/pattern.js``) reads a crease pattern
from the stroke colours of an SVG drawing: black boundary, red mountain, blue valley, yellow
flat facet lines, magenta undriven creases, green cuts, and a crease's stroke opacity as the
fraction of 180 degrees it folds. :func:`read_svg` reads such a drawing into its planar
faces, in the drawing's own coordinates (user units, y flipped to point up), in four steps,
a module each:

* the XML is walked once without recursion (:mod:`rigidfold.io.svg_xml`): elements nested
  deeper than ``Settings.limits.max_svg_depth``, an ``<svg>`` ``width`` or ``height`` that is
  not a positive finite length, a ``viewBox`` that is not four finite numbers with a positive
  size, and a ``transform`` that is not transform functions of finite numbers are refused
  before svgelements sees them (it would fail with a RecursionError, ZeroDivisionError or
  IndexError);
* the lines drawn (:mod:`rigidfold.io.svg_lines`; svgelements parses the file: transforms,
  ``viewBox``, ``<use>``, styles): every ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>``
  and ``<path>`` with a stroke; unstroked shapes, text and images are not drawn lines and are
  skipped. A curved piece (an arc, a Bezier curve, a circle, an ellipse, a rounded rect) is
  refused. Colours by hue (:data:`rigidfold.io.svg_lines.COLOURS`), so ``#FF0000``, ``#f00``,
  ``rgb(255,0,0)`` and ``red`` are all mountains; green cuts are refused;
* their planar arrangement (:mod:`rigidfold.io.svg_planar`): lines are split where they
  cross (a crossing near an end too; lines along one line do not cross) or where one ends
  on another, points closer than ``Settings.inputs.svg_merge_tol`` times the drawing's
  bounding-box diagonal are merged (the ends of the lines drawn before the crossings are
  found, as Origami Simulator does, so that lines drawn to one point from ends that miss it
  slightly meet there), and pieces shorter than that are dropped. A piece drawn twice is
  kept once: if one drawing is black it stays boundary; one drawn in two crease colours is a
  slip when it is no longer than ``Settings.inputs.svg_snap_tol`` times the diagonal (lines
  drawn to one point that miss it, or one crease running on along another), and its ends
  become one vertex, and is refused when it is longer. Where just two pieces of the same
  colour and opacity meet in a straight line, they become one line. Pieces of one colour
  and opacity drawn over each other along one line are made one before they are split (a
  line drawn back and forth many times costs no more than once), and a drawing with more
  than ``Settings.limits.max_svg_pairs`` pairs of pieces that meet or cross is refused.
  Slips of the pen up to ``Settings.inputs.svg_snap_tol`` times the diagonal are mended
  where a line would otherwise end on nothing (:mod:`rigidfold.io.svg_mend`): the boundary
  first (a black piece past a corner, or drawn over a crease inside the sheet, is dropped,
  the crease stays, and a gap between two ends of the boundary is closed halfway), then the
  creases (an overshoot past the line a crease crosses, the boundary among them, is cut off,
  and a crease that ends short of a line is extended to it), and the drawing is arranged
  again;
* its boundary and faces (:mod:`rigidfold.io.svg_faces`): the black lines must form one
  closed outline (in a drawing without black lines, the outline of the lines drawn is the
  boundary, as Origami Simulator takes it), every crease must lie inside it and end on
  another line, and every face must be a simple polygon (no holes, no crease loop hanging
  at one point).

Each problem is a one-line ``ValueError`` (:class:`rigidfold.errors.RigidfoldError`) naming
the file.

Units: when the root ``<svg>`` gives its ``width`` in mm, cm, in or pt, :attr:`SvgDrawing.unit`
is that unit and :attr:`SvgDrawing.scale` the metres per user unit (the width over the
``viewBox`` width, or one CSS pixel, 1/96 in, without a ``viewBox``); a width in px or none
is ``"unit"``, scale 1.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path

import numpy as np
import svgelements as se

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.svg_faces import (
    check_boundary,
    check_creases,
    inside_boundary,
    outline_as_boundary,
    simple_faces,
)
from rigidfold.io.svg_lines import SVGELEMENTS_ERRORS, cannot_read, drawing_units, drawn_lines
from rigidfold.io.svg_mend import MENDS, mend
from rigidfold.io.svg_planar import compact, join_straight, node
from rigidfold.io.svg_xml import check_xml


@dataclass(frozen=True, eq=False)
class SvgDrawing:
    """A crease pattern drawn in SVG, read into its planar faces.

    Attributes
    ----------
    xy : (V, 2) float64
        Vertex positions in drawing (user) units, y up (SVG's y negated), not translated.
    polygons : list of F lists of int
        The faces (regions bounded by the lines inside the boundary), each counter-clockwise
        seen from +z, at least 3 vertices, none repeated; every consecutive pair is an edge.
    edges : (E, 2) int64
        Every line piece after splitting at intersections and merging vertices.
    assignment : list of E str
        ``"B"`` boundary (black), ``"M"`` mountain (red), ``"V"`` valley (blue), ``"F"``
        flat facet line (yellow), ``"U"`` undriven crease (magenta).
    unit : str
        ``"unit"`` when the drawing gives no physical unit, else a key of
        :data:`rigidfold.io.fold.UNITS` (``"mm"``, ``"cm"``, ``"in"``, ``"pt"``).
    scale : float
        Metres per drawing unit (1.0 for ``"unit"``).
    fold_angles : (E,) float64 or None
        Origami Simulator's target fold angles, degrees: stroke opacity times 180, valleys
        positive, mountains negative; 0 for boundary and facet lines, NaN for undriven ones.
    """

    xy: np.ndarray
    polygons: list[list[int]]
    edges: np.ndarray
    assignment: list[str]
    unit: str
    scale: float
    fold_angles: np.ndarray | None


def read_svg(path: str | os.PathLike, *, settings: Settings = DEFAULTS) -> SvgDrawing:
    """Read a crease pattern drawn in SVG (Origami Simulator's colours); see the module.

    Parameters
    ----------
    path : str or path-like
        The SVG file.
    settings : Settings
        ``svg_merge_tol``: points closer than this times the bounding-box diagonal of all
        lines are one vertex; ``svg_snap_tol``, ``max_svg_depth``, ``max_svg_pairs``.

    Raises
    ------
    ValueError
        One line naming the file: unreadable, not an SVG, elements nested deeper than
        ``settings.limits.max_svg_depth``, a ``width``, ``height``, ``viewBox`` or ``transform``
        that is not finite numbers (or scales the drawing to nothing), no lines, a curve, an
        unknown or a cut (green) colour, more than ``settings.limits.max_svg_pairs`` pairs of
        pieces that meet or cross, no boundary, a boundary that is not one closed
        outline (open, branching, several pieces, holes), creases outside the boundary, a
        crease ending inside a face, a face that is not a simple polygon.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise RigidfoldError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        check_xml(data, settings)
    except ElementTree.ParseError as exc:
        raise RigidfoldError(f"not an SVG file: {path}: {exc}") from None
    except ValueError as exc:
        raise RigidfoldError(f"{path}: {exc}") from None
    try:
        svg = se.SVG.parse(BytesIO(data))
    except (ElementTree.ParseError, ValueError) as exc:
        raise RigidfoldError(f"not an SVG file: {path}: {exc}") from None
    except SVGELEMENTS_ERRORS as exc:
        raise RigidfoldError(f"{path}: {cannot_read(exc)}") from None
    if not isinstance(svg, se.SVG):
        raise RigidfoldError(f"not an SVG file: {path}: the root element is not <svg>")
    try:
        return _read(svg, settings)
    except ValueError as exc:
        raise RigidfoldError(f"{path}: {exc}") from None


def _read(svg: se.SVG, settings: Settings) -> SvgDrawing:
    unit, scale, to_user = drawing_units(svg)
    ends, letters, angles = drawn_lines(svg, to_user)
    across = float(np.linalg.norm(np.ptp(ends.reshape(-1, 2), axis=0)))
    tol, snap = settings.inputs.svg_merge_tol * across, settings.inputs.svg_snap_tol * across
    drawn = (ends, letters, angles)
    pieces: tuple[np.ndarray, list[str], list[float]] | None = drawn
    for _ in range(MENDS):
        if pieces is None:
            break
        xy, edges, letters, angles = node(*pieces, tol, snap, settings.limits.max_svg_pairs)
        xy, edges, letters, angles = join_straight(xy, edges, letters, angles, tol)
        pieces = mend(xy, edges, letters, angles, snap, tol, drawn)
    if "B" not in drawn[1]:
        letters, angles = outline_as_boundary(xy, edges, letters, angles)
        xy, edges, letters, angles = join_straight(xy, edges, letters, angles, tol)
    boundary = check_boundary(xy, edges, letters, snap)
    inside = inside_boundary(xy, edges, boundary, letters, snap)
    if not inside.all():
        xy, edges = compact(xy, edges[inside])
        letters = [a for a, k in zip(letters, inside, strict=True) if k]
        angles = [a for a, k in zip(angles, inside, strict=True) if k]
        xy, edges, letters, angles = join_straight(xy, edges, letters, angles, tol)
        boundary = check_boundary(xy, edges, letters, snap)
    check_creases(xy, edges, letters, boundary, max(tol, snap))
    return SvgDrawing(
        xy=xy,
        polygons=simple_faces(xy, edges),
        edges=edges,
        assignment=letters,
        unit=unit,
        scale=scale,
        fold_angles=np.array(angles),
    )
