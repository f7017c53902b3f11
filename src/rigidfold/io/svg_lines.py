"""The lines of an SVG crease pattern: its elements, read by svgelements, as straight pieces
in Origami Simulator's colours (:func:`rigidfold.io.svg_read.read_svg`).

Every ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>`` and ``<path>`` with a stroke is
read, its transforms and the ``viewBox`` applied, into straight pieces in user units, y up;
unstroked shapes, text and images are skipped, a curved piece (an arc, a Bezier curve, a
circle, an ellipse, a rounded rect) is refused. Colours are read by hue (:data:`COLOURS`), a
crease's stroke opacity as the fraction of 180 degrees it folds; green cuts are refused. The
root's ``width`` gives the drawing's unit (:func:`drawing_units`).
"""

from __future__ import annotations

import colorsys
import contextlib
import math
import re

import numpy as np
import svgelements as se

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
:func:`rigidfold.io.svg_read.read_svg` (by hue) and written by the cut sheets
(:mod:`rigidfold.exports.cutsheet`)."""

COLOURS = {letter: name for letter, (name, _) in OS_STROKES.items()}
"""Origami Simulator's stroke colours by FOLD letter. A stroke whose brightest channel is
below 25 % is black; one with saturation and brightness of at least 50 % whose hue is less
than :data:`HUE_TOLERANCE` degrees from red (0), yellow (60), green (120), blue (240) or
magenta (300) is that colour; any other stroke is refused."""

HUE_TOLERANCE = 30.0
"""Largest hue difference (degrees) of a stroke from its colour in :data:`COLOURS`."""


_LARGEST = 1e150
"""Largest extent of a drawing in its own units: squares of its lengths stay finite."""

_HUES = {
    letter: 360.0 * colorsys.rgb_to_hsv(*(int(hex_[k : k + 2], 16) / 255 for k in (1, 3, 5)))[0]
    for letter, (_, hex_) in OS_STROKES.items()
    if letter != "B"
}
"""The hue (degrees) of each colour of :data:`OS_STROKES` but black."""
_SHAPES = (se.SimpleLine, se.Polyline, se.Polygon, se.Rect, se.Path, se.Circle, se.Ellipse)


SVGELEMENTS_ERRORS = (ArithmeticError, IndexError, RecursionError, TypeError, AttributeError)
"""What svgelements raises on drawings it cannot compute with: arithmetic on degenerate or
enormous numbers, a transform or style it misreads, references in a loop, a value it has
not parsed (None) met in its arithmetic."""


def cannot_read(exc: BaseException) -> str:
    """The message of :data:`SVGELEMENTS_ERRORS`."""
    if isinstance(exc, RecursionError):
        hint = "do its <use> elements refer to each other in a loop?"
    elif isinstance(exc, TypeError | AttributeError):
        hint = "check the path data, points and coordinates of its shapes"
    else:
        hint = "check the numbers of its width, height, viewBox and transform attributes and styles"
    return f"svgelements cannot read the drawing ({type(exc).__name__}: {exc}): {hint}"


@contextlib.contextmanager
def _svgelements():
    """Turn :data:`SVGELEMENTS_ERRORS` into a one-line ValueError."""
    try:
        yield
    except SVGELEMENTS_ERRORS as exc:
        raise RigidfoldError(cannot_read(exc)) from None


def drawing_units(svg: se.SVG) -> tuple[str, float, se.Matrix]:
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


def drawn_lines(svg: se.SVG, to_user: se.Matrix) -> tuple[np.ndarray, list[str], list[float]]:
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
