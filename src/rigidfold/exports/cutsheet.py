"""Cut sheets of a design: its development diagram as DXF and SVG, millimetres at 1:1.

Both drawings come from one :class:`rigidfold.exports.sheet.Sheet` (the diagram turned to its
smallest bounding rectangle and placed with a margin at the origin) and sort what they draw
by kind (:data:`LAYERS`):

* ``BOUNDARY`` the outline of the sheet, the cut;
* ``MOUNTAIN``, ``VALLEY`` the free creases folded in the design;
* ``FLAT`` free creases that are flat in the design (hinges, drawn but not folded); none in
  most designs;
* ``PANEL`` the outline of each panel (triangles joined by fixed creases): the fixed creases
  themselves are not drawn, the panel is one piece;
* ``LABELS`` at the middle of every free crease its number (the pattern's edge index, as in
  the FOLD file and the schedule) and fold angle in degrees, valley positive.

DXF (ezdxf, R2010, ``$INSUNITS`` millimetres): one layer per kind; every boundary edge and
crease is one ``LINE``, every panel outline a closed ``LWPOLYLINE``, every label a ``TEXT``.
SVG: ``width``/``height`` in ``mm`` and a ``viewBox`` in millimetres (1 user unit = 1 mm), y
drawn downwards as SVG does (the sheet is seen from +z, not mirrored); one group per kind
(Inkscape shows them as layers), the boundary one closed path, creases ``line`` elements with
``id="crease-E"``; below the sheet a legend and a scale bar.

``convention="origami-simulator"`` writes the SVG that Origami Simulator imports instead: only
``line`` elements, boundary black ``#000000``, mountain red ``#ff0000`` and valley blue
``#0000ff`` with ``stroke-opacity`` = |fold angle| / 180 degrees (its target angle), fixed
creases yellow ``#ffff00`` (its facet creases, kept flat) and flat free creases magenta
``#ff00ff`` (its hinges without a target angle); no labels, legend or background, which it
would not read. It merges vertices closer than 3 user units (3 mm here).
"""

from __future__ import annotations

import html
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.exports.sheet import Sheet
from rigidfold.io.files import atomic_write
from rigidfold.io.svg_lines import OS_STROKES

CONVENTIONS = ("rigidfold", "origami-simulator")
"""SVG conventions of :func:`sheet_svg_text`."""


@dataclass(frozen=True)
class Layer:
    """A kind of line on the cut sheet: DXF layer ``name`` with AutoCAD colour index ``aci``;
    in SVG the group ``name`` drawn in ``colour``, ``width`` times the sheet's line width."""

    name: str
    aci: int
    colour: str
    width: float
    legend: str


LAYERS = (
    Layer("BOUNDARY", 7, "#000000", 1.5, "cut (boundary)"),
    Layer("MOUNTAIN", 1, "#d62728", 1.0, "mountain fold"),
    Layer("VALLEY", 5, "#1f77b4", 1.0, "valley fold"),
    Layer("FLAT", 8, "#8c8c8c", 1.0, "hinge, flat in the design"),
    Layer("PANEL", 3, "#2ca02c", 0.6, "panel outline (fixed creases inside)"),
    Layer("LABELS", 7, "#333333", 0.0, "crease number: fold angle (valley +)"),
)
"""The layers of the cut sheet, in drawing order of the SVG legend."""

CREASE_LAYERS = {"B": "BOUNDARY", "M": "MOUNTAIN", "V": "VALLEY", "F": "FLAT"}
"""Layer of the edges of each assignment letter; fixed creases (``"J"``) are in none."""

OS_LETTERS = {"B": "B", "M": "M", "V": "V", "J": "F", "F": "U"}
"""Origami Simulator's letter (colour, :data:`rigidfold.io.svg_lines.OS_STROKES`) of each
assignment letter: a fixed crease is a facet crease (yellow), a free crease left flat an
undriven one (magenta)."""

_LAYER = {layer.name: layer for layer in LAYERS}


LABEL_FILL = 0.7
"""Share of its crease's length a crease label may take on the whole-pattern sheet."""


@dataclass(frozen=True)
class Label:
    """A crease label: ``text`` centred at (x, y) mm, turned ``rotation`` degrees
    counter-clockwise (y up), so that it reads along its crease, beside it, ``size`` mm
    high (0: the sheet's :attr:`~rigidfold.exports.sheet.Sheet.text_height`)."""

    text: str
    x: float
    y: float
    rotation: float
    size: float = 0.0


