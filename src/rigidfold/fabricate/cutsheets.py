"""Cut sheets of thick panels, nested onto stock sheets: one DXF and one SVG per sheet, in mm.

Each panel is drawn as seen from its face on the design surface: that face's outline (the cut
line, layer CUT), the outline of its far face (where the bevels and reliefs end, layer
BEVEL), its number ``P K`` (the ``panel_K`` of the 3D files and the schedules) and, on each
bevelled edge, the hinge's crease ``E`` and the bevel angle between the bevel face and the
surface (``E12 64.2°``: tilt the saw blade by 90° minus it). Both outlines are taken from
the solid itself (its faces on the surface and at the full depth), so the sheets and the 3D
files agree.

Nesting (:func:`nest`), two ways, the one on fewer stock sheets kept (then the one that
uses less of the last sheet's width; the boxes where both are alike). By boxes
(:func:`nest_boxes`): parts are first joined in pairs where that packs tighter
(:func:`group`: two parts, most often triangles, whose convex hulls' longest sides are about
as long, set side by side along them, the gap apart, the second turned half round, where the
pair's smallest box is smaller than the two boxes alone), then each part or pair is turned
to its smallest bounding rectangle (:func:`rigidfold.exports.sheet.min_area_angle`), its box
rounded up to whole millimetres plus the gap, and the boxes are packed onto as many stock
sheets as needed by ``rectpack`` (boxes may turn a quarter), the fewest sheets of a few of
its heuristics (:func:`_pack`). By outlines (:func:`nest_by_outlines`, for at most
``fabricate_nest_parts`` parts): each part's true outline is placed, largest first, at the
leftmost-then-lowest spot where it keeps the gap, at a few turns
(:mod:`rigidfold.fabricate.nesting`). Parts are never mirrored (their surface face stays
up). A part larger than the stock in either direction is put on a sheet of its own size and
reported (``oversize``) either way.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
import shapely.errors
import shapely.geometry

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.exports.sheet import min_area_angle
from rigidfold.fabricate.build import Fabrication
from rigidfold.io.files import write_together

MM = 1000.0

SHEET_FILE = r"{}_(?:sheet|oversize)_[0-9]{{2,}}\.(?:dxf|svg)"
"""The names :func:`write_cut_sheets` writes (a regular expression, ``{}`` for the design's
name, escaped): ``NAME_sheet_NN`` and ``NAME_oversize_NN``, ``.dxf`` and ``.svg``."""


@dataclass(frozen=True, eq=False)
class Part:
    """One panel drawn flat, millimetres, its bounding box starting at (0, 0).

    panel : int; cut : shapely geometry of the surface face; far : of the far face (may be
    empty); labels : ((x, y, text), ...) of the bevelled edges; width, height : its box.
    """

    panel: int
    cut: shapely.Geometry
    far: shapely.Geometry
    labels: tuple[tuple[float, float, str], ...]
    width: float
    height: float


@dataclass(frozen=True, eq=False)
class Placed:
    """A part on a sheet: its geometry moved there, mm."""

    part: Part
    cut: shapely.Geometry
    far: shapely.Geometry
    labels: tuple[tuple[float, float, str], ...]
    centre: tuple[float, float]


@dataclass(frozen=True, eq=False)
class StockSheet:
    """One stock sheet: its size (mm), its parts, whether it is an oversize one, and how
    its parts were nested (``"boxes"`` or ``"outlines"``)."""

    width: float
    height: float
    parts: tuple[Placed, ...]
    oversize: bool = False
    nesting: str = "boxes"


def _frame(fab: Fabrication, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin, a1, a2): a frame in panel k's surface, seen from outside its surface face."""
    p = fab.panels
    origin = p.pattern.coords[p.vertices[k]].mean(axis=0)
    out = -p.material[k]
    a1 = p.pattern.coords[p.vertices[k][0]] - origin
    a1 -= (a1 @ out) * out
    a1 /= np.linalg.norm(a1)
    return origin, a1, np.cross(out, a1)


