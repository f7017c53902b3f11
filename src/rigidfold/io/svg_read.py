"""Reading crease patterns drawn as SVG in Origami Simulator's colour convention.

Origami Simulator (https://origamisimulator.org, ``js/pattern.js``) reads a crease pattern
from the stroke colours of an SVG drawing: black boundary, red mountain, blue valley, yellow
flat facet lines, magenta undriven creases, green cuts, and a crease's stroke opacity as the
fraction of 180 degrees it folds. :func:`read_svg` reads such a drawing into its planar
faces, in the drawing's own coordinates (user units, y flipped to point up).

What is read (svgelements parses the file: transforms, ``viewBox``, ``<use>``, styles), once
the XML has been walked without recursion: elements nested deeper than
``Settings.limits.max_svg_depth``, an ``<svg>`` ``width`` or ``height`` that is not a positive
finite length, a ``viewBox`` that is not four finite numbers with a positive size, and a
``transform`` that is not transform functions of finite numbers are refused before
svgelements sees them (it would fail with a RecursionError, ZeroDivisionError or IndexError):

* every ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>`` and ``<path>`` with a stroke;
  unstroked shapes, text and images are not drawn lines and are skipped. A curved piece
  (an arc, a Bezier curve, a circle, an ellipse, a rounded rect) is refused;
* colours by hue (:data:`COLOURS`), so ``#FF0000``, ``#f00``, ``rgb(255,0,0)`` and ``red``
  are all mountains; green cuts are refused;
* lines are split where they cross (a crossing near an end too; lines along one line do
  not cross) or where one ends on another, points closer than
  ``Settings.inputs.svg_merge_tol`` times the drawing's bounding-box diagonal are merged (the
  ends of the lines drawn before the crossings are found, as Origami Simulator does, so that
  lines drawn to one point from ends that miss it slightly meet there), and pieces shorter
  than that are dropped. A piece drawn twice is kept once: if one drawing
  is black it stays boundary; one drawn in two crease colours is a slip when it is no
  longer than ``Settings.inputs.svg_snap_tol`` times the diagonal (lines drawn to one point
  that miss it, or one crease running on along another), and its ends become one vertex,
  and is refused when it is longer. Where just two pieces
  of the same colour and opacity meet in a straight line, they become one line. Pieces of
  one colour and opacity drawn over each other along one line are made one before they are
  split (a line drawn back and forth many times costs no more than once), and a drawing
  with more than ``Settings.limits.max_svg_pairs`` pairs of pieces that meet or cross is refused;
* slips of the pen up to ``Settings.inputs.svg_snap_tol`` times the diagonal are mended where a
  line would otherwise end on nothing. The boundary first (:func:`_close_boundary`): a black
  piece past a corner, or drawn over a crease inside the sheet, is dropped (the crease
  stays), and a gap between two ends of the boundary is closed halfway. Then the creases
  (:func:`_mend`): an overshoot past the line a crease crosses (the boundary among them) is
  cut off, and a crease that ends short of a line is extended to it;
* the black lines must form one closed outline (in a drawing without black lines, the
  outline of the lines drawn is the boundary, as Origami Simulator takes it), every crease
  must lie inside it and end
  on another line, and every face must be a simple polygon (no holes, no crease loop
  hanging at one point). Each problem is a one-line ``ValueError`` naming the file.

Units: when the root ``<svg>`` gives its ``width`` in mm, cm, in or pt, :attr:`SvgDrawing.unit`
is that unit and :attr:`SvgDrawing.scale` the metres per user unit (the width over the
``viewBox`` width, or one CSS pixel, 1/96 in, without a ``viewBox``); a width in px or none
is ``"unit"``, scale 1.
"""

from __future__ import annotations

import colorsys
import contextlib
import math
import os
import re
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path

import numpy as np
import shapely
import svgelements as se
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.fold import UNITS

OS_STROKES = {
    "B": ("black", "#000000"),
    "M": ("red", "#ff0000"),
    "V": ("blue", "#0000ff"),
    "F": ("yellow", "#ffff00"),
    "U": ("magenta", "#ff00ff"),
    "C": ("green", "#00ff00"),
}
"""Origami Simulator's stroke colours by FOLD letter, (name, hex): boundary, mountain,
valley, facet (flat) crease, undriven crease, cut. The one table of the convention: read by
:func:`read_svg` (by hue) and written by the cut sheets (:mod:`rigidfold.exports.cutsheet`)."""

COLOURS = {letter: name for letter, (name, _) in OS_STROKES.items()}
"""Origami Simulator's stroke colours by FOLD letter. A stroke whose brightest channel is
below 25 % is black; one with saturation and brightness of at least 50 % whose hue is less
than :data:`HUE_TOLERANCE` degrees from red (0), yellow (60), green (120), blue (240) or
magenta (300) is that colour; any other stroke is refused."""

HUE_TOLERANCE = 30.0
"""Largest hue difference (degrees) of a stroke from its colour in :data:`COLOURS`."""

_MENDS = 4
"""How many times the slips of a drawing are mended (:func:`_mend`) and the drawing noded
again, at most: the boundary is closed first, and cutting off an overshoot can leave another
loose end."""

_LARGEST = 1e150
"""Largest extent of a drawing in its own units: squares of its lengths stay finite."""

_HUES = {
    letter: 360.0 * colorsys.rgb_to_hsv(*(int(hex_[k : k + 2], 16) / 255 for k in (1, 3, 5)))[0]
    for letter, (_, hex_) in OS_STROKES.items()
    if letter != "B"
}
"""The hue (degrees) of each colour of :data:`OS_STROKES` but black."""
_SHAPES = (se.SimpleLine, se.Polyline, se.Polygon, se.Rect, se.Path, se.Circle, se.Ellipse)


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
        _check_xml(data, settings)
    except ElementTree.ParseError as exc:
        raise RigidfoldError(f"not an SVG file: {path}: {exc}") from None
    except ValueError as exc:
        raise RigidfoldError(f"{path}: {exc}") from None
    try:
        svg = se.SVG.parse(BytesIO(data))
    except (ElementTree.ParseError, ValueError) as exc:
        raise RigidfoldError(f"not an SVG file: {path}: {exc}") from None
    except _SVGELEMENTS_ERRORS as exc:
        raise RigidfoldError(f"{path}: {_cannot_read(exc)}") from None
    if not isinstance(svg, se.SVG):
        raise RigidfoldError(f"not an SVG file: {path}: the root element is not <svg>")
    try:
        return _read(svg, settings)
    except ValueError as exc:
        raise RigidfoldError(f"{path}: {exc}") from None


