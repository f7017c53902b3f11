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
from typing import NamedTuple

import numpy as np
import shapely
import shapely.errors
import shapely.geometry
import shapely.ops

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.exports.sheet import min_area_angle
from rigidfold.fabricate.build import Fabrication
from rigidfold.io.files import text_bytes

MM = 1000.0

SHEET_FILE = r"{}_(?:sheet|oversize)_[0-9]{{2,}}\.(?:dxf|svg)"
"""The names of the sheets :func:`cut_sheet_data` makes (a regular expression, ``{}`` for
the design's name, escaped): ``NAME_sheet_NN`` and ``NAME_oversize_NN``, ``.dxf`` and
``.svg``."""


class Label(NamedTuple):
    """A bevelled edge's label on a part, mm: ``text`` centred at (x, y), reading along the
    unit direction (ux, uy) (the edge's, turned so that it never reads upside down),
    ``size`` high (fitted to the edge's length and kept off the other labels)."""

    x: float
    y: float
    text: str
    ux: float
    uy: float
    size: float


LABEL_SIZE = 10.0
"""Largest height of an edge label on a nested sheet, mm (the panel numbers: twice it)."""

LABEL_LEAST = 2.0
"""Smallest height of an edge label, mm: a label on a shorter edge overhangs it."""

CHAR_WIDTH = 0.62
"""Width of a character of the labels' sans-serif font, in text heights (an estimate that
errs wide, used to keep labels apart)."""


def _labels_moved(labels, matrix: np.ndarray, offset) -> tuple[Label, ...]:
    """``labels`` with every point p (row) taken to ``p @ matrix + offset`` and every
    direction to ``d @ matrix`` (turned back where it would read upside down)."""
    out = []
    for lab in labels:
        q = np.array([lab.x, lab.y]) @ matrix + offset
        d = np.array([lab.ux, lab.uy]) @ matrix
        if d[0] < -1e-9 or (abs(d[0]) <= 1e-9 and d[1] < 0):
            d = -d
        out.append(Label(float(q[0]), float(q[1]), lab.text, float(d[0]), float(d[1]), lab.size))
    return tuple(out)


def _label_box(lab: Label) -> shapely.Geometry:
    """The rectangle a label covers (its estimated width x its height), mm."""
    half = 0.5 * CHAR_WIDTH * lab.size * len(lab.text)
    d = np.array([lab.ux, lab.uy])
    n = np.array([-d[1], d[0]]) * 0.5 * lab.size
    c = np.array([lab.x, lab.y])
    return shapely.Polygon([c - half * d - n, c + half * d - n, c + half * d + n, c - half * d + n])


def _edge_labels(centre: np.ndarray, edges, texts, keep_off: shapely.Geometry) -> tuple[Label, ...]:
    """The labels ``texts`` of the edges ``edges`` ((a, b) points, mm, in a part's own
    frame; ``centre``: a point inside it), each along its edge, inside the part, as high as
    :data:`LABEL_SIZE` and the edge's length allow; labels that would overlap each other or
    ``keep_off`` (the panel's number) are made smaller together (down to
    :data:`LABEL_LEAST`) and then, where they still do, moved further inside."""
    labels = []
    for (a, b), text in zip(edges, texts, strict=True):
        d = b - a
        length = float(np.hypot(*d))
        if length <= 0:
            continue
        d = d / length
        n = np.array([-d[1], d[0]])
        if (centre - a) @ n < 0:
            n = -n
        size = min(LABEL_SIZE, 0.8 * length / (CHAR_WIDTH * len(text)))
        size = max(size, LABEL_LEAST)
        labels.append([a, b, d, n, text, size, 0.9])
    for _ in range(8):
        made = []
        for a, b, d, n, text, size, depth in labels:
            at = 0.5 * (a + b) + depth * size * n
            made.append(Label(float(at[0]), float(at[1]), text, float(d[0]), float(d[1]), size))
        made = list(_labels_moved(made, np.eye(2), (0.0, 0.0)))
        boxes = [_label_box(lab) for lab in made]
        crowded = {
            i
            for i in range(len(boxes))
            for j in range(len(boxes))
            if i != j and boxes[i].intersects(boxes[j])
        } | {i for i, box in enumerate(boxes) if box.intersects(keep_off)}
        if not crowded:
            break
        for i in crowded:
            if labels[i][5] > LABEL_LEAST:
                labels[i][5] = max(0.8 * labels[i][5], LABEL_LEAST)
            else:
                labels[i][6] += 1.2
    return tuple(made) if labels else ()