def crease_labels(sheet: Sheet) -> list[Label]:
    """One label per free crease (mountain, valley or flat): ``"E: +A°"`` with E the edge
    index and A the fold angle in degrees, beside the crease's midpoint, as large as
    :data:`LABEL_FILL` of the crease's length allows (at least the sheet's text height, at
    most twice it); labels that would overlap another are made smaller again (down to the
    sheet's text height; overlaps are found with shapely's STRtree)."""
    import shapely

    least = sheet.text_height
    rows = []
    for e in sheet.pattern.free_creases.tolist():
        u, v = sheet.pattern.edges[e]
        a, b = sheet.xy[u], sheet.xy[v]
        text = f"{e}: {sheet.fold_angles_deg[e]:+.1f}°"
        # as large as fits along the crease (0.6 em a character), never below the sheet's
        h = max(least, min(LABEL_FILL * float(np.hypot(*(b - a))) / (0.6 * len(text)), 2 * least))
        rotation = math.degrees(math.atan2(b[1] - a[1], b[0] - a[0]))
        if rotation > 90:
            rotation -= 180
        elif rotation <= -90:
            rotation += 180
        rows.append([text, (a + b) / 2, rotation, h])

    def made() -> list[Label]:
        out = []
        for text, mid, rotation, h in rows:
            turn = math.radians(rotation)
            x, y = mid + 0.7 * h * np.array([-math.sin(turn), math.cos(turn)])
            out.append(Label(text, float(x), float(y), rotation, h))
        return out

    labels = made()
    for _ in range(6):
        boxes = [_box(label) for label in labels]
        first, second = shapely.STRtree(boxes).query(boxes, predicate="intersects")
        crowded = {int(i) for i, j in zip(first, second, strict=True) if i != j}
        crowded = {i for i in crowded if rows[i][3] > least}
        if not crowded:
            break
        for i in crowded:
            rows[i][3] = max(0.8 * rows[i][3], least)
        labels = made()
    return labels


def _box(label: Label):
    """The rectangle a crease label covers (0.6 em a character), mm."""
    import shapely

    half = 0.3 * label.size * len(label.text)
    turn = math.radians(label.rotation)
    d = np.array([math.cos(turn), math.sin(turn)])
    n = np.array([-d[1], d[0]]) * 0.5 * label.size
    c = np.array([label.x, label.y])
    return shapely.Polygon([c - half * d - n, c + half * d - n, c + half * d + n, c - half * d + n])


# ------------------------------------------------------------------------------ DXF
def dxf_text(sheet: Sheet) -> str:
    """The DXF document (R2010, millimetres) of the cut sheet; see the module."""
    import ezdxf
    from ezdxf import units
    from ezdxf.enums import TextEntityAlignment

    doc = ezdxf.new("R2010", units=units.MM)
    for layer in LAYERS:
        doc.layers.add(layer.name, color=layer.aci)
    msp = doc.modelspace()
    xy, edges = sheet.xy, sheet.pattern.edges
    for letter, name in CREASE_LAYERS.items():
        for e in sheet.edges_of(letter):
            u, v = edges[e]
            msp.add_line(tuple(xy[u]), tuple(xy[v]), dxfattribs={"layer": name})
    for loops in sheet.panel_loops:
        for loop in loops:
            msp.add_lwpolyline(xy[loop].tolist(), close=True, dxfattribs={"layer": "PANEL"})
    for label in crease_labels(sheet):
        text = msp.add_text(
            label.text,
            height=label.size or sheet.text_height,
            rotation=label.rotation,
            dxfattribs={"layer": "LABELS"},
        )
        text.set_placement((label.x, label.y), align=TextEntityAlignment.MIDDLE_CENTER)
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue()


def write_dxf(path: str | os.PathLike, sheet: Sheet) -> Path:
    """Write :func:`dxf_text` atomically (:func:`rigidfold.io.atomic_write`); returns
    ``path``. ValueError ``"cannot write '<path>': <reason>"`` when it cannot be written."""
    return atomic_write(path, dxf_text(sheet))


# ------------------------------------------------------------------------------ SVG
def check_convention(convention: str) -> None:
    """ValueError naming ``convention`` unless it is one of :data:`CONVENTIONS`."""
    if convention not in CONVENTIONS:
        raise RigidfoldError(
            f"convention must be one of {', '.join(CONVENTIONS)}, got {convention!r}"
        )