def _read(svg: se.SVG, settings: Settings) -> SvgDrawing:
    unit, scale, to_user = _units(svg)
    ends, letters, angles = _lines(svg, to_user)
    across = float(np.linalg.norm(np.ptp(ends.reshape(-1, 2), axis=0)))
    tol, snap = settings.inputs.svg_merge_tol * across, settings.inputs.svg_snap_tol * across
    drawn = (ends, letters, angles)
    pieces: tuple[np.ndarray, list[str], list[float]] | None = drawn
    for _ in range(_MENDS):
        if pieces is None:
            break
        xy, edges, letters, angles = _node(*pieces, tol, snap, settings.limits.max_svg_pairs)
        xy, edges, letters, angles = _join_straight(xy, edges, letters, angles, tol)
        pieces = _mend(xy, edges, letters, angles, snap, tol, drawn)
    if "B" not in drawn[1]:
        letters, angles = _outline(xy, edges, letters, angles)
        xy, edges, letters, angles = _join_straight(xy, edges, letters, angles, tol)
    boundary = _check_boundary(xy, edges, letters, snap)
    inside = _inside(xy, edges, boundary, letters, snap)
    if not inside.all():
        xy, edges = _compact(xy, edges[inside])
        letters = [a for a, k in zip(letters, inside, strict=True) if k]
        angles = [a for a, k in zip(angles, inside, strict=True) if k]
        xy, edges, letters, angles = _join_straight(xy, edges, letters, angles, tol)
        boundary = _check_boundary(xy, edges, letters, snap)
    _check_creases(xy, edges, letters, boundary, max(tol, snap))
    return SvgDrawing(
        xy=xy,
        polygons=_faces(xy, edges),
        edges=edges,
        assignment=letters,
        unit=unit,
        scale=scale,
        fold_angles=np.array(angles),
    )


# ------------------------------------------------------------------------- the XML
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_LENGTH = re.compile(rf"\s*({_NUMBER})\s*([A-Za-z%]*)\s*")
_SEPARATORS = re.compile(r"[\s,]+")
_TRANSFORM_NUMBERS = {
    "matrix": (6,),
    "translate": (1, 2),
    "translatex": (1,),
    "translatey": (1,),
    "scale": (1, 2),
    "scalex": (1,),
    "scaley": (1,),
    "rotate": (1, 3),
    "skew": (1, 2),
    "skewx": (1,),
    "skewy": (1,),
}
"""How many numbers each transform function of svgelements takes."""


def _check_xml(data: bytes, settings: Settings) -> None:
    """Walk the XML once before svgelements reads it, without recursion: ValueError for
    elements nested deeper than ``settings.limits.max_svg_depth``, for the attributes svgelements
    would fail on with a ZeroDivisionError, IndexError or TypeError
    (:func:`_check_attributes`), and for a drawing larger than ``settings.limits.max_svg_size``
    once its ``<use>`` elements are expanded (:func:`_expanded_size`: a loop of them is
    named); ``ElementTree.ParseError`` for text that is not XML."""
    parser: ElementTree.XMLPullParser = ElementTree.XMLPullParser(events=("start", "end"))
    # per open element: [its size and its children's, {id: <use>s of it}]
    # (Settings.limits.max_svg_size)
    stack: list[list] = [[0, {}]]
    found: dict[str, list[tuple[int, dict[str, int]]]] = {}
    step = 1 << 16
    for start in range(0, len(data) + 1, step):
        if start < len(data):
            parser.feed(data[start : start + step])
        else:
            parser.close()
        for event in parser.read_events():
            kind, element = event[0], event[-1]
            if not isinstance(element, ElementTree.Element):
                continue  # only "start" and "end" events are asked for
            if kind == "end":
                size, uses = stack.pop()
                key = element.get("id")
                if key is not None:
                    found.setdefault(key, []).append((size, uses))
                parent = stack[-1]
                parent[0] += size
                for target, count in uses.items():
                    parent[1][target] = parent[1].get(target, 0) + count
                element.clear()
                continue
            if len(stack) > settings.limits.max_svg_depth:
                raise RigidfoldError(
                    f"its elements nest more than {settings.limits.max_svg_depth} levels deep (at "
                    f"<{_local(element.tag)}>; Settings.limits.max_svg_depth)"
                )
            _check_attributes(element)
            size = ELEMENT_SIZE + sum(len(value) for value in element.attrib.values())
            used: dict[str, int] = {}
            if _local(element.tag) == "use":
                target = element.get(_XLINK_HREF, element.get("href", ""))
                if target.startswith("#"):
                    used[target[1:]] = 1
            stack.append([size, used])
    size, uses = stack[0]
    total = _expanded_size(size, uses, found, settings.limits.max_svg_size)
    if total > settings.limits.max_svg_size:
        raise RigidfoldError(
            f"its elements are larger than {settings.limits.max_svg_size} characters of attributes "
            f"and {ELEMENT_SIZE} per element, each <use> counted as what it refers to "
            "(Settings.limits.max_svg_size)"
        )


ELEMENT_SIZE = 100
"""What one element adds to the size of a drawing besides its attributes' characters
(``Settings.limits.max_svg_size``): svgelements takes about as long to read an element as to read
a hundred characters of path data."""
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"


def _expanded_size(
    size: int,
    uses: dict[str, int],
    found: dict[str, list[tuple[int, dict[str, int]]]],
    limit: int,
) -> int:
    """``size`` plus what the ``<use>`` elements counted in ``uses`` ({id: how many}) refer
    to, each element with an id in ``found`` ([(its size, its uses)], the largest if several
    share the id) expanded likewise, without recursion; at most ``limit + 1`` (it stops
    there). ValueError naming an id whose element uses itself, directly or not."""
    cap = limit + 1
    sizes: dict[str, int] = {}
    for first in uses:
        todo, open_ = [first], {first}
        while todo:
            key = todo[-1]
            if key in sizes or key not in found:
                sizes.setdefault(key, 0)  # an unknown id draws nothing
                todo.pop()
                open_.discard(key)
                continue
            waiting = [t for _, inner in found[key] for t in inner if t not in sizes or t in open_]
            loop = [t for t in waiting if t in open_]
            if loop:
                raise RigidfoldError(
                    f'its <use> elements refer to each other in a loop (through id="{loop[0]}")'
                )
            if waiting:
                todo += waiting
                open_.update(waiting)
                continue
            sizes[key] = max(
                min(cap, own + sum(count * sizes[t] for t, count in inner.items()))
                for own, inner in found[key]
            )
            todo.pop()
            open_.discard(key)
    return min(cap, size + sum(count * sizes[t] for t, count in uses.items()))