@dataclass(frozen=True, eq=False)
class Part:
    """One panel drawn flat, millimetres, its bounding box starting at (0, 0).

    panel : int; cut : shapely geometry of the surface face; far : of the far face (may be
    empty); labels : a :class:`Label` of each bevelled edge; width, height : its box;
    mark : the panel's number ``P K`` (drawn level on the sheet, at its point, its size),
    None for an empty part.
    """

    panel: int
    cut: shapely.Geometry
    far: shapely.Geometry
    labels: tuple[Label, ...]
    width: float
    height: float
    mark: Label | None = None


@dataclass(frozen=True, eq=False)
class Placed:
    """A part on a sheet: its geometry moved there, mm."""

    part: Part
    cut: shapely.Geometry
    far: shapely.Geometry
    labels: tuple[Label, ...]
    centre: tuple[float, float]


@dataclass(frozen=True)
class Stock:
    """What parts are nested onto (:func:`nest`, :func:`nest_boxes`,
    :func:`nest_by_outlines`): stock sheets ``width`` x ``height`` mm, the parts ``gap`` mm
    apart and from the sheets' edges."""

    width: float
    height: float
    gap: float


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
        flat = (p.pattern.coords - origin) @ np.column_stack([a1, a2]) * MM
        edges, texts = [], []
        for h in p.hinges_of[k].tolist():
            u, v = p.hinge_vertices[h].tolist()
            edges.append((flat[u], flat[v]))
            texts.append(f"E{int(p.hinge_edges[h])} {math.degrees(s.bevel[h]):.1f}°")
        mark = _mark(cut, f"P{k}")
        keep_off = (
            shapely.Point(mark.x, mark.y).buffer(0.5 * CHAR_WIDTH * mark.size * len(mark.text))
            if mark is not None
            else shapely.Polygon()
        )
        inside = np.array([mark.x, mark.y]) if mark is not None else np.zeros(2)
        labels = _edge_labels(inside, edges, texts, keep_off)
        part = Part(k, cut, far, labels, 0.0, 0.0, mark)
        out.append(part if cut.is_empty else _fit([part])[0])
    return out


def _mark(cut: shapely.Geometry, text: str) -> Label | None:
    """A part's number ``text`` at the point of ``cut`` farthest from its outline (shapely's
    ``polylabel``), as high as :data:`LABEL_SIZE` twice, less where the part is small; None
    for an empty part."""
    if cut.is_empty or cut.geom_type != "Polygon":
        return None
    at = shapely.ops.polylabel(cut, tolerance=max(1e-3, 0.01 * math.sqrt(cut.area)))
    room = cut.exterior.distance(at)
    size = min(2 * LABEL_SIZE, 0.25 * math.sqrt(cut.area), 1.6 * room / (CHAR_WIDTH * len(text)))
    return Label(float(at.x), float(at.y), text, 1.0, 0.0, max(size, LABEL_LEAST))