def _faces_at(fab: Fabrication, k: int, depth: float, origin, a1, a2) -> shapely.Geometry:
    verts, tris = fab.solids.meshes[k]
    if not len(tris):
        return shapely.Polygon()
    d = fab.panels.material[k]
    w = (verts - origin) @ d
    tol = 1e-6 * fab.solids.thickness
    on = np.abs(w[tris] - depth).max(axis=1) <= tol
    if not on.any():
        return shapely.Polygon()
    xy = np.column_stack([(verts - origin) @ a1, (verts - origin) @ a2]) * MM
    polys = shapely.polygons(xy[tris[on]])
    return outline(shapely.union_all(polys, grid_size=OUTLINE_GRID), OUTLINE_CLOSE)


OUTLINE_GRID = 1e-4
"""The grid (mm) the triangles of a face are snapped to before their union."""

OUTLINE_CLOSE = 1e-2
"""Cracks narrower than twice this (mm) between a face's triangles are closed: the solid's
mesh has vertices on its triangles' edges (T-junctions), which leave slits of about 1e-6 mm
between the triangles' union that a cutter would follow into the panel."""


def outline(face: shapely.Geometry, close: float = OUTLINE_CLOSE) -> shapely.Geometry:
    """One face of a solid drawn flat as one simple polygon without holes (mm): ``face``
    closed morphologically by ``close`` mm (grown, then shrunk by it with mitred corners,
    so that the slits between its triangles close and its corners stay sharp), and of what
    is left the largest polygon's outer ring (the pieces and holes left are slivers of the
    mesh's rounding: a panel is one piece without holes); empty for an empty face."""
    if face.is_empty:
        return shapely.Polygon()
    closed = face.buffer(close, join_style="mitre", mitre_limit=10.0).buffer(
        -close, join_style="mitre", mitre_limit=10.0
    )
    pieces = [g for g in getattr(closed, "geoms", [closed]) if g.geom_type == "Polygon"]
    if not pieces:
        return shapely.Polygon()
    largest = max(pieces, key=lambda g: g.area)
    ring = shapely.Polygon(largest.exterior).simplify(OUTLINE_GRID)
    return shapely.geometry.polygon.orient(ring, 1.0)


def parts(fab: Fabrication) -> list[Part]:
    """Every panel's :class:`Part`, turned to its smallest box."""
    p, s = fab.panels, fab.solids
    out = []
    for k in range(p.n):
        origin, a1, a2 = _frame(fab, k)
        cut = _faces_at(fab, k, 0.0, origin, a1, a2)
        far = _faces_at(fab, k, s.thickness, origin, a1, a2)
        labels = []
        for h in p.hinges_of[k].tolist():
            u, v = p.hinge_vertices[h].tolist()
            mid = 0.5 * (p.pattern.coords[u] + p.pattern.coords[v]) - origin
            inward = p.pattern.coords[p.vertices[k]].mean(axis=0) - origin - mid
            at = mid + 0.15 * inward
            text = f"E{int(p.hinge_edges[h])} {math.degrees(s.bevel[h]):.1f}°"
            labels.append((float(at @ a1) * MM, float(at @ a2) * MM, text))
        part = Part(k, cut, far, tuple(labels), 0.0, 0.0)
        out.append(part if cut.is_empty else _fit([part])[0])
    return out


def _fit(members: list[Part]) -> list[Part]:
    """``members`` (in one frame) turned together to their smallest bounding rectangle, its
    longer side along x, moved to start at (0, 0); each gets that rectangle's size."""
    ring = np.vstack([np.asarray(shapely.get_coordinates(m.cut)) for m in members])
    angle = min_area_angle(ring)
    c, sn = math.cos(angle), math.sin(angle)
    turn = np.array([[c, sn], [-sn, c]])  # row vectors: xy @ turn turns by angle
    x0, y0 = (ring @ turn).min(axis=0)
    x1, y1 = (ring @ turn).max(axis=0)
    if (y1 - y0) > (x1 - x0):
        turn = turn @ np.array([[0.0, 1.0], [-1.0, 0.0]])
        x0, y0 = (ring @ turn).min(axis=0)
        x1, y1 = (ring @ turn).max(axis=0)
    shift = -np.array([x0, y0])
    out = []
    for m in members:
        labels = tuple(
            (float(q[0]), float(q[1]), t)
            for q, t in ((np.array([x, y]) @ turn + shift, t) for x, y, t in m.labels)
        )
        out.append(
            Part(
                m.panel,
                _moved(m.cut, turn, shift),
                _moved(m.far, turn, shift),
                labels,
                float(x1 - x0),
                float(y1 - y0),
            )
        )
    return out