def _check_attributes(element: ElementTree.Element) -> None:
    """ValueError naming the element and the value for a ``width`` or ``height`` of an
    ``<svg>`` that is not a positive finite length, a ``viewBox`` that is not four finite
    numbers with a positive width and height, and a ``transform`` that is not a list of
    transform functions of finite numbers."""
    tag = _local(element.tag)
    key = element.get("id")
    name = f'<{tag} id="{key}">' if key else f"<{tag}>"
    if tag == "svg":
        for size in ("width", "height"):
            text = element.get(size)
            length = None if text is None else _LENGTH.fullmatch(text)
            if text is not None and not (length and 0 < float(length[1]) < math.inf):
                raise RigidfoldError(
                    f'{name} has {size}="{text}": a {size} is a positive finite length, such '
                    "as 210mm or 800"
                )
    text = element.get("viewBox")
    if text is not None and text.strip():
        try:
            box = [float(v) for v in _SEPARATORS.split(text.strip())]
        except ValueError:
            box = []
        if not (len(box) == 4 and all(map(math.isfinite, box)) and min(box[2:]) > 0):
            raise RigidfoldError(
                f'{name} has viewBox="{text}": a viewBox is four finite numbers "min-x min-y '
                'width height", the width and height positive'
            )
    if tag == "path":
        text = element.get("d")
        if text is None or not _path_data_ok(text):
            flat = " ".join((text or "").split())  # the data's newlines and tabs as spaces
            shown = "no d" if text is None else f'd="{flat[:40]}{"..." if len(flat) > 40 else ""}"'
            raise RigidfoldError(
                f"{name} has {shown}: path data is moveto, lineto and closepath commands (M, "
                "L, H, V, Z) and numbers, starting with M"
            )
    text = element.get("transform")
    if text is not None and not _transform_ok(text):
        raise RigidfoldError(
            f'{name} has transform="{text}": a transform is a list of matrix(a,b,c,d,e,f), '
            "translate, scale, rotate, skewX or skewY of finite numbers"
        )


_PATH_TOKEN = re.compile(rf"({_NUMBER})|([A-Za-z])|[\s,]+|(.)", re.DOTALL)


def _path_data_ok(text: str) -> bool:
    """Whether svgelements reads the path data ``text`` as written: empty, or M first, then
    commands each followed by numbers (Z by none). A command without its numbers, a word in
    place of a number (``nan``) and no leading M end in its TypeError or AttributeError.
    Curves pass here and are refused later by name. Linear in the text."""
    command, numbers = "", 0
    for number, letter, other in _PATH_TOKEN.findall(text):
        if other:
            return False
        if letter:
            if letter not in "MmLlHhVvCcSsQqTtAaZz" or (not command and letter not in "Mm"):
                return False
            if command and command not in "Zz" and not numbers:
                return False
            command, numbers = letter, 0
        elif number:
            if not command or command in "Zz":
                return False
            numbers += 1
    return not command or command in "Zz" or numbers > 0


def _transform_ok(text: str) -> bool:
    """Whether svgelements reads the transform attribute ``text`` as written: only transform
    functions, each with as many finite numbers as it takes (``"none"`` is none)."""
    text = text.lower()
    if text.strip() in ("", "none"):
        return True
    if _SEPARATORS.sub("", se.REGEX_TRANSFORM_TEMPLATE.sub("", text)):
        return False  # something besides the functions: unknown words, a missing bracket
    for function, arguments in se.REGEX_TRANSFORM_TEMPLATE.findall(text):
        numbers = [float(v) for v, _ in se.REGEX_TRANSFORM_PARAMETER.findall(arguments)]
        if _SEPARATORS.sub("", se.REGEX_TRANSFORM_PARAMETER.sub("", arguments)):
            return False  # something besides numbers: nan, inf, words
        if len(numbers) not in _TRANSFORM_NUMBERS[function]:
            return False
        if not all(map(math.isfinite, numbers)):
            return False
    return True


def _local(tag: str) -> str:
    """An XML tag without its namespace: ``{http://www.w3.org/2000/svg}g`` -> ``g``."""
    return tag.rpartition("}")[2]


_SVGELEMENTS_ERRORS = (ArithmeticError, IndexError, RecursionError, TypeError, AttributeError)
"""What svgelements raises on drawings it cannot compute with: arithmetic on degenerate or
enormous numbers, a transform or style it misreads, references in a loop, a value it has
not parsed (None) met in its arithmetic."""


def _cannot_read(exc: BaseException) -> str:
    """The message of :data:`_SVGELEMENTS_ERRORS`."""
    if isinstance(exc, RecursionError):
        hint = "do its <use> elements refer to each other in a loop?"
    elif isinstance(exc, TypeError | AttributeError):
        hint = "check the path data, points and coordinates of its shapes"
    else:
        hint = "check the numbers of its width, height, viewBox and transform attributes and styles"
    return f"svgelements cannot read the drawing ({type(exc).__name__}: {exc}): {hint}"


@contextlib.contextmanager
def _svgelements():
    """Turn :data:`_SVGELEMENTS_ERRORS` into a one-line ValueError."""
    try:
        yield
    except _SVGELEMENTS_ERRORS as exc:
        raise RigidfoldError(_cannot_read(exc)) from None


# ------------------------------------------------------------------------- the drawing
def _units(svg: se.SVG) -> tuple[str, float, se.Matrix]:
    """(unit, metres per user unit, matrix from svgelements' pixels to user units)."""
    to_user = _to_user(svg)
    width = str(svg.values.get("width", ""))
    match = re.fullmatch(r"\s*(\+?[\d.]+(?:[eE][-+]?\d+)?)\s*(mm|cm|in|pt)\s*", width)
    if match is None or not svg.width > 0:
        return "unit", 1.0, to_user
    unit = match.group(2)
    if not svg.viewbox_transform:
        return unit, UNITS["in"] / 96, to_user  # a user unit is a CSS pixel
    px_x, px_y = abs(1 / to_user.a), abs(1 / to_user.d)  # pixels per user unit
    if not math.isclose(px_x, px_y, rel_tol=1e-9):
        raise RigidfoldError("the width, height and viewBox scale x and y differently")
    return unit, px_x * float(match.group(1)) * UNITS[unit] / svg.width, to_user


def _to_user(svg: se.SVG) -> se.Matrix:
    """The inverse of the root's viewBox transform (a scale and a translation), computed
    without the determinant (whose square of the scale underflows or overflows first);
    ValueError when the scale is not a finite nonzero number or its inverse overflows."""
    with _svgelements():
        transform = svg.viewbox_transform
    if not transform:
        return se.Matrix()
    m = se.Matrix(transform)
    with np.errstate(all="ignore"):
        a, d = np.float64(1.0) / m.a, np.float64(1.0) / m.d
        inverse = [a, 0.0, 0.0, d, -m.e * a, -m.f * d]
    if m.b or m.c or not np.isfinite([m.a, m.d, m.e, m.f, *inverse]).all() or 0 in (a, d):
        raise RigidfoldError(
            f'the viewBox="{svg.values.get("viewBox")}" scales the drawing to its width="'
            f'{svg.values.get("width")}" and height="{svg.values.get("height")}" by '
            f"{m.a:.3g} x {m.d:.3g}, which cannot be computed with"
        )
    return se.Matrix(*map(float, inverse))