def _mark_moved(mark: Label | None, matrix: np.ndarray, offset) -> Label | None:
    return None if mark is None else _labels_moved((mark,), matrix, offset)[0]


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
        labels = _labels_moved(m.labels, turn, shift)
        out.append(
            Part(
                m.panel,
                _moved(m.cut, turn, shift),
                _moved(m.far, turn, shift),
                labels,
                float(x1 - x0),
                float(y1 - y0),
                _mark_moved(m.mark, turn, shift),
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


Sides = tuple[tuple[np.ndarray, np.ndarray, float], tuple[np.ndarray, np.ndarray, float]]
"""The longest sides of two parts' convex hulls (:func:`_longest_side`)."""


def _placements(gap: float, sides: Sides) -> tuple[np.ndarray, list[np.ndarray]]:
    """(the turn, the two shifts) that put the second part's longest hull side along the
    first's (``sides``), ``gap`` away on the other side, its ends at either end: a point
    ``p`` of the second part goes to ``p @ turn + shift``."""
    (a, b, _), (c, d, _) = sides
    e = (b - a) / np.linalg.norm(b - a)
    normal = np.array([e[1], -e[0]])  # right of a -> b: away from first
    angle = math.atan2(*(a - b)[::-1]) - math.atan2(*(d - c)[::-1])
    co, si = math.cos(angle), math.sin(angle)
    turn = np.array([[co, si], [-si, co]])
    return turn, [anchor + gap * normal - point @ turn for anchor, point in ((b, c), (a, d))]


def _joined(first: Part, second: Part, gap: float, sides: Sides) -> list[list[Part]]:
    """``second`` turned and moved so that the longest side of its convex hull runs along
    that of ``first``'s (``sides``: both, :func:`_longest_side`), ``gap`` away on the other
    side, its ends at either end (:func:`_placements`): the two pairs, fitted (:func:`_fit`).
    The hulls lie on the two sides of a strip ``gap`` wide, so the parts keep the gap."""
    turn, shifts = _placements(gap, sides)
    out = []
    for shift in shifts:
        moved = Part(
            second.panel,
            _moved(second.cut, turn, shift),
            _moved(second.far, turn, shift),
            _labels_moved(second.labels, turn, shift),
            0.0,
            0.0,
            _mark_moved(second.mark, turn, shift),
        )
        out.append(_fit([first, moved]))
    return out


def _box_of(ring: np.ndarray) -> tuple[float, float]:
    """(longer, shorter) side of the smallest bounding rectangle of the points ``ring``
    (n, 2), as :func:`_fit` turns a part to it."""
    angle = min_area_angle(ring)
    c, sn = math.cos(angle), math.sin(angle)
    xy = ring @ np.array([[c, sn], [-sn, c]])
    w, h = np.ptp(xy, axis=0)
    return float(max(w, h)), float(min(w, h))


def _joined_boxes(
    first: np.ndarray, second: np.ndarray, gap: float, sides: Sides
) -> list[tuple[float, float]]:
    """The boxes of the two pairs :func:`_joined` makes of parts of hull points ``first``
    and ``second`` (n, 2), computed on those points alone (the same turns and shifts)."""
    turn, shifts = _placements(gap, sides)
    return [_box_of(np.vstack([first, second @ turn + shift])) for shift in shifts]


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
    hulls = [np.asarray(shapely.get_coordinates(shapely.convex_hull(p.cut))) for p in live]
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
            both = _joined_boxes(hulls[a], hulls[b], gap, (longest[a], longest[b]))
            for way, (w, h) in enumerate(both):
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


def nest(items: list[Part], stock: Stock, *, settings: Settings = DEFAULTS) -> list[StockSheet]:
    """Pack ``items`` onto ``stock`` (see the module's text): by their boxes
    (:func:`nest_boxes`) and by their outlines (:func:`nest_by_outlines`, up to
    ``fabricate_nest_parts`` parts), the one on fewer stock sheets kept, then the one that
    uses less of the last sheet's width, the boxes where both are alike. Parts with an
    empty outline are left out."""
    boxes = nest_boxes(items, stock, settings=settings)
    sheets = [s for s in boxes if not s.oversize]
    panels = {p.part.panel for s in sheets for p in s.parts}
    on_stock = [p for p in items if p.panel in panels]  # each in its own frame, not its pair's
    if not on_stock or len(on_stock) > settings.fabricate.nest_parts:
        return boxes
    try:
        outlines = nest_by_outlines(on_stock, stock, settings=settings)
    except shapely.errors.GEOSException:  # a degenerate outline: the boxes still hold
        outlines = None
    if outlines is None or _usage(outlines) >= _usage(sheets):
        return boxes
    return outlines + [s for s in boxes if s.oversize]


def _usage(sheets: list[StockSheet]) -> tuple[int, float]:
    """(how many sheets, how far the last one is used along its width, mm)."""
    last = max((p.cut.bounds[2] for p in sheets[-1].parts), default=0.0) if sheets else 0.0
    return len(sheets), round(last, 3)


def nest_by_outlines(
    items: list[Part], stock: Stock, *, settings: Settings = DEFAULTS
) -> list[StockSheet] | None:
    """``items`` placed by their true outlines on ``stock``
    (:func:`rigidfold.fabricate.nesting.nest_outlines`: turned, never mirrored); ``None``
    where one of them fits on no sheet."""
    from rigidfold.fabricate.nesting import nest_outlines

    width, height = stock.width, stock.height
    spots = nest_outlines([p.cut for p in items], width, height, stock.gap, settings=settings)
    if spots is None:
        return None
    placed: dict[int, list[Placed]] = {}
    for part, spot in zip(items, spots, strict=True):
        c, s = math.cos(spot.angle), math.sin(spot.angle)
        turn = np.array([[c, s], [-s, c]])  # row vectors: x @ turn turns x by the angle
        placed.setdefault(spot.sheet, []).append(_placed(part, turn, (spot.x, spot.y)))
    return [StockSheet(width, height, tuple(placed[b]), nesting="outlines") for b in sorted(placed)]


def nest_boxes(
    items: list[Part], stock: Stock, *, settings: Settings = DEFAULTS
) -> list[StockSheet]:
    """Pack ``items`` by their boxes (their pairs' boxes, :func:`group`) onto ``stock`` by
    ``rectpack`` (:func:`_pack`); a part larger than the stock on an oversize sheet of its
    own after them."""
    width, height, gap = stock.width, stock.height, stock.gap
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
    moved = _labels_moved(part.labels, m, offset)
    mark = _mark_moved(part.mark, m, offset)
    c = cut.representative_point() if mark is None else shapely.Point(mark.x, mark.y)
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
    """Height of the legend's text below a sheet, mm."""
    return max(min(sheet.width, sheet.height) / 60.0, 5.0)


def panel_text_height(placed: Placed) -> float:
    """Height of a part's number ``P K`` (:func:`_mark`), mm."""
    mark = placed.part.mark
    return 2 * LABEL_SIZE if mark is None else mark.size


LEGEND = (
    ("cut", "cut line: the panel's face on the design surface, cut through the sheet"),
    ("far", "far face: where the bevels and reliefs end (bevel from the cut line to it)"),
    ("panel", "P12: panel 12 (panel_12 of the 3D files, the schedules)"),
    ("edge", "E34 64.2°: hinge of crease 34, bevel 64.2° between bevel and surface"),
    ("", "(tilt the saw blade by 90° minus the bevel); all lengths in mm at 1:1"),
)
"""The rows of the legend below a nested sheet: (sample, text)."""


def legend_height(sheet: StockSheet) -> float:
    """Height of the band below a sheet that holds its legend and scale bar, mm."""
    return (1.6 * (len(LEGEND) + 1)) * text_height(sheet)


def _nice_length(limit: float) -> float:
    """The largest 1, 2 or 5 times a power of ten that is at most ``limit`` (> 0), mm."""
    power = 10.0 ** math.floor(math.log10(limit))
    return max(m * power for m in (1, 2, 5) if m * power <= limit)


def _scale_bar(sheet: StockSheet) -> tuple[float, float]:
    """(length, left end) of a sheet's scale bar, mm: a round length near a quarter of the
    sheet's width, right of the legend and at least 60 % of the way across."""
    f = text_height(sheet)
    legend = 7 * f + CHAR_WIDTH * 0.8 * f * max(len(text) for _, text in LEGEND)
    return _nice_length(sheet.width / 4), max(0.6 * sheet.width, legend)


def _degrees(lab: Label) -> float:
    """A label's direction as an angle, degrees counter-clockwise (y up)."""
    return math.degrees(math.atan2(lab.uy, lab.ux))


def dxf_bytes(sheet: StockSheet, *, title: str = "") -> bytes:
    """One stock sheet as DXF (R2010, mm): layers SHEET, CUT, BEVEL, LABELS, and LEGEND (the
    legend and a scale bar below the sheet)."""
    import io

    import ezdxf
    from ezdxf import units
    from ezdxf.enums import TextEntityAlignment

    doc = ezdxf.new("R2010", setup=True)
    doc.units = units.MM
    doc.header["$INSUNITS"] = units.MM
    for name, colour in (("SHEET", 8), ("CUT", 7), ("BEVEL", 1), ("LABELS", 5), ("LEGEND", 8)):
        doc.layers.add(name, color=colour)
    doc.linetypes.add("DASHED2", pattern=[6.0, 4.0, -2.0], description="- - -")
    msp = doc.modelspace()
    msp.add_lwpolyline(
        [(0, 0), (sheet.width, 0), (sheet.width, sheet.height), (0, sheet.height)],
        close=True,
        dxfattribs={"layer": "SHEET"},
    )
    centre = TextEntityAlignment.MIDDLE_CENTER
    for placed in sheet.parts:
        for ring in _rings(placed.cut):
            msp.add_lwpolyline(ring.tolist(), close=True, dxfattribs={"layer": "CUT"})
        for ring in _rings(placed.far):
            msp.add_lwpolyline(
                ring.tolist(), close=True, dxfattribs={"layer": "BEVEL", "linetype": "DASHED2"}
            )
        msp.add_text(
            f"P{placed.part.panel}",
            height=panel_text_height(placed),
            dxfattribs={"layer": "LABELS"},
        ).set_placement(placed.centre, align=centre)
        for lab in placed.labels:
            msp.add_text(
                lab.text,
                height=lab.size,
                rotation=_degrees(lab),
                dxfattribs={"layer": "LABELS"},
            ).set_placement((lab.x, lab.y), align=centre)
    f = text_height(sheet)
    for i, (_, text) in enumerate(LEGEND):
        msp.add_text(text, height=f * 0.8, dxfattribs={"layer": "LEGEND"}).set_placement(
            (f, -1.6 * f * (i + 1))
        )
    bar, x0 = _scale_bar(sheet)
    y0 = -1.6 * f
    msp.add_lwpolyline(
        [(x0, y0 + f / 2), (x0, y0), (x0 + bar, y0), (x0 + bar, y0 + f / 2)],
        dxfattribs={"layer": "LEGEND"},
    )
    msp.add_text(f"{bar:g} mm", height=f * 0.8, dxfattribs={"layer": "LEGEND"}).set_placement(
        (x0 + bar / 2, y0 - f), align=centre
    )
    if title:
        msp.add_text(title, height=f * 0.5, dxfattribs={"layer": "LABELS"}).set_placement(
            (f, sheet.height - f)
        )
    out = io.StringIO()
    doc.write(out)
    return text_bytes(out.getvalue())


def svg_text(sheet: StockSheet, *, title: str = "") -> str:
    """One stock sheet as SVG at 1:1 in mm (y up in the drawing's numbers, flipped for
    SVG): the sheet in grey, cut lines black, far-face lines red and dashed, labels blue
    (each edge's along its edge), and below the sheet a legend and a scale bar."""
    from xml.sax.saxutils import escape

    w, h = sheet.width, sheet.height
    f = text_height(sheet)
    total = h + legend_height(sheet)
    bar, x0 = _scale_bar(sheet)
    wide = max(w, x0 + max(bar, 45 * CHAR_WIDTH * 0.8 * f))

    def path(ring: np.ndarray) -> str:
        pts = " L ".join(f"{x:.3f} {h - y:.3f}" for x, y in ring.tolist())
        return f"M {pts} Z"

    items = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{wide:.3f}mm" height="{total:.3f}mm" '
        f'viewBox="0 0 {wide:.3f} {total:.3f}">',
        f"<title>{escape(title)}</title>",
        f'<rect x="0" y="0" width="{w:.3f}" height="{h:.3f}" fill="none" stroke="#999" '
        'stroke-width="1"/>',
    ]
    font = 'font-family="sans-serif" fill="#1f3fbf" text-anchor="middle"'
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
            f'<text x="{cx:.2f}" y="{h - cy:.2f}" font-size="{panel_text_height(placed):.2f}" '
            f'{font} dominant-baseline="middle">P{placed.part.panel}</text>'
        )
        for lab in placed.labels:
            x, y = lab.x, h - lab.y
            items.append(
                f'<text x="{x:.2f}" y="{y:.2f}" font-size="{lab.size:.2f}" {font} '
                f'dominant-baseline="middle" transform="rotate({-_degrees(lab):.2f} {x:.2f} '
                f'{y:.2f})">{escape(lab.text)}</text>'
            )
    samples = {
        "cut": 'stroke="#000" stroke-width="0.5"',
        "far": 'stroke="#d62728" stroke-width="0.4" stroke-dasharray="4 2"',
    }
    items.append(f'<g id="LEGEND" font-family="sans-serif" font-size="{0.8 * f:.2f}">')
    for i, (sample, text) in enumerate(LEGEND):
        y = h + 1.6 * f * (i + 1)
        if sample in samples:
            items.append(
                f'<line x1="{f:.2f}" y1="{y:.2f}" x2="{4 * f:.2f}" y2="{y:.2f}" {samples[sample]}/>'
            )
        label = escape(text.split(": ", 1)[0]) if sample in ("panel", "edge") else ""
        if label:
            items.append(
                f'<text x="{2.5 * f:.2f}" y="{y:.2f}" fill="#1f3fbf" text-anchor="middle" '
                f'dominant-baseline="middle">{label}</text>'
            )
        rest = text.split(": ", 1)[1] if label else text
        items.append(
            f'<text x="{5 * f:.2f}" y="{y:.2f}" dominant-baseline="middle">{escape(rest)}</text>'
        )
    y0 = h + 1.6 * f * 2
    items += [
        f'<path d="M {x0:.2f} {y0 - f / 2:.2f} V {y0:.2f} H {x0 + bar:.2f} V {y0 - f / 2:.2f}" '
        'fill="none" stroke="#333" stroke-width="1"/>',
        f'<text x="{x0 + bar / 2:.2f}" y="{y0 + 1.2 * f:.2f}" text-anchor="middle" '
        f'dominant-baseline="middle">{bar:g} mm</text>',
        f'<text x="{x0:.2f}" y="{y0 + 2.8 * f:.2f}" dominant-baseline="middle">'
        f"stock sheet {w:.0f} x {h:.0f} mm, scale 1:1</text>",
        "</g>",
    ]
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
    sheets = nest(parts(fab), Stock(width, height, gap), settings=settings)
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