def _longest_side(cut: shapely.Geometry) -> tuple[np.ndarray, np.ndarray, float]:
    """(a, b, length): the longest side of the convex hull of ``cut``, counter-clockwise (the
    part on its left)."""
    hull = shapely.geometry.polygon.orient(shapely.convex_hull(cut), 1.0)
    ring = np.asarray(hull.exterior.coords)
    sides = np.diff(ring, axis=0)
    i = int(np.argmax(np.hypot(sides[:, 0], sides[:, 1])))
    return ring[i], ring[i + 1], float(np.hypot(*sides[i]))


def _joined(
    first: Part,
    second: Part,
    gap: float,
    sides: tuple[tuple[np.ndarray, np.ndarray, float], tuple[np.ndarray, np.ndarray, float]],
) -> list[list[Part]]:
    """``second`` turned and moved so that the longest side of its convex hull runs along
    that of ``first``'s (``sides``: both, :func:`_longest_side`), ``gap`` away on the other
    side, its ends at either end: the two pairs, fitted (:func:`_fit`). The hulls lie on
    the two sides of a strip ``gap`` wide, so the parts keep the gap."""
    (a, b, _), (c, d, _) = sides
    e = (b - a) / np.linalg.norm(b - a)
    normal = np.array([e[1], -e[0]])  # right of a -> b: away from first
    angle = math.atan2(*(a - b)[::-1]) - math.atan2(*(d - c)[::-1])
    co, si = math.cos(angle), math.sin(angle)
    turn = np.array([[co, si], [-si, co]])
    out = []
    for anchor, point in ((b, c), (a, d)):
        shift = anchor + gap * normal - point @ turn
        moved = Part(
            second.panel,
            _moved(second.cut, turn, shift),
            _moved(second.far, turn, shift),
            tuple(
                (float(q[0]), float(q[1]), t)
                for q, t in ((np.array([x, y]) @ turn + shift, t) for x, y, t in second.labels)
            ),
            0.0,
            0.0,
        )
        out.append(_fit([first, moved]))
    return out


def group(
    items: list[Part],
    width: float,
    height: float,
    gap: float,
    *,
    window: int = DEFAULTS.fabricate.nest_pair_window,
) -> list[list[Part]]:
    """The parts in groups of one or two to be packed as one box each: two parts whose
    hulls' longest sides are within a fifth of each other's length are joined along them
    (:func:`_joined`) where that saves box area (with the gap) and still fits the stock,
    the largest savings first; the rest alone.

    Only the ``window`` parts that follow a part in the order of those sides are offered
    to it (parts of about one length lie next to each other there), and an offer keeps its
    saving alone, the pair built again when it is taken: time and memory grow as the
    parts times ``window``, not as the parts squared."""

    def box(w: float, h: float) -> float:
        return (w + gap) * (h + gap)

    def fits(w: float, h: float) -> bool:
        w, h = math.ceil(w + gap), math.ceil(h + gap)
        inner_w, inner_h = math.floor(width - gap), math.floor(height - gap)
        return (w <= inner_w and h <= inner_h) or (h <= inner_w and w <= inner_h)

    live = [p for p in items if not p.cut.is_empty]
    longest = [_longest_side(p.cut) for p in live]
    sides = np.array([x[2] for x in longest], dtype=np.float64)
    alone_fits = [fits(p.width, p.height) for p in live]
    order = np.argsort(sides, kind="stable")
    offers: list[tuple[float, int, int, int]] = []
    for at, i in enumerate(order.tolist()):
        if not alone_fits[i]:
            continue
        for j in order[at + 1 : at + 1 + window].tolist():
            if sides[j] - sides[i] > 0.2 * max(sides[i], sides[j]):
                break
            if not alone_fits[j]:
                continue
            a, b = min(i, j), max(i, j)
            alone = box(live[a].width, live[a].height) + box(live[b].width, live[b].height)
            for way, pair in enumerate(_joined(live[a], live[b], gap, (longest[a], longest[b]))):
                w, h = pair[0].width, pair[0].height
                if fits(w, h) and box(w, h) < alone:
                    offers.append((box(w, h) - alone, a, b, way))
    offers.sort()
    used: set[int] = set()
    groups = []
    for _, i, j, way in offers:
        if i not in used and j not in used:
            used |= {i, j}
            groups.append(_joined(live[i], live[j], gap, (longest[i], longest[j]))[way])
    groups += [[p] for k, p in enumerate(live) if k not in used]
    return groups