def _lines(svg: se.SVG, to_user: se.Matrix) -> tuple[np.ndarray, list[str], list[float]]:
    """Every straight piece drawn: ends (n, 2, 2) in user units y up, letters, fold angles."""
    ends, letters, angles = [], [], []
    with _svgelements():
        shapes = [e for e in svg.elements() if isinstance(e, _SHAPES)]
    for k, shape in enumerate(shapes, start=1):
        tag = shape.values.get("tag", type(shape).__name__.lower())
        name = f'<{tag} id="{shape.id}">' if shape.id else f"<{tag}> (drawn element {k})"
        if shape.stroke is None or shape.stroke.value is None:
            continue
        letter = _letter(shape.stroke, shape.values.get("stroke"), name)
        opacity = _opacity(shape, name)
        angle = {"M": -180.0 * opacity, "V": 180.0 * opacity, "U": math.nan}.get(letter, 0.0)
        m = shape.transform
        if not np.isfinite([m.a, m.b, m.c, m.d, m.e, m.f]).all():
            raise RigidfoldError(
                f"{name} is drawn with a transform that is not finite, matrix({m.a:g}, {m.b:g}, "
                f"{m.c:g}, {m.d:g}, {m.e:g}, {m.f:g}) (its transforms and the viewBox multiplied)"
            )
        with _svgelements():
            pieces = list(se.Path(shape).segments())
        for piece in pieces:
            if isinstance(piece, se.Move):
                continue
            if not isinstance(piece, se.Line | se.Close):
                raise RigidfoldError(
                    f"{name} has a curved piece ({type(piece).__name__}): creases and the "
                    "boundary must be straight lines"
                )
            a, b = (
                to_user.point_in_matrix_space(piece.start),
                to_user.point_in_matrix_space(piece.end),
            )
            if not np.isfinite([a.x, a.y, b.x, b.y]).all():
                raise RigidfoldError(
                    f"{name} has a line from ({a.x:g}, {a.y:g}) to ({b.x:g}, {b.y:g}): "
                    "coordinates must be finite numbers (transforms and the viewBox applied)"
                )
            ends.append([[a.x, 0.0 - a.y], [b.x, 0.0 - b.y]])
            letters.append(letter)
            angles.append(angle)
    if not ends:
        raise RigidfoldError(
            "no lines drawn: a crease pattern is <line>, <polyline>, <polygon>, <rect> or "
            "<path> elements with a stroke"
        )
    drawn = np.array(ends, dtype=float)
    with np.errstate(over="ignore"):
        across = float(np.linalg.norm(np.ptp(drawn.reshape(-1, 2), axis=0)))
    if not across <= _LARGEST:
        raise RigidfoldError(
            f"its lines span {across:.3g} drawing units (their transforms and viewBox "
            f"applied): more than {_LARGEST:g}, too large to compute with"
        )
    return drawn, letters, angles


def _opacity(shape: se.Shape, name: str) -> float:
    """Stroke opacity times opacity, in [0, 1], as written (svgelements' colour keeps 8 bits)."""
    values = shape.values
    try:
        opacity = float(values.get("stroke-opacity", shape.stroke.opacity))
        opacity *= float(values.get("opacity", 1.0))
    except ValueError:
        raise RigidfoldError(f"{name} has an opacity that is not a number") from None
    return min(max(opacity, 0.0), 1.0)


def _letter(colour: se.Color, written: str | None, name: str) -> str:
    """The FOLD letter of a stroke colour (:data:`COLOURS`); ValueError for others."""
    hue, saturation, value = colorsys.rgb_to_hsv(
        colour.red / 255, colour.green / 255, colour.blue / 255
    )
    if value < 0.25:
        return "B"
    if saturation >= 0.5 and value >= 0.5:
        for letter, centre in _HUES.items():
            if abs((360 * hue - centre + 180) % 360 - 180) < HUE_TOLERANCE:
                if letter == "C":
                    raise RigidfoldError(f"{name} is green, a cut: cuts are not supported")
                return letter
    shown = colour.hex[:7]
    if written and written.strip().lower() != shown:
        shown = f"{written.strip()} ({shown})"
    raise RigidfoldError(
        f"{name} has stroke colour {shown}, none of Origami Simulator's: black boundary, red "
        "mountain, blue valley, yellow flat, magenta undriven"
    )


# ------------------------------------------------------------------------- the geometry
def _node(
    ends: np.ndarray,
    letters: list[str],
    angles: list[float],
    tol: float,
    snap: float = 0.0,
    max_pairs: int = DEFAULTS.limits.max_svg_pairs,
) -> tuple[np.ndarray, np.ndarray, list[str], list[float]]:
    """The drawn pieces split where they meet, close points merged, repeats dropped.

    ends : (n, 2, 2) float; letters, angles : n each; tol : merge distance; snap : a piece
    no longer than this drawn in two crease colours (the ends of lines drawn to one point
    that miss it by more than ``tol``, or a crease that overshoots its end along another) is
    contracted, its ends made one vertex (:func:`_pieces`), instead of refused;
    max_pairs : ``Settings.limits.max_svg_pairs`` (:func:`_splits`). Pieces of one colour and
    angle drawn over each other along one line are first made one (:func:`_merge_overlaps`),
    so that a line drawn back and forth many times costs no more than once.
    Returns xy (V, 2), edges (E, 2) int64 (in drawing order), their letters and angles.
    """
    ends, letters, angles = _merge_overlaps(ends, letters, angles, tol)
    ends = _merge_ends(ends, tol)
    a, b = ends[:, 0], ends[:, 1]
    length = np.linalg.norm(b - a, axis=1)
    drawn = np.flatnonzero(length > tol)
    if not len(drawn):
        raise RigidfoldError("the lines drawn have no length")
    a, b, length = a[drawn], b[drawn], length[drawn]
    seg, t, points, near = _splits(a, b, length, tol, max_pairs)
    n = len(drawn)
    seg = np.concatenate([np.arange(n), np.arange(n), seg])
    t = np.concatenate([np.zeros(n), np.ones(n), t])
    points = np.concatenate([a, b, points])
    near = np.concatenate([np.zeros(2 * n, dtype=bool), near])
    order = np.lexsort((t, seg))
    seg, points, near = seg[order], points[order], near[order]
    distinct, same = np.unique(points, axis=0, return_inverse=True)  # ends drawn again
    pairs = cKDTree(distinct).query_pairs(tol, output_type="ndarray")
    vertex = connected_components(_graph(pairs, len(distinct)), directed=False)[1]
    vertex = vertex[same.reshape(-1)]
    piece = np.flatnonzero(seg[:-1] == seg[1:])
    source = drawn[seg[piece]]
    while True:
        # each merged vertex at its first point (a crossing near an end only if it has no
        # other); a piece drawn in two crease colours (a slip) contracted, until none is left
        rank = np.lexsort((near, vertex))
        first = rank[np.unique(vertex[rank], return_index=True)[1]]
        xy = points[first]
        edges, out_letters, out_angles, twice = _pieces(
            vertex[piece], vertex[piece + 1], source, letters, angles, xy, snap
        )
        if not len(twice):
            break
        vertex = connected_components(_graph(twice, len(xy)), directed=False)[1][vertex]
    return (*_compact(xy, edges), out_letters, out_angles)


