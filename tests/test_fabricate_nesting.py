"""Nesting the cut sheets by the parts' true outlines (fabricate/nesting.py, cutsheets.nest):
checked on the placed geometry itself, independently of the nester's own no-fit polygons."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.cutsheets import (
    Label,
    Part,
    Stock,
    _fit,
    nest,
    nest_boxes,
    nest_by_outlines,
    sheets_summary,
)
from rigidfold.fabricate.nesting import Convex, convex_pieces, minkowski

W, H, GAP = 2440.0, 1220.0, 10.0


def _part(k: int, ring) -> Part:
    """A part of outline ``ring`` (counter-clockwise), a label at its centroid, turned to its
    smallest box like the panels' parts."""
    cut = shapely.Polygon(ring)
    c = cut.centroid
    return _fit(
        [Part(k, cut, shapely.Polygon(), (Label(c.x, c.y, f"E{k}", 1.0, 0.0, 10.0),), 0.0, 0.0)]
    )[0]


def _signed(geometry) -> float:
    """The signed area of the outer rings (counter-clockwise > 0): a mirror flips it."""
    total = 0.0
    for poly in getattr(geometry, "geoms", [geometry]):
        xy = np.asarray(poly.exterior.coords)
        total += 0.5 * float(np.sum(xy[:-1, 0] * xy[1:, 1] - xy[1:, 0] * xy[:-1, 1]))
    return total


def check_nesting(sheets, items, width=W, height=H, gap=GAP):
    """Every part with an outline placed once; on stock sheets inside the sheet, ``gap`` from
    its edges and from every other part's cut outline; turned and moved only (same area,
    same signed area, labels kept the same distance from the outline)."""
    placed = [p for s in sheets for p in s.parts]
    assert sorted(p.part.panel for p in placed) == sorted(
        p.panel for p in items if not p.cut.is_empty
    )
    for sheet in sheets:
        for a in sheet.parts:
            x0, y0, x1, y1 = a.cut.bounds
            if not sheet.oversize:
                assert (sheet.width, sheet.height) == (width, height)
            assert min(x0, y0) >= gap - 1e-6
            assert x1 <= sheet.width - gap + 1e-6 and y1 <= sheet.height - gap + 1e-6
            assert a.cut.area == pytest.approx(a.part.cut.area, rel=1e-9)
            assert _signed(a.cut) == pytest.approx(_signed(a.part.cut), rel=1e-9)
            assert len(a.labels) == len(a.part.labels)
            for (x, y, t, *_), (u, v, s, *_) in zip(a.labels, a.part.labels, strict=True):
                assert t == s
                assert a.cut.distance(shapely.Point(x, y)) == pytest.approx(
                    a.part.cut.distance(shapely.Point(u, v)), abs=1e-6
                )
        for a, b in itertools.combinations(sheet.parts, 2):
            assert a.cut.distance(b.cut) >= gap - 1e-6


def _placements(sheets):
    return [[(p.part.panel, p.cut.wkt, p.labels) for p in s.parts] for s in sheets]


@pytest.fixture(scope="module")
def triangles():
    """24 isosceles triangles 600 mm wide, 500 mm high: pairing them along their bases saves
    no box area, so the boxes take one triangle each (6 a sheet), while by their outlines
    they fit up and down in rows."""
    return [_part(k, [(0, 0), (600, 0), (300, 500)]) for k in range(24)]


def test_outlines_use_fewer_sheets_than_boxes(triangles):
    boxes = nest_boxes(triangles, Stock(W, H, GAP))
    outlines = nest_by_outlines(triangles, Stock(W, H, GAP))
    assert outlines is not None
    check_nesting(outlines, triangles)
    check_nesting(boxes, triangles)
    assert len(outlines) < len(boxes)
    kept = nest(triangles, Stock(W, H, GAP))
    assert _placements(kept) == _placements(outlines)
    summary = sheets_summary(kept)
    assert summary["nested_by"] == "outlines" and summary["sheets"] == len(outlines)


def test_nesting_is_deterministic(triangles):
    mixed = triangles[:6] + [
        _part(30 + k, [(0, 0), (200 + 90 * k, 0), (200 + 90 * k, 150 + 40 * k), (0, 300)])
        for k in range(8)
    ]
    first = nest(mixed, Stock(W, H, GAP))
    check_nesting(first, mixed)
    assert _placements(first) == _placements(nest(mixed, Stock(W, H, GAP)))


def test_concave_parts_and_oversize(triangles):
    """An L-shaped part (cut into triangles) keeps the gap too; a part larger than the stock
    goes on its own sheet, as with the boxes."""
    ell = [(0, 0), (900, 0), (900, 200), (200, 200), (200, 700), (0, 700)]
    big = [(0, 0), (3000, 0), (3000, 500), (0, 500)]
    items = [_part(k, ell) for k in range(5)] + triangles[:4] + [_part(99, big)]
    sheets = nest(items, Stock(W, H, GAP))
    check_nesting(sheets, items)
    assert [p.part.panel for s in sheets if s.oversize for p in s.parts] == [99]
    stock = [s for s in sheets if not s.oversize]
    assert len(stock) <= len([s for s in nest_boxes(items, Stock(W, H, GAP)) if not s.oversize])
    assert len(convex_pieces(items[0].cut, DEFAULTS.fabricate.nest_concavity)) > 1


def test_nest_parts_zero_keeps_the_boxes(triangles):
    settings = DEFAULTS.with_(fabricate_nest_parts=0)
    kept = nest(triangles, Stock(W, H, GAP), settings=settings)
    assert _placements(kept) == _placements(nest_boxes(triangles, Stock(W, H, GAP)))
    assert sheets_summary(kept)["nested_by"] == "boxes"


def test_nest_settings_are_checked():
    with pytest.raises(RigidfoldError, match="fabricate_nest_gap_sides"):
        DEFAULTS.with_(fabricate_nest_gap_sides=7)
    with pytest.raises(RigidfoldError, match="fabricate_nest_round"):
        DEFAULTS.with_(fabricate_nest_round=0.0)


def test_minkowski_is_the_hull_of_the_sums():
    """The edge-merged Minkowski sum of convex polygons is the convex hull of all pairwise
    vertex sums (random convex polygons, seeded)."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        polys = []
        for n in (3, 5, 8):
            phi = np.sort(rng.uniform(0, 2 * math.pi, n))
            ring = rng.uniform(50, 300) * np.column_stack([np.cos(phi), np.sin(phi)])
            polys.append(Convex.of(ring + rng.uniform(-500, 500, 2)))
        other = Convex.of(-polys[0].ring[::-1])
        ks = max(len(p.edges) for p in polys[1:])
        starts = np.array([p.start for p in polys[1:]])
        edges = np.zeros((2, ks, 2))
        angles = np.full((2, ks), 10.0)
        for i, p in enumerate(polys[1:]):
            edges[i, : len(p.edges)] = p.edges
            angles[i, : len(p.angles)] = p.angles
        for ring, p in zip(minkowski(starts, edges, angles, other), polys[1:], strict=True):
            sums = (p.ring[:, None, :] + other.ring[None, :, :]).reshape(-1, 2)
            hull = shapely.convex_hull(shapely.multipoints(sums))
            got = shapely.Polygon(ring)
            assert got.is_valid
            assert shapely.symmetric_difference(got, hull).area <= 1e-9 * hull.area