def nest(
    items: list[Part],
    width: float,
    height: float,
    gap: float,
    *,
    settings: Settings = DEFAULTS,
) -> list[StockSheet]:
    """Pack ``items`` onto stock sheets ``width`` x ``height`` mm with ``gap`` mm between
    parts and from the edges (see the module's text): by their boxes (:func:`nest_boxes`)
    and by their outlines (:func:`nest_by_outlines`, up to ``fabricate_nest_parts`` parts),
    the one on fewer stock sheets kept, then the one that uses less of the last sheet's
    width, the boxes where both are alike. Parts with an empty outline are left out."""
    boxes = nest_boxes(items, width, height, gap, settings=settings)
    stock = [s for s in boxes if not s.oversize]
    panels = {p.part.panel for s in stock for p in s.parts}
    on_stock = [p for p in items if p.panel in panels]  # each in its own frame, not its pair's
    if not on_stock or len(on_stock) > settings.fabricate.nest_parts:
        return boxes
    try:
        outlines = nest_by_outlines(on_stock, width, height, gap, settings=settings)
    except shapely.errors.GEOSException:  # a degenerate outline: the boxes still hold
        outlines = None
    if outlines is None or _usage(outlines) >= _usage(stock):
        return boxes
    return outlines + [s for s in boxes if s.oversize]


def _usage(sheets: list[StockSheet]) -> tuple[int, float]:
    """(how many sheets, how far the last one is used along its width, mm)."""
    last = max((p.cut.bounds[2] for p in sheets[-1].parts), default=0.0) if sheets else 0.0
    return len(sheets), round(last, 3)


def nest_by_outlines(
    items: list[Part],
    width: float,
    height: float,
    gap: float,
    *,
    settings: Settings = DEFAULTS,
) -> list[StockSheet] | None:
    """``items`` placed by their true outlines on stock sheets ``width`` x ``height`` mm,
    ``gap`` mm apart and from the edges (:func:`rigidfold.fabricate.nesting.nest_outlines`:
    turned, never mirrored); ``None`` where one of them fits on no sheet."""
    from rigidfold.fabricate.nesting import nest_outlines

    spots = nest_outlines([p.cut for p in items], width, height, gap, settings=settings)
    if spots is None:
        return None
    placed: dict[int, list[Placed]] = {}
    for part, spot in zip(items, spots, strict=True):
        c, s = math.cos(spot.angle), math.sin(spot.angle)
        turn = np.array([[c, s], [-s, c]])  # row vectors: x @ turn turns x by the angle
        placed.setdefault(spot.sheet, []).append(_placed(part, turn, (spot.x, spot.y)))
    return [StockSheet(width, height, tuple(placed[b]), nesting="outlines") for b in sorted(placed)]