def _pieces(
    tail: np.ndarray,
    head: np.ndarray,
    source: np.ndarray,
    letters: list[str],
    angles: list[float],
    xy: np.ndarray,
    snap: float,
) -> tuple[np.ndarray, list[str], list[float], np.ndarray]:
    """The edges of the pieces from vertex ``tail`` to ``head`` (k each), drawn as piece
    ``source`` (k,) of ``letters`` and ``angles``, each edge once: one drawn black stays
    boundary, one drawn in two crease colours no longer than ``snap`` (the ends of lines
    drawn to one point that miss it, or a crease that runs on along another) is returned
    among the vertex pairs to contract, a longer one is refused. Returns edges (E, 2) int64,
    their letters and angles, and the pairs (m, 2) to contract."""
    kept: dict[tuple[int, int], int] = {}
    edges: list[tuple[int, int]] = []
    twice: set[int] = set()
    out_letters, out_angles = [], []
    for u, v, k in zip(tail.tolist(), head.tolist(), source.tolist(), strict=True):
        letter, key = letters[k], (min(u, v), max(u, v))
        if u == v:
            continue
        if key not in kept:
            kept[key] = len(edges)
            edges.append((u, v))
            out_letters.append(letter)
            out_angles.append(angles[k])
            continue
        e = kept[key]
        if letter == "B":
            out_letters[e], out_angles[e] = "B", 0.0
            twice.discard(e)
        elif out_letters[e] not in ("B", letter):
            if np.linalg.norm(xy[u] - xy[v]) > snap:
                raise RigidfoldError(
                    f"the line from {_at(xy[u])} to {_at(xy[v])} is "
                    f"drawn both {COLOURS[out_letters[e]]} and {COLOURS[letter]}"
                )
            twice.add(e)
    pairs = np.array(edges, dtype=np.int64).reshape(-1, 2)
    return pairs, out_letters, out_angles, pairs[sorted(twice)]


def _merge_ends(ends: np.ndarray, tol: float) -> np.ndarray:
    """The pieces' ends closer than ``tol`` to each other (or linked by such ends) moved onto
    one point, the first of them drawn, before the pieces are split where they cross: lines
    drawn to one point from ends that miss each other by less than ``tol`` then meet there,
    and do not cross each other near it, as Origami Simulator merges points before it looks
    for intersections. ends (n, 2, 2) -> the same, with the ends moved."""
    points = ends.reshape(-1, 2)
    distinct, same = np.unique(points, axis=0, return_inverse=True)
    pairs = cKDTree(distinct).query_pairs(tol, output_type="ndarray")
    if not len(pairs):
        return ends
    label = connected_components(_graph(pairs, len(distinct)), directed=False)[1]
    label = label[same.reshape(-1)]
    first = np.full(label.max() + 1, len(points))
    np.minimum.at(first, label, np.arange(len(points)))
    return points[first[label]].reshape(ends.shape)


def _merge_overlaps(
    ends: np.ndarray, letters: list[str], angles: list[float], tol: float
) -> tuple[np.ndarray, list[str], list[float]]:
    """Pieces of one letter and angle that lie along one line (both ends within ``tol`` of
    the longest one's line) and overlap by more than ``tol`` made one piece, from the
    farthest end of them to the other, in the place of the first one drawn; the other
    pieces as drawn. What :func:`_node` makes of the drawing is the same (the ends inside a
    merged piece would be vertices on a straight line of one letter, which
    :func:`_join_straight` removes), without the pairs of :func:`_splits` that grow with the
    square of the number of pieces drawn over each other.

    Candidates are grouped by letter, angle, direction (bins of ``tol`` over the extent of
    the drawing) and distance of their line from the origin (bins of ``tol``), so the work
    is near-linear in the number of pieces; pieces that fall into neighbouring bins are
    left to :func:`_splits`. ends (n, 2, 2) -> ends (m, 2, 2), letters, angles, m <= n.
    """
    n = len(ends)
    if n < 2 or not tol > 0:
        return ends, letters, angles
    a, b = ends[:, 0], ends[:, 1]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    flip = (d[:, 0] < 0) | ((d[:, 0] == 0) & (d[:, 1] < 0))
    d[flip] *= -1
    across = float(np.linalg.norm(np.ptp(ends.reshape(-1, 2), axis=0)))
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / length[:, None]
        direction = np.floor(np.arctan2(u[:, 1], u[:, 0]) * across / tol)
        offset = np.floor(_cross(u, a) / tol)
    groups: dict[tuple, list[int]] = {}
    for k in np.flatnonzero(length > tol).tolist():
        angle = angles[k]
        key = (letters[k], "nan" if math.isnan(angle) else angle, direction[k], offset[k])
        groups.setdefault(key, []).append(k)
    merged: dict[int, np.ndarray] = {}  # first piece of a run -> its ends
    gone = np.zeros(n, dtype=bool)
    for members in groups.values():
        if len(members) < 2:
            continue
        ref = members[int(np.argmax(length[members]))]
        start, axis = a[ref], u[ref]
        on = np.array(members)
        off = np.abs(_cross(axis, np.stack([a[on], b[on]], axis=1) - start))  # (m, 2)
        on = on[(off <= tol).all(axis=1)]
        s = np.stack([(a[on] - start) @ axis, (b[on] - start) @ axis], axis=1)  # (m, 2)
        low, high = s.min(axis=1), s.max(axis=1)
        order = np.argsort(low, kind="stable").tolist()
        run, top = [order[0]], order[0]  # a run of overlapping pieces, the one reaching farthest
        for m in [*order[1:], None]:
            if m is not None and low[m] < high[top] - tol:
                run.append(m)
                top = m if high[m] > high[top] else top
                continue
            if len(run) > 1:
                bottom = run[0]  # sorted by low
                lo = ends[on[bottom], int(s[bottom, 1] < s[bottom, 0])]
                hi = ends[on[top], int(s[top, 1] > s[top, 0])]
                gone[on[run]] = True
                merged[int(on[run].min())] = np.array([lo, hi])
            if m is not None:
                run, top = [m], m
    if not merged:
        return ends, letters, angles
    ends = ends.copy()
    for k, piece in merged.items():
        gone[k] = False
        ends[k] = piece
    keep = np.flatnonzero(~gone)
    return ends[keep], [letters[k] for k in keep], [angles[k] for k in keep]