def sheet_svg_text(sheet: Sheet, *, title: str = "", convention: str = "rigidfold") -> str:
    """The SVG document of the cut sheet in ``convention`` (:data:`CONVENTIONS`); see the
    module. Raises ValueError for an unknown convention."""
    check_convention(convention)
    lw = max(sheet.width, sheet.height) / 1000
    body = _origami_simulator(sheet, lw) if convention == CONVENTIONS[1] else _drawing(sheet, lw)
    height = sheet.height + (0 if convention == CONVENTIONS[1] else _legend_height(sheet))
    head = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<svg xmlns="http://www.w3.org/2000/svg" '
        'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        f'width="{_n(sheet.width)}mm" height="{_n(height)}mm" '
        f'viewBox="0 0 {_n(sheet.width)} {_n(height)}">',
        f"<title>{html.escape(title)}</title>" if title else "",
        "<desc>rigidfold cut sheet: millimetres at 1:1 (1 user unit = 1 mm), seen from +z; "
        f"the development diagram turned {math.degrees(sheet.angle):.3f} degrees</desc>",
    ]
    return "\n".join(line for line in [*head, *body, "</svg>"] if line) + "\n"


def write_sheet_svg(
    path: str | os.PathLike, sheet: Sheet, *, title: str = "", convention: str = "rigidfold"
) -> Path:
    """Write :func:`sheet_svg_text` atomically (:func:`rigidfold.io.atomic_write`); returns
    ``path``. ValueError ``"cannot write '<path>': <reason>"`` when it cannot be written."""
    return atomic_write(path, sheet_svg_text(sheet, title=title, convention=convention))


def _drawing(sheet: Sheet, lw: float) -> list[str]:
    """The SVG elements of the rigidfold convention: groups per layer, legend, scale bar."""
    X, Y = _svg_xy(sheet)
    edges = sheet.pattern.edges
    panel = _LAYER["PANEL"]
    out = [
        _group(panel, lw, f'fill="{panel.colour}" fill-opacity="0.08" fill-rule="evenodd"'),
        *(
            f'<path id="panel-{k}" d="{" ".join(_ring(X, Y, loop) for loop in loops)}"/>'
            for k, loops in enumerate(sheet.panel_loops)
        ),
        "</g>",
    ]
    for letter in "FMV":
        out.append(_group(_LAYER[CREASE_LAYERS[letter]], lw, 'stroke-linecap="round"'))
        for e in sheet.edges_of(letter).tolist():
            u, v = edges[e]
            out.append(f'<line id="crease-{e}" {_segment(X, Y, u, v)}/>')
        out.append("</g>")
    out += [
        _group(_LAYER["BOUNDARY"], lw, 'fill="none" stroke-linejoin="round"'),
        f'<path id="boundary" d="{_ring(X, Y, sheet.boundary_loop)}"/>',
        "</g>",
        _group(_LAYER["LABELS"], lw, _font(sheet.text_height)),
    ]
    for label in crease_labels(sheet):
        x, y = _n(label.x), _n(sheet.height - label.y)
        out.append(
            f'<text x="{x}" y="{y}" dy="0.35em" font-size="{_n(label.size or sheet.text_height)}"'
            f' transform="rotate({-label.rotation:.3f} {x} {y})">{html.escape(label.text)}</text>'
        )
    return [*out, "</g>", *_legend(sheet, lw)]


def _origami_simulator(sheet: Sheet, lw: float) -> list[str]:
    """The ``line`` elements of Origami Simulator's convention, one per drawn edge."""
    X, Y = _svg_xy(sheet)
    out = []
    for e, (u, v) in enumerate(sheet.pattern.edges.tolist()):
        letter = sheet.assignment[e]
        opacity = ""
        if letter in "MV":
            opacity = f' stroke-opacity="{abs(sheet.fold_angles_deg[e]) / 180:.6g}"'
        out.append(
            f'<line id="crease-{e}" {_segment(X, Y, u, v)} fill="none" '
            f'stroke="{OS_STROKES[OS_LETTERS[letter]][1]}"{opacity} stroke-width="{_n(lw)}"/>'
        )
    return out


def _legend_height(sheet: Sheet) -> float:
    """Height of the band below the sheet that holds the legend and the scale bar, mm."""
    rows = max(len(_legend_layers(sheet)), 4)  # the scale bar takes four
    return (2.4 + 1.6 * (rows - 1)) * _legend_font(sheet) + sheet.margin