def nest_boxes(
    items: list[Part],
    width: float,
    height: float,
    gap: float,
    *,
    settings: Settings = DEFAULTS,
) -> list[StockSheet]:
    """Pack ``items`` by their boxes (their pairs' boxes, :func:`group`) onto stock sheets
    ``width`` x ``height`` mm with ``gap`` mm between parts and from the edges, by
    ``rectpack`` (:func:`_pack`); a part larger than the stock on an oversize sheet of its
    own after them."""
    inner_w, inner_h = math.floor(width - gap), math.floor(height - gap)
    boxes: dict[int, tuple[int, int, list[Part]]] = {}
    oversize = []
    for g, members in enumerate(
        group(items, width, height, gap, window=settings.fabricate.nest_pair_window)
    ):
        first = members[0]
        w = math.ceil(first.width + gap)
        h = math.ceil(first.height + gap)
        fits = (w <= inner_w and h <= inner_h) or (h <= inner_w and w <= inner_h)
        if fits:
            boxes[g] = (w, h, members)
        else:
            oversize += members
    sheets: list[StockSheet] = []
    if boxes:
        packer = _pack({rid: (w, h) for rid, (w, h, _) in boxes.items()}, inner_w, inner_h)
        placed: dict[int, list[Placed]] = {}
        for b, x, y, w, h, rid in packer.rect_list():
            bw, bh, members = boxes[rid]
            turned = (w, h) != (bw, bh)
            for part in members:
                placed.setdefault(b, []).append(_place(part, x + gap, y + gap, turned))
        if sum(len(v) for v in placed.values()) != sum(len(m) for *_, m in boxes.values()):
            raise RigidfoldError(
                "the nesting lost a part (rectpack placed fewer than it was given)"
            )
        sheets += [StockSheet(width, height, tuple(placed[b])) for b in sorted(placed)]
    for part in oversize:
        sheets.append(
            StockSheet(
                part.width + 2 * gap,
                part.height + 2 * gap,
                (_place(part, gap, gap, False),),
                oversize=True,
            )
        )
    return sheets


def _pack(boxes: dict[int, tuple[int, int]], width: int, height: int):
    """The ``rectpack`` packer that puts ``boxes`` {id: (w, h)} on the fewest bins of
    ``width`` x ``height`` among a few of its heuristics (MaxRects best short side, best
    area, bottom-left and best long side fit; boxes sorted by area, perimeter, longer or
    shorter side; bins filled first fit or best fit), the first of the fewest kept."""
    import rectpack

    best = None
    for algo in (
        rectpack.MaxRectsBssf,
        rectpack.MaxRectsBaf,
        rectpack.MaxRectsBl,
        rectpack.MaxRectsBlsf,
    ):
        for order in (
            rectpack.SORT_AREA,
            rectpack.SORT_PERI,
            rectpack.SORT_LSIDE,
            rectpack.SORT_SSIDE,
        ):
            for bins in (rectpack.PackingBin.BFF, rectpack.PackingBin.BBF):
                packer = rectpack.newPacker(
                    bin_algo=bins, pack_algo=algo, sort_algo=order, rotation=True
                )
                for rid, (w, h) in boxes.items():
                    packer.add_rect(w, h, rid)
                packer.add_bin(width, height, count=float("inf"))
                packer.pack()
                if best is None or len(packer) < len(best):
                    best = packer
    return best


def _moved(geometry, matrix: np.ndarray | None = None, offset=(0.0, 0.0)):
    """``geometry`` with every point x (row) taken to ``x @ matrix + offset``."""
    m = np.eye(2) if matrix is None else np.asarray(matrix, dtype=np.float64)
    o = np.asarray(offset, dtype=np.float64)
    return shapely.transform(geometry, lambda x: x @ m + o)


def _place(part: Part, x: float, y: float, turned: bool) -> Placed:
    """``part`` at (x, y), a quarter turn back into its box ``[0, height] x [0, width]``
    where ``turned``."""
    if not turned:
        return _placed(part, None, (x, y))
    quarter = np.array([[0.0, 1.0], [-1.0, 0.0]])
    return _placed(part, quarter, (part.height + x, y))