def _splits(
    a: np.ndarray,
    b: np.ndarray,
    length: np.ndarray,
    tol: float,
    max_pairs: int = DEFAULTS.limits.max_svg_pairs,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Where pieces must be split: where an end of another piece lies within ``tol`` of
    their interior (a T-junction: split at the foot of the perpendicular from that end) and
    where two pieces cross.

    Two pieces cross where each has its ends on both sides of the other's line, one of them
    farther than ``tol`` from it: pieces along one line (within ``tol``) do not cross, since
    the crossing of their lines is round-off (they meet at T-junctions instead). A crossing
    within ``tol`` of an end of either piece is a split too (lines drawn to one point from
    ends that miss each other, crossing each other on the way): merged with the ends near
    it, it makes them one vertex.

    a, b : (n, 2) float, the pieces' ends; length : (n,) float, all > tol.
    Returns the piece index (k,), the parameter along it (k,), the point (k, 2), and (k,)
    bool: True for a crossing within ``tol`` of an end.
    ValueError when more than ``max_pairs`` pairs of pieces come within ``tol`` of each
    other (``Settings.limits.max_svg_pairs``), counted in batches before the pairs are examined.
    """
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    tree = shapely.STRtree(lines)
    found, pairs, batch = [], 0, 256  # pieces per query: the pairs of a query stay small
    for first in range(0, len(lines), batch):
        i, j = tree.query(lines[first : first + batch], predicate="dwithin", distance=tol)
        i += first
        i, j = i[i < j], j[i < j]
        pairs += len(i)
        if pairs > max_pairs:
            raise RigidfoldError(
                f"more than {max_pairs} pairs of its {len(lines)} line pieces meet, cross or "
                "come within the merge distance of each other (Settings.limits.max_svg_pairs): too "
                "many lines cross or are drawn over each other"
            )
        found.append((i, j))
    i = np.concatenate([p[0] for p in found])
    j = np.concatenate([p[1] for p in found])
    seg, t, points, near = [], [], [], []

    def interior(s: np.ndarray, on: np.ndarray) -> np.ndarray:
        return (s * length[on] > tol) & ((1 - s) * length[on] > tol)

    chunk = 1 << 16  # pairs examined at once: the temporary arrays stay small
    for k in range(0, max(len(i), 1), chunk):  # once at least: the arrays returned
        ik, jk = i[k : k + chunk], j[k : k + chunk]
        for on, other in ((ik, jk), (jk, ik)):
            d = b[on] - a[on]
            for end in (a[other], b[other]):
                s = np.sum((end - a[on]) * d, axis=1) / length[on] ** 2
                foot = a[on] + s[:, None] * d
                hit = interior(s, on) & (np.linalg.norm(foot - end, axis=1) <= tol)
                seg.append(on[hit])
                t.append(s[hit])
                points.append(foot[hit])
                near.append(np.zeros(hit.sum(), dtype=bool))
        di, dj, r = b[ik] - a[ik], b[jk] - a[jk], a[jk] - a[ik]
        # signed distances times length: of j's ends from i's line, of i's ends from j's line
        pj = np.stack([_cross(di, r), _cross(di, r + dj)], axis=1)
        pi = np.stack([_cross(dj, -r), _cross(dj, di - r)], axis=1)
        proper = (
            (np.sign(pj[:, 0]) * np.sign(pj[:, 1]) < 0)
            & (np.sign(pi[:, 0]) * np.sign(pi[:, 1]) < 0)
            & (np.abs(pj).max(axis=1) > tol * length[ik])
            & (np.abs(pi).max(axis=1) > tol * length[jk])
        )
        denom = _cross(di, dj)
        si = np.divide(_cross(r, dj), denom, out=np.full(len(ik), np.nan), where=proper)
        sj = np.divide(_cross(r, di), denom, out=np.full(len(ik), np.nan), where=proper)
        hit = (si > 0) & (si < 1) & (sj > 0) & (sj < 1)
        crossing = a[ik][hit] + si[hit, None] * di[hit]
        end = ~(interior(si, ik) & interior(sj, jk))[hit]
        seg += [ik[hit], jk[hit]]
        t += [si[hit], sj[hit]]
        points += [crossing, crossing]
        near += [end, end]
    return (
        np.concatenate(seg),
        np.concatenate(t),
        np.concatenate(points).reshape(-1, 2),
        np.concatenate(near),
    )


def _join_straight(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], angles: list[float], tol: float
) -> tuple[np.ndarray, np.ndarray, list[str], list[float]]:
    """Vertices where just two edges of one letter and angle meet in a straight line (within
    ``tol``) removed, the two edges made one. xy (V, 2), edges (E, 2) -> the same, fewer."""
    ends = edges.tolist()
    incident: list[set[int]] = [set() for _ in xy]
    for e, (u, v) in enumerate(ends):
        incident[u].add(e)
        incident[v].add(e)
    alive = np.ones(len(ends), dtype=bool)
    for w, around in enumerate(incident):
        if len(around) != 2:
            continue
        e, f = sorted(around)
        p, q = sum(ends[e]) - w, sum(ends[f]) - w  # the other ends: p - w - q
        same = letters[e] == letters[f] and (
            angles[e] == angles[f] or (math.isnan(angles[e]) and math.isnan(angles[f]))
        )
        chord = xy[q] - xy[p]
        off = abs(_cross(chord, xy[w] - xy[p])) / np.linalg.norm(chord)
        inside = np.dot(xy[p] - xy[w], xy[q] - xy[w]) < 0
        joined = any(q in ends[g] for g in incident[p])
        if not (same and off <= tol and inside) or joined:
            continue
        ends[e] = [q if x == w else x for x in ends[e]]
        alive[f] = False
        incident[q].remove(f)
        incident[q].add(e)
        around.clear()
    keep = np.flatnonzero(alive)
    xy, edges = _compact(xy, np.array(ends, dtype=np.int64)[keep])
    return xy, edges, [letters[e] for e in keep], [angles[e] for e in keep]


def _mend(
    xy: np.ndarray,
    edges: np.ndarray,
    letters: list[str],
    angles: list[float],
    snap: float,
    tol: float = 0.0,
    drawn: tuple[np.ndarray, list[str], list[float]] | None = None,
) -> tuple[np.ndarray, list[str], list[float]] | None:
    """The drawing with its slips within ``snap`` mended, as pieces to node again (ends
    (n, 2, 2), letters, angles), or None when it has none. Gaps in the boundary are closed
    first (:func:`_close_boundary`, which needs the pieces as ``drawn`` and the merge
    distance ``tol``); when it closes any, the creases are mended on the next call. A loose
    crease end (one that touches no other line) is mended: the piece no longer than ``snap``
    that ends there (an overshoot past the line it crosses) is dropped; a longer crease is
    extended from there to the first line that it points at within ``snap``, or else to the
    nearest point within ``snap`` of a line that does not touch it.
    xy (V, 2), edges (E, 2) -> see above."""
    if drawn is not None:
        closed = _close_boundary(xy, edges, letters, angles, snap, tol, drawn)
        if closed is not None:
            return closed
    crease = np.array(letters) != "B"
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    loose = (degree[edges] == 1) & crease[:, None]  # (E, 2): a crease's loose ends
    if not loose.any():
        return None
    length = np.linalg.norm(xy[edges[:, 1]] - xy[edges[:, 0]], axis=1)
    keep = ~(loose.any(axis=1) & (length <= snap))
    edges, letters = edges[keep], [a for a, k in zip(letters, keep, strict=True) if k]
    angles = [a for a, k in zip(angles, keep, strict=True) if k]
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    e, side = np.nonzero((degree[edges] == 1) & (np.array(letters) != "B")[:, None])
    w, p = edges[e, side], edges[e, 1 - side]  # the loose end, the crease's other end
    lines = shapely.linestrings(xy[edges])
    near, other = shapely.STRtree(lines).query(
        shapely.points(xy[w]), predicate="dwithin", distance=snap
    )
    touching = (edges[other] == w[near, None]) | (edges[other] == p[near, None])
    near, other = near[~touching.any(axis=1)], other[~touching.any(axis=1)]
    pieces = [xy[edges]]
    for k in np.unique(near):
        f = other[near == k]
        a, r = xy[edges[f, 0]], xy[edges[f, 1]] - xy[edges[f, 0]]
        start = xy[w[k]]
        d = start - xy[p[k]]
        d = d / np.linalg.norm(d)
        denom = _cross(np.broadcast_to(d, r.shape), r)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(a - start, r) / denom  # along the crease's direction from its end
            t = _cross(a - start, np.broadcast_to(d, r.shape)) / denom  # along the line
        ahead = (denom != 0) & (s >= 0) & (s <= snap) & (t >= 0) & (t <= 1)
        if ahead.any():
            target = start + s[ahead].min() * d
        else:
            t = np.clip(np.sum((start - a) * r, axis=1) / np.sum(r * r, axis=1), 0, 1)
            foot = a + t[:, None] * r
            target = foot[np.argmin(np.linalg.norm(foot - start, axis=1))]
        pieces.append(np.array([[start, target]]))
        letters.append(letters[e[k]])
        angles.append(angles[e[k]])
    return np.concatenate(pieces), letters, angles


def _close_boundary(
    xy: np.ndarray,
    edges: np.ndarray,
    letters: list[str],
    angles: list[float],
    snap: float,
    tol: float,
    drawn: tuple[np.ndarray, list[str], list[float]],
) -> tuple[np.ndarray, list[str], list[float]] | None:
    """The drawing with the gaps of its boundary within ``snap`` closed, as pieces to node
    again (ends (n, 2, 2), letters, angles), or None when the boundary has no loose end (a
    vertex where just one black line ends).

    A black piece no longer than ``snap`` from a loose end to a vertex where three or more
    black lines meet (an overshoot past a corner, or a black stroke drawn over a crease
    inside the sheet) is dropped; where a crease was drawn along all of it (within ``tol``,
    ``drawn``: the pieces as drawn, ends (n, 2, 2), letters, angles), that crease stays.
    Then two loose ends within ``snap`` of each other, each the other's nearest, become one
    vertex halfway between them (the lines that end there, creases among them, move with
    it), as Origami Simulator merges points within 3 px. Other loose ends are left for
    :func:`_check_boundary` to refuse. xy (V, 2), edges (E, 2) -> see above."""
    black = np.array(letters) == "B"
    degree = np.bincount(edges[black].ravel(), minlength=len(xy))
    loose = (degree[edges] == 1) & black[:, None]  # (E, 2): the boundary's loose ends
    if not loose.any():
        return None
    length = np.linalg.norm(xy[edges[:, 1]] - xy[edges[:, 0]], axis=1)
    stub = loose.any(axis=1) & (degree[edges].max(axis=1) >= 3) & (length <= snap)
    pieces, out_letters, out_angles = [], [], []
    ends, kinds, folds = drawn
    crease = np.flatnonzero(np.array(kinds) != "B")
    lines = shapely.linestrings(ends[crease])
    for e in np.flatnonzero(stub):
        gap = shapely.distance(lines[:, None], shapely.points(xy[edges[e]])[None, :])
        along = np.flatnonzero((gap <= tol).all(axis=1))
        if len(along):
            k = int(crease[along[0]])
            pieces.append(xy[edges[e]])
            out_letters.append(kinds[k])
            out_angles.append(folds[k])
    keep = ~stub
    degree = np.bincount(edges[black & keep].ravel(), minlength=len(xy))
    free = np.flatnonzero(degree == 1)
    moved = xy.copy()
    if len(free) > 1:
        distance, nearest = cKDTree(xy[free]).query(xy[free], k=2)
        partner = nearest[:, 1]
        pair = np.flatnonzero(
            (partner[partner] == np.arange(len(free)))
            & (distance[:, 1] <= snap)
            & (np.arange(len(free)) < partner)
        )
        joined = {frozenset(e) for e in edges[black & keep].tolist()}
        for i in pair:
            u, v = int(free[i]), int(free[partner[i]])
            if frozenset((u, v)) not in joined:  # not both ends of one short black line
                moved[u] = moved[v] = (xy[u] + xy[v]) / 2
    if not stub.any() and np.array_equal(moved, xy):
        return None
    return (
        np.concatenate([moved[edges[keep]], np.reshape(pieces, (-1, 2, 2))]),
        [a for a, k in zip(letters, keep, strict=True) if k] + out_letters,
        [a for a, k in zip(angles, keep, strict=True) if k] + out_angles,
    )


def _compact(xy: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Only the vertices that edges use, numbered in order of first use.
    xy (V, 2), edges (E, 2) -> xy (V', 2), edges (E, 2)."""
    used, first = np.unique(edges.ravel(), return_index=True)
    order = used[np.argsort(first)]
    number = np.full(len(xy), -1)
    number[order] = np.arange(len(order))
    return xy[order], number[edges]


# ------------------------------------------------------------------------- the faces
def _check_boundary(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], snap: float = 0.0
) -> list[int]:
    """The black edges' one closed outline (counter-clockwise vertex indices); ValueError
    when it is open (naming ``snap``, the gap closed: :func:`_close_boundary`), branches,
    or is several outlines (a hole among them)."""
    black = edges[np.array(letters) == "B"]
    degree = np.bincount(black.ravel(), minlength=len(xy))
    if (degree == 1).any():
        ends = np.flatnonzero(degree == 1)
        gap = np.linalg.norm(xy[ends[1:]] - xy[ends[0]], axis=1)
        other = (
            f", {gap.min():.3g} drawing units from its end at {_at(xy[ends[1 + np.argmin(gap)]])}"
            if len(gap)
            else ""
        )
        raise RigidfoldError(
            f"the boundary (black) is not closed: it ends at {_at(xy[ends[0]])}{other} (a gap "
            f"of up to {snap:.3g} drawing units between two ends is closed; "
            "Settings.inputs.svg_snap_tol)"
        )
    if (degree > 2).any():
        w = int(np.argmax(degree))
        raise RigidfoldError(
            f"the boundary (black) is not one outline: {degree[w]} black lines meet at {_at(xy[w])}"
        )
    loops = [cycle for cycle, area in _cycles(xy, black) if area > 0]
    if len(loops) == 1:
        return loops[0]
    if not loops:
        raise RigidfoldError("the boundary (black) encloses no area")
    outlines = [shapely.Polygon(xy[loop]) for loop in loops]
    for loop in loops:
        x, y = xy[loop[0]]
        if sum(shapely.contains_xy(outlines, x, y)) > 0:
            raise RigidfoldError(
                f"the black outline through {_at(xy[loop[0]])} lies inside another: holes "
                "are not supported"
            )
    raise RigidfoldError(f"the boundary (black) is {len(loops)} separate outlines, not one sheet")