def _legend_font(sheet: Sheet) -> float:
    return max(sheet.width, sheet.height) / 60


def _legend_layers(sheet: Sheet) -> list[Layer]:
    """The layers that hold something on this sheet (all but, mostly, FLAT)."""
    empty = {CREASE_LAYERS[k] for k in "MVF" if not len(sheet.edges_of(k))}
    if not len(sheet.pattern.free_creases):
        empty.add("LABELS")
    return [layer for layer in LAYERS if layer.name not in empty]


def _legend(sheet: Sheet, lw: float) -> list[str]:
    """The legend (a sample of each layer drawn) and a scale bar, below the sheet."""
    f = _legend_font(sheet)
    x0, top = sheet.margin, sheet.height + 1.2 * f
    out = [f'<g id="LEGEND" {_font(f)} text-anchor="start">']
    for i, layer in enumerate(_legend_layers(sheet)):
        y = _n(top + 1.6 * f * i)
        if layer.name == "LABELS":
            sample = (
                f'<text x="{_n(x0)}" y="{y}" dy="0.35em" fill="{layer.colour}">12: +35.0°</text>'
            )
        else:
            sample = (
                f'<line x1="{_n(x0)}" y1="{y}" x2="{_n(x0 + 4 * f)}" y2="{y}" '
                f'stroke="{layer.colour}" stroke-width="{_n(lw * max(layer.width, 1.0))}"/>'
            )
        text = html.escape(layer.legend)
        out += [sample, f'<text x="{_n(x0 + 7 * f)}" y="{y}" dy="0.35em">{text}</text>']
    bar = _nice_length(sheet.width / 4)
    bx, by = 0.55 * sheet.width, top
    out += [
        "</g>",
        f'<g id="SCALE" {_font(f)} stroke="#000000" stroke-width="{_n(lw)}">',
        f'<path d="M {_n(bx)} {_n(by - f / 2)} V {_n(by)} H {_n(bx + bar)} V {_n(by - f / 2)}" '
        'fill="none"/>',
        f'<text x="{_n(bx + bar / 2)}" y="{_n(by + 1.6 * f)}" dy="0.35em" stroke="none" '
        f'text-anchor="middle">{bar:g} mm</text>',
        f'<text x="{_n(bx)}" y="{_n(by + 3.2 * f)}" dy="0.35em" stroke="none">'
        "scale 1:1, millimetres</text>",
        f'<text x="{_n(bx)}" y="{_n(by + 4.8 * f)}" dy="0.35em" stroke="none">'
        f"sheet {sheet.width:.1f} x {sheet.height:.1f} mm</text>",
        "</g>",
    ]
    return out


def _nice_length(limit: float) -> float:
    """The largest 1, 2 or 5 times a power of ten that is at most ``limit`` (> 0), mm."""
    power = 10.0 ** math.floor(math.log10(limit))
    return max(m * power for m in (1, 2, 5) if m * power <= limit)


def _svg_xy(sheet: Sheet) -> tuple[np.ndarray, np.ndarray]:
    """(V,) x and (V,) y of the vertices in SVG user units: mm, y downwards."""
    return sheet.xy[:, 0], sheet.height - sheet.xy[:, 1]


def _group(layer: Layer, lw: float, extra: str) -> str:
    stroke = f'stroke="{layer.colour}" stroke-width="{_n(lw * layer.width)}"'
    if layer.name == "LABELS":
        stroke = f'fill="{layer.colour}" text-anchor="middle"'
    return (
        f'<g id="{layer.name}" inkscape:groupmode="layer" inkscape:label="{layer.name}" '
        f"{stroke} {extra}>"
    )


def _font(size: float) -> str:
    return f'font-family="sans-serif" font-size="{_n(size)}"'


def _segment(X: np.ndarray, Y: np.ndarray, u: int, v: int) -> str:
    return f'x1="{_n(X[u])}" y1="{_n(Y[u])}" x2="{_n(X[v])}" y2="{_n(Y[v])}"'


def _ring(X: np.ndarray, Y: np.ndarray, loop: np.ndarray) -> str:
    """Path data of the closed polygon through the vertices ``loop`` (m,)."""
    points = " L ".join(f"{_n(X[v])} {_n(Y[v])}" for v in loop.tolist())
    return f"M {points} Z"


def _n(value: float) -> str:
    """A length in mm for SVG: six decimals (a nanometre), no trailing zeros."""
    text = f"{float(value):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text