def _placed(part: Part, matrix: np.ndarray | None, offset: tuple[float, float]) -> Placed:
    """``part`` with every point p (row) taken to ``p @ matrix + offset`` (a turn: never a
    mirror), its labels with it."""
    m = np.eye(2) if matrix is None else np.asarray(matrix, dtype=np.float64)
    cut = _moved(part.cut, m, offset)
    far = _moved(part.far, m, offset)
    moved = tuple(
        (float(q[0]), float(q[1]), t)
        for q, t in ((np.array([lx, ly]) @ m + offset, t) for lx, ly, t in part.labels)
    )
    c = cut.representative_point()
    return Placed(part, cut, far, moved, (float(c.x), float(c.y)))


def _rings(geometry: shapely.Geometry) -> list[np.ndarray]:
    """The closed rings (exterior and holes) of a polygonal geometry, (n, 2) each."""
    out = []
    for poly in getattr(geometry, "geoms", [geometry]):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        out.append(np.asarray(poly.exterior.coords)[:-1])
        out += [np.asarray(r.coords)[:-1] for r in poly.interiors]
    return out


def text_height(sheet: StockSheet) -> float:
    return max(min(sheet.width, sheet.height) / 60.0, 5.0)


def dxf_bytes(sheet: StockSheet, *, title: str = "") -> bytes:
    """One stock sheet as DXF (R2010, mm): layers SHEET, CUT, BEVEL, LABELS."""
    import io

    import ezdxf
    from ezdxf import units

    doc = ezdxf.new("R2010", setup=True)
    doc.units = units.MM
    doc.header["$INSUNITS"] = units.MM
    for name, colour in (("SHEET", 8), ("CUT", 7), ("BEVEL", 1), ("LABELS", 5)):
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    msp.add_lwpolyline(
        [(0, 0), (sheet.width, 0), (sheet.width, sheet.height), (0, sheet.height)],
        close=True,
        dxfattribs={"layer": "SHEET"},
    )
    size = text_height(sheet)
    for placed in sheet.parts:
        for ring in _rings(placed.cut):
            msp.add_lwpolyline(ring.tolist(), close=True, dxfattribs={"layer": "CUT"})
        for ring in _rings(placed.far):
            msp.add_lwpolyline(ring.tolist(), close=True, dxfattribs={"layer": "BEVEL"})
        msp.add_text(
            f"P{placed.part.panel}", height=size, dxfattribs={"layer": "LABELS"}
        ).set_placement(placed.centre, align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
        for x, y, text in placed.labels:
            msp.add_text(text, height=size * 0.5, dxfattribs={"layer": "LABELS"}).set_placement(
                (x, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER
            )
    if title:
        msp.add_text(title, height=size * 0.5, dxfattribs={"layer": "LABELS"}).set_placement(
            (size, sheet.height - size)
        )
    out = io.StringIO()
    doc.write(out)
    return out.getvalue().encode("utf-8")


def svg_text(sheet: StockSheet, *, title: str = "") -> str:
    """One stock sheet as SVG at 1:1 in mm (y up in the drawing's numbers, flipped for
    SVG): the sheet in grey, cut lines black, far-face lines red, labels blue."""
    from xml.sax.saxutils import escape

    w, h = sheet.width, sheet.height
    size = text_height(sheet)

    def path(ring: np.ndarray) -> str:
        pts = " L ".join(f"{x:.3f} {h - y:.3f}" for x, y in ring.tolist())
        return f"M {pts} Z"

    items = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.3f}mm" height="{h:.3f}mm" '
        f'viewBox="0 0 {w:.3f} {h:.3f}">',
        f"<title>{escape(title)}</title>",
        f'<rect x="0" y="0" width="{w:.3f}" height="{h:.3f}" fill="none" stroke="#999" '
        'stroke-width="1"/>',
    ]
    for placed in sheet.parts:
        cut = " ".join(path(r) for r in _rings(placed.cut))
        far = " ".join(path(r) for r in _rings(placed.far))
        items.append(
            f'<path d="{cut}" fill="none" stroke="#000" stroke-width="0.5" fill-rule="evenodd"/>'
        )
        if far:
            items.append(
                f'<path d="{far}" fill="none" stroke="#d62728" stroke-width="0.4" '
                'stroke-dasharray="4 2" fill-rule="evenodd"/>'
            )
        cx, cy = placed.centre
        items.append(
            f'<text x="{cx:.2f}" y="{h - cy:.2f}" font-size="{size:.2f}" fill="#1f3fbf" '
            f'text-anchor="middle" dominant-baseline="middle">P{placed.part.panel}</text>'
        )
        for x, y, text in placed.labels:
            items.append(
                f'<text x="{x:.2f}" y="{h - y:.2f}" font-size="{size * 0.5:.2f}" '
                f'fill="#1f3fbf" text-anchor="middle">{escape(text)}</text>'
            )
    items.append("</svg>")
    return "\n".join(items) + "\n"