def _outline(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], angles: list[float]
) -> tuple[list[str], list[float]]:
    """The letters and angles of a drawing without black lines, the edges of the outline of
    its lines (the outer face of each connected part) made boundary, as Origami Simulator
    takes an edge with a face on one side only for one; ValueError when the lines enclose
    no area or their outline passes twice through a point (a crease hanging out of it).
    xy (V, 2), edges (E, 2) -> E letters, E angles."""
    cycles = _cycles(xy, edges)
    if not any(area > 0 for _, area in cycles):
        raise RigidfoldError(
            "no boundary: no black lines (Origami Simulator draws it black), and the lines "
            "drawn enclose no area to take for the sheet"
        )
    number = {(min(u, v), max(u, v)): e for e, (u, v) in enumerate(edges.tolist())}
    letters, angles = list(letters), list(angles)
    for cycle, area in cycles:
        if area >= 0:
            continue
        seen: set[int] = set()
        for w in cycle:
            if w in seen:
                raise RigidfoldError(
                    f"no boundary: no black lines, and the outline of the lines drawn, taken "
                    f"for the sheet's, passes twice through {_at(xy[w])} (a crease hanging "
                    "out of it)"
                )
            seen.add(w)
        for u, v in zip(cycle, cycle[1:] + cycle[:1], strict=True):
            e = number[(min(u, v), max(u, v))]
            letters[e], angles[e] = "B", 0.0
    return letters, angles