def cut_sheet_data(
    fab: Fabrication,
    out: Path,
    name: str,
    *,
    width: float,
    height: float,
    gap: float,
    title: str = "",
    settings: Settings = DEFAULTS,
) -> tuple[list[tuple[Path, str | bytes]], list[StockSheet]]:
    """Nest the panels onto ``width`` x ``height`` mm stock (:func:`nest`): the files
    ``NAME_sheet_NN.dxf`` and ``.svg`` per sheet (``NAME_oversize_NN`` for a part larger
    than the stock) as (path in ``out``, data), and the sheets."""
    from rigidfold.fabricate.progress import step

    step(f"nesting the cut sheets of {fab.panels.n} panels", fab.panels.n, settings=settings)
    sheets = nest(parts(fab), width, height, gap, settings=settings)
    files: list[tuple[Path, str | bytes]] = []
    stock = oversize = 0
    for sheet in sheets:
        if sheet.oversize:
            oversize += 1
            stem = f"{name}_oversize_{oversize:02d}"
        else:
            stock += 1
            stem = f"{name}_sheet_{stock:02d}"
        label = f"{title} {stem} ({sheet.width:.0f} x {sheet.height:.0f} mm)".strip()
        files.append((out / f"{stem}.dxf", dxf_bytes(sheet, title=label)))
        files.append((out / f"{stem}.svg", svg_text(sheet, title=label)))
    return files, sheets


def write_cut_sheets(
    fab: Fabrication,
    out: Path,
    name: str,
    *,
    width: float,
    height: float,
    gap: float,
    title: str = "",
    settings: Settings = DEFAULTS,
) -> tuple[list[Path], list[StockSheet]]:
    """Nest the panels and write their sheets together (:func:`cut_sheet_data`,
    :func:`rigidfold.io.files.write_together`); returns the files and the sheets."""
    files, sheets = cut_sheet_data(
        fab, out, name, width=width, height=height, gap=gap, title=title, settings=settings
    )
    return write_together(files), sheets


def sheet_files(directory: str | os.PathLike, name: str) -> list[str]:
    """The names of the cut sheets of design ``name`` in ``directory`` (:data:`SHEET_FILE`:
    left there by an earlier ``fabricate``; a symbolic link of such a name counts, a
    directory does not), sorted; ``[]`` when it cannot be listed."""
    pattern = re.compile(SHEET_FILE.format(re.escape(name)), re.DOTALL)
    try:
        entries = list(os.scandir(os.fsdecode(directory)))
    except OSError:
        return []
    return sorted(
        e.name for e in entries if pattern.fullmatch(e.name) and not e.is_dir(follow_symlinks=False)
    )


def sheets_summary(sheets: list[StockSheet]) -> dict:
    """JSON-ready: the stock sheets, how they were nested (``"boxes"`` or ``"outlines"``,
    :func:`nest`), and which panel is on which."""
    stock = [s for s in sheets if not s.oversize]
    return {
        "sheets": len(stock),
        "nested_by": stock[0].nesting if stock else None,
        "oversize_panels": [p.part.panel for s in sheets if s.oversize for p in s.parts],
        "panels_on_sheet": [[p.part.panel for p in s.parts] for s in sheets if not s.oversize],
    }