def _inside(
    xy: np.ndarray, edges: np.ndarray, boundary: list[int], letters: list[str], snap: float
) -> np.ndarray:
    """(E,) bool: False for the creases outside the ``boundary`` (its vertex indices) whose
    ends both lie within ``snap`` of it (overshoots of creases that end on the boundary),
    True for every other edge."""
    outline = shapely.Polygon(xy[boundary])
    mid = xy[edges].mean(axis=1)
    outside = ~shapely.contains_xy(outline, mid[:, 0], mid[:, 1]) & (np.array(letters) != "B")
    if not outside.any():
        return ~outside
    gap = shapely.distance(outline.exterior, shapely.points(xy[edges[outside]]))  # (k, 2)
    outside[outside] = (gap <= snap).all(axis=1)
    return ~outside


def _check_creases(
    xy: np.ndarray, edges: np.ndarray, letters: list[str], boundary: list[int], tol: float
) -> None:
    """ValueError for a crease outside the ``boundary`` (its vertex indices), a crease end
    that touches no other line, or creases not connected to the boundary."""
    outline = shapely.Polygon(xy[boundary])
    mid = xy[edges].mean(axis=1)
    outside = ~shapely.contains_xy(outline, mid[:, 0], mid[:, 1]) & (np.array(letters) != "B")
    if outside.any():
        u, v = edges[np.argmax(outside)]
        raise RigidfoldError(
            f"the crease from {_at(xy[u])} to {_at(xy[v])} lies outside the boundary"
        )
    degree = np.bincount(edges.ravel(), minlength=len(xy))
    if (degree == 1).any():
        raise RigidfoldError(
            f"a crease ends inside a face at {_at(xy[degree == 1][0])}: creases must end on "
            f"another line (an end within {tol:.3g} drawing units of a line is joined to it; "
            "Settings.inputs.svg_snap_tol)"
        )
    n, component = connected_components(_graph(edges, len(xy)), directed=False)
    if n > 1:
        raise RigidfoldError(
            f"creases around {_at(xy[component != component[0]][0])} are not connected to the "
            "boundary: the face around them would have a hole"
        )


def _faces(xy: np.ndarray, edges: np.ndarray) -> list[list[int]]:
    """The bounded faces of the drawing's plane graph, counter-clockwise; ValueError for one
    that is not a simple polygon. xy (V, 2), edges (E, 2) -> F lists of vertex indices."""
    faces = [cycle for cycle, area in _cycles(xy, edges) if area > 0]
    for face in faces:
        seen: set[int] = set()
        for w in face:
            if w in seen:
                raise RigidfoldError(
                    f"a face is not a simple polygon: its outline passes twice through "
                    f"{_at(xy[w])} (a crease with the same face on both sides, or crease "
                    "loops touching at one point)"
                )
            seen.add(w)
    return faces


def _cycles(xy: np.ndarray, edges: np.ndarray) -> list[tuple[list[int], float]]:
    """Every face cycle of a plane graph, each with its signed area: bounded faces run
    counter-clockwise (area > 0), the outer face of each connected part clockwise.

    Each directed edge u -> v is followed by the edge out of v next clockwise from v -> u,
    which keeps the face on the left. xy (V, 2), edges (E, 2) -> list of (vertices, area).
    """
    tail = np.concatenate([edges[:, 0], edges[:, 1]])
    head = np.concatenate([edges[:, 1], edges[:, 0]])
    twin = np.roll(np.arange(len(tail)), len(edges))
    d = xy[head] - xy[tail]
    order = np.lexsort((np.arctan2(d[:, 1], d[:, 0]), tail))  # around each vertex, ccw
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    start = np.searchsorted(tail[order], tail)  # where each vertex's ring begins
    degree = np.bincount(tail, minlength=len(xy))[tail]
    following = order[start[twin] + (rank[twin] - start[twin] - 1) % degree[twin]]
    cycles, done = [], np.zeros(len(tail), dtype=bool)
    for h in range(len(tail)):
        cycle, g = [], h
        while not done[g]:
            done[g] = True
            cycle.append(int(tail[g]))
            g = following[g]
        if cycle:
            x, y = xy[cycle].T
            area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
            cycles.append((cycle, area))
    return cycles


def _graph(edges: np.ndarray, n: int) -> coo_matrix:
    """The (n, n) adjacency matrix of the edges (E, 2)."""
    return coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))


def _cross(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """z component of p x q; p, q : (..., 2) float -> (...)."""
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _at(point: np.ndarray) -> str:
    """A point (2,) y up as the file's coordinates, for messages: ``(x, y)``, y down."""
    return f"({point[0]:.6g}, {-point[1] + 0.0:.6g})"
