"""Crease patterns drawn in SVG (Origami Simulator's colours): rigidfold.io.read_svg."""

from __future__ import annotations

import math
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import shapely

from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.io import UNITS, SvgDrawing, read_svg
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.triangulate import orient_up, triangulate_polygons

DATA = Path(__file__).parent / "data" / "origami_simulator"

SQUARE = '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>'
"""The boundary of most cases: a 100 x 100 square, corners (0, 0) to (100, 100) in SVG."""


def write(tmp_path: Path, body: str, size: str = 'width="100" height="100"') -> Path:
    path = tmp_path / "pattern.svg"
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" {size}>{body}</svg>\n')
    return path


def points(xy: np.ndarray) -> list[tuple[float, float]]:
    """Vertex positions as a sorted list, rounded against round-off of transforms."""
    return sorted((round(x, 9) + 0.0, round(y, 9) + 0.0) for x, y in xy)


def counts(drawing: SvgDrawing) -> tuple[int, int, int]:
    """(vertices, edges, faces)."""
    return len(drawing.xy), len(drawing.edges), len(drawing.polygons)


def shortest_edge(drawing: SvgDrawing) -> float:
    """The length of the drawing's shortest edge, in drawing units."""
    xy, edges = drawing.xy, drawing.edges
    return float(np.linalg.norm(xy[edges[:, 0]] - xy[edges[:, 1]], axis=1).min())


OLD_MERGE = {"svg_merge_tol": 1e-4}
"""The default svg_merge_tol before issue 39 item 19 (5e-4 since): near misses of 2e-4 to 4e-4
of the diagonal, as in Origami Simulator's examples drawn in Illustrator, stay apart."""


def check_planar(drawing: SvgDrawing) -> None:
    """What every drawing read must satisfy: faces counter-clockwise and simple, their
    sides edges, every edge a side of one face (boundary) or two (creases), a disc."""
    xy, edges = drawing.xy, drawing.edges
    assert xy.shape == (len(xy), 2) and xy.dtype == np.float64
    assert edges.shape == (len(edges), 2) and edges.dtype == np.int64
    assert len(drawing.assignment) == len(edges)
    assert drawing.fold_angles is not None and drawing.fold_angles.shape == (len(edges),)
    keys = {frozenset(e) for e in edges.tolist()}
    assert len(keys) == len(edges)
    sides: Counter = Counter()
    for polygon in drawing.polygons:
        assert len(polygon) >= 3 and len(set(polygon)) == len(polygon)
        x, y = xy[polygon].T
        assert np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0
        sides.update(frozenset(p) for p in zip(polygon, np.roll(polygon, -1).tolist(), strict=True))
    assert set(sides) == keys
    for (u, v), letter in zip(edges.tolist(), drawing.assignment, strict=True):
        assert sides[frozenset((u, v))] == (1 if letter == "B" else 2)
    assert len(xy) - len(edges) + len(drawing.polygons) == 1
    boundary = shapely.polygonize(
        shapely.linestrings(xy[edges[np.array(drawing.assignment) == "B"]])
    )
    faces = sum(shapely.Polygon(xy[p]).area for p in drawing.polygons)
    assert faces == pytest.approx(boundary.area, rel=1e-12)
    assert set(np.unique(edges)) == set(range(len(xy)))


# --------------------------------------------------------------------------- drawings
def t_junction(end: str, y: float) -> tuple:
    """A case of :data:`CASES`: a valley from the left side ending (at ``end``) on a vertical
    mountain at x = 50, whose vertex there gets ``y`` (y up)."""
    return (
        SQUARE
        + '<line x1="50" y1="0" x2="50" y2="100" stroke="#f00"/>'
        + f'<line x1="0" y1="50" {end} stroke="#00f"/>',
        'width="100" height="100"',
        (8, 10, 3),
        {"B": 7, "M": 2, "V": 1},
        [(0, -100), (0, -50), (0, 0), (50, -100), (50, y), (50, 0), (100, -100), (100, 0)],
    )


CASES = {
    "square with one diagonal": (
        SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="#0000ff"/>',
        'width="100" height="100"',
        (4, 5, 2),
        {"B": 4, "V": 1},
        [(0, -100), (0, 0), (100, -100), (100, 0)],
    ),
    "crossing diagonals are split": (
        SQUARE
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>'
        + '<line x1="100" y1="0" x2="0" y2="100" stroke="rgb(0, 0, 255)"/>',
        'width="100" height="100"',
        (5, 8, 4),
        {"B": 4, "M": 2, "V": 2},
        [(0, -100), (0, 0), (50, -50), (100, -100), (100, 0)],
    ),
    "T-junction": t_junction('x2="50" y2="50"', -50),
    "T-junction missed by 1e-3": t_junction('x2="49.999" y2="50.001"', -50.001),
    "rect boundary away from the origin, polyline crease": (
        '<rect x="10" y="20" width="80" height="40" stroke="black" fill="white"/>'
        + '<polyline points="10,20 50,40 90,20" stroke="blue" fill="none"/>',
        'width="100" height="100"',
        (5, 6, 2),
        {"B": 4, "V": 2},
        [(10, -60), (10, -20), (50, -40), (90, -60), (90, -20)],
    ),
    "Illustrator path with H, V, z and relative moves": (
        '<path fill="#FFFFFF" stroke="#000000" stroke-miterlimit="10" d="M100,100H0V0h100V100z"/>'
        + '<path fill="none" stroke="#FF0000" d="M0,50h100 M50,0v50"/>'
        + '<path fill="none" stroke="#0000FF" d="M50,50v50"/>',
        'width="100px" height="100px" viewBox="0 0 100 100"',
        (9, 12, 4),
        {"B": 8, "M": 3, "V": 1},
        [(x, y) for x in (0, 50, 100) for y in (-100, -50, 0)],
    ),
    "group with a transform and inherited stroke": (
        '<g transform="translate(10, 20) scale(2)" stroke="black" fill="none">'
        + '<polygon points="0,0 40,0 40,40 0,40"/>'
        + '<line x1="0" y1="0" x2="40" y2="40" style="stroke:magenta"/>'
        + '<g style="stroke: yellow"><line x1="40" y1="0" x2="0" y2="40"/></g></g>',
        'width="100" height="100"',
        (5, 8, 4),
        {"B": 4, "U": 2, "F": 2},
        [(10, -100), (10, -20), (50, -60), (90, -100), (90, -20)],
    ),
    "a crease drawn in two straight pieces is one line": (
        SQUARE
        + '<line x1="0" y1="50" x2="50" y2="50" stroke="red"/>'
        + '<line x1="50" y1="50" x2="100" y2="50" stroke="red"/>',
        'width="100" height="100"',
        (6, 7, 2),
        {"B": 6, "M": 1},
        [(0, -100), (0, -50), (0, 0), (100, -100), (100, -50), (100, 0)],
    ),
    "repeats kept once, a crease over the boundary is boundary": (
        SQUARE
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>'
        + '<line x1="100" y1="100" x2="0" y2="0" stroke="red"/>'
        + '<line x1="0" y1="0" x2="100" y2="0" stroke="blue"/>'
        + '<text x="5" y="5">label</text><circle cx="50" cy="20" r="3" fill="black"/>',
        'width="100" height="100"',
        (4, 5, 2),
        {"B": 4, "M": 1},
        [(0, -100), (0, 0), (100, -100), (100, 0)],
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_drawings(tmp_path, case):
    body, size, sizes, letters, xy = CASES[case]
    drawing = read_svg(write(tmp_path, body, size))
    check_planar(drawing)
    assert counts(drawing) == sizes
    assert Counter(drawing.assignment) == letters
    assert points(drawing.xy) == xy
    assert (drawing.unit, drawing.scale) == ("unit", 1.0)


def test_square_with_one_diagonal_in_detail(tmp_path):
    """Vertices in order of first use, edges in drawing order, faces counter-clockwise."""
    drawing = read_svg(write(tmp_path, CASES["square with one diagonal"][0]))
    assert drawing.xy.tolist() == [[0, 0], [100, 0], [100, -100], [0, -100]]
    assert drawing.edges.tolist() == [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]]
    assert drawing.assignment == ["B", "B", "B", "B", "V"]
    assert sorted(sorted(p) for p in drawing.polygons) == [[0, 1, 2], [0, 2, 3]]
    np.testing.assert_array_equal(drawing.fold_angles, [0, 0, 0, 0, 180])


def test_fold_angles_from_opacity(tmp_path):
    """Origami Simulator: stroke opacity (times opacity) is the fraction of 180 degrees;
    valleys positive, mountains negative, facet lines 0, undriven creases NaN."""
    body = (
        SQUARE
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="red" stroke-opacity="0.5"/>'
        + '<line x1="100" y1="0" x2="50" y2="50" stroke="blue" style="opacity:0.25"/>'
        + '<line x1="50" y1="50" x2="0" y2="100" stroke="#ff00ff"/>'
    )
    drawing = read_svg(write(tmp_path, body))
    keys = map(tuple, np.sort(drawing.edges, axis=1).tolist())
    angles = dict(zip(keys, drawing.fold_angles, strict=True))
    assert angles[(0, 4)] == angles[(2, 4)] == -90
    assert angles[(1, 4)] == 45
    assert math.isnan(angles[(3, 4)])
    assert drawing.assignment.count("U") == 1


@pytest.mark.parametrize(
    ("size", "unit", "scale"),
    [
        ('width="200mm" height="100mm" viewBox="0 0 400 200"', "mm", 0.5e-3),
        ('width="20cm" height="10cm" viewBox="0 0 200 100"', "cm", 1e-3),
        ('width="4in" height="2in" viewBox="0 0 4 2"', "in", 0.0254),
        ('width="72pt" height="36pt" viewBox="0 0 72 36"', "pt", 0.0254 / 72),
        ('width="200mm" height="100mm"', "mm", 0.0254 / 96),
        ('width="400px" height="200px" viewBox="0 0 200 100"', "unit", 1.0),
        ("", "unit", 1.0),
    ],
)
def test_units(tmp_path, size, unit, scale):
    """A physical width gives the unit and the metres per user unit; coordinates stay in user
    units (the viewBox's), whatever the width."""
    body = '<rect x="1" y="1" width="2" height="1" stroke="black"/>'
    drawing = read_svg(write(tmp_path, body, size))
    assert drawing.unit == unit and (unit == "unit" or unit in UNITS)
    assert drawing.scale == pytest.approx(scale, rel=1e-12)
    assert points(drawing.xy) == [(1, -2), (1, -1), (3, -2), (3, -1)]


def test_viewbox_offset_is_kept(tmp_path):
    """The drawing's own coordinates: a viewBox that starts at (10, 20) moves nothing."""
    size = 'width="100mm" height="100mm" viewBox="10 20 100 100"'
    body = '<rect x="10" y="20" width="5" height="5" stroke="#000"/>'
    drawing = read_svg(write(tmp_path, body, size))
    assert points(drawing.xy) == [(10, -25), (10, -20), (15, -25), (15, -20)]
    assert (drawing.unit, drawing.scale) == ("mm", pytest.approx(1e-3))


# --------------------------------------------------------------------------- refusals
ERRORS = {
    "no lines": ('<text x="0" y="10">hello</text>', r"no lines drawn: a crease pattern is <line>"),
    "curve with id": (
        SQUARE + '<path id="wave" d="M0,50 Q50,0 100,50" stroke="red" fill="none"/>',
        r'<path id="wave"> has a curved piece \(QuadraticBezier\): creases and the boundary '
        r"must be straight lines",
    ),
    "circle without id": (
        SQUARE + '<circle cx="50" cy="50" r="10" stroke="blue"/>',
        r"<circle> \(drawn element 2\) has a curved piece \(Arc\)",
    ),
    "rounded rect": (
        '<rect x="0" y="0" width="100" height="100" rx="5" stroke="black"/>',
        r"<rect> \(drawn element 1\) has a curved piece \(Arc\)",
    ),
    "no boundary": (
        '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>',
        r"no boundary: no black lines",
    ),
    "lines of no length": (
        '<line x1="5" y1="5" x2="5" y2="5" stroke="black"/>',
        r"the lines drawn have no length",
    ),
    "boundary of no area": (
        '<rect x="50" y="50" width="0.001" height="0.001" stroke="black"/>'
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>',
        r"the boundary \(black\) encloses no area",
    ),
    "boundary not closed": (
        '<polyline points="0,0 100,0 100,100 0,100" stroke="black" fill="none"/>',
        r"the boundary \(black\) is not closed: it ends at \((0, 0|0, 100)\)",
    ),
    "boundary branches": (
        SQUARE + '<line x1="50" y1="0" x2="50" y2="100" stroke="black"/>',
        r"the boundary \(black\) is not one outline: 3 black lines meet at \(50, (0|100)\)",
    ),
    "two sheets": (
        SQUARE + '<rect x="200" y="0" width="10" height="10" stroke="black"/>',
        r"the boundary \(black\) is 2 separate outlines, not one sheet",
    ),
    "hole": (
        SQUARE + '<rect x="40" y="40" width="20" height="20" stroke="black"/>',
        r"the black outline through \(\d+, \d+\) lies inside another: holes are not supported",
    ),
    "cut": (
        SQUARE + '<line x1="0" y1="50" x2="100" y2="50" stroke="#00ff00" id="slit"/>',
        r'<line id="slit"> is green, a cut: cuts are not supported',
    ),
    "crease outside": (
        SQUARE + '<line x1="100" y1="0" x2="150" y2="0" stroke="red"/>',
        r"the crease from \((100, 0|150, 0)\) to \((100, 0|150, 0)\) lies outside the boundary",
    ),
    "dangling crease": (
        SQUARE + '<line x1="0" y1="50" x2="60" y2="50" stroke="red"/>',
        r"a crease ends inside a face at \(60, 50\): creases must end on another line \(an end "
        r"within 1\.41 drawing units of a line is joined to it; Settings\.inputs\.svg_snap_tol\)",
    ),
    "crease crossing out of the boundary": (
        SQUARE + '<line x1="50" y1="50" x2="150" y2="50" stroke="blue"/>',
        r"the crease from \((100, 50|150, 50)\) to \((100, 50|150, 50)\) lies outside",
    ),
    "floating crease loop": (
        SQUARE + '<polygon points="40,40 60,40 50,60" stroke="red" fill="none"/>',
        r"creases around \(\d+, \d+\) are not connected to the boundary: the face around them "
        r"would have a hole",
    ),
    "crease loop hanging on one line": (
        SQUARE
        + '<polygon points="40,40 60,40 50,60" stroke="red" fill="none"/>'
        + '<line x1="50" y1="0" x2="50" y2="40" stroke="blue"/>',
        r"a face is not a simple polygon: its outline passes twice through \(50, (0|40)\)",
    ),
    "unknown colour": (
        SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="cyan"/>',
        r"<line> \(drawn element 2\) has stroke colour cyan \(#00ffff\), none of Origami "
        r"Simulator's: black boundary, red mountain, blue valley, yellow flat, magenta undriven",
    ),
    "grey": (
        SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="#888888"/>',
        r"<line> \(drawn element 2\) has stroke colour #888888, none of",
    ),
    "opacity not a number": (
        SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="red" opacity="half"/>',
        r"<line> \(drawn element 2\) has an opacity that is not a number",
    ),
    "one line in two colours": (
        SQUARE
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>'
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="blue"/>',
        r"the line from \(0, 0\) to \(100, 100\) is drawn both red and blue",
    ),
}


@pytest.mark.parametrize("case", ERRORS)
def test_refusals(tmp_path, case):
    body, message = ERRORS[case]
    path = write(tmp_path, body)
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))}: {message}") as info:
        read_svg(path)
    assert "\n" not in str(info.value)


def degree(drawing: SvgDrawing) -> np.ndarray:
    """(V,) int: how many edges meet at each vertex."""
    return np.bincount(drawing.edges.ravel(), minlength=len(drawing.xy))


def test_pieces_along_one_line_do_not_cross(tmp_path):
    """Huffman's stars-triangles (issue 49): a diagonal drawn as pieces of alternate colours
    end to end, its ends merged with ends drawn 1e-3 units away, so that two pieces lie
    along one line. The crossing of their lines is round-off (its denominator 4e-11 of
    126 x 126), 2.8 units before their common end: it is not a split, and the lines
    meeting there stay one vertex (before, it was refused: a face not a simple polygon)."""
    body = (
        '<rect x="0" y="0" width="2400" height="2400" fill="none" stroke="#000"/>'
        '<line x1="0" y1="1096.42" x2="959.719" y2="1096.42" stroke="blue"/>'
        '<line x1="959.719" y1="1096.421" x2="1049.005" y2="1185.706" stroke="blue"/>'
        '<line x1="1138.291" y1="1274.992" x2="1227.577" y2="1364.277" stroke="blue"/>'
        '<line x1="1138.292" y1="1274.992" x2="1049.005" y2="1185.706" stroke="red"/>'
        '<line x1="1227.577" y1="1364.277" x2="2400" y2="1364.277" stroke="blue"/>'
        '<line x1="1049.005" y1="1185.706" x2="2400" y2="1185.706" stroke="red"/>'
    )
    drawing = read_svg(write(tmp_path, body, 'width="2400" height="2400"'))
    check_planar(drawing)
    assert counts(drawing) == (11, 13, 3)
    meet = np.flatnonzero(np.all(np.abs(drawing.xy - [1049.005, -1185.706]) < 1e-9, axis=1))
    assert len(meet) == 1 and degree(drawing)[meet[0]] == 3


def test_lines_that_cross_near_their_ends_meet_there(tmp_path):
    """Lang's cardinal (issue 49): two creases drawn to the boundary at points 0.09 units
    apart (more than the merge distance, 0.07) cross each other 0.045 units before it,
    within the merge distance of both ends. The crossing is a split, merged with both ends:
    they end at one vertex (before, neither piece was split there, as the crossing lies
    within the merge distance of their ends, and the face was refused)."""
    body = (
        '<line x1="0" y1="50" x2="50.045" y2="0" stroke="red"/>'
        '<line x1="100" y1="50" x2="49.955" y2="0" stroke="blue"/>'
    )
    drawing = read_svg(write(tmp_path, SQUARE + body))
    check_planar(drawing)
    assert counts(drawing) == (7, 9, 3)
    creases = drawing.edges[[a != "B" for a in drawing.assignment]]
    assert len(set(creases[0]) & set(creases[1])) == 1
    assert degree(drawing).max() == 4


def test_a_piece_drawn_in_two_crease_colours_within_the_snap_tolerance_is_one_point(
    tmp_path,
):
    """Lang's cardinal and rattan weave (issue 49): a mountain misses the point where two
    valleys meet by 0.05 units, at a shallow angle, and crosses one of them 0.25 units
    before it. The 0.25-unit piece between is drawn both red and blue: within svg_snap_tol,
    a slip, its two ends are made one vertex, where all four creases meet (before, it was
    dropped and the valley ended at the crossing, away from the other)."""
    body = (
        '<line x1="0" y1="50" x2="50" y2="50" stroke="blue"/>'
        '<line x1="50" y1="50" x2="50" y2="100" stroke="blue"/>'
        '<line x1="0" y1="40.05" x2="100" y2="60.05" stroke="red"/>'
    )
    drawing = read_svg(write(tmp_path, SQUARE + body))
    check_planar(drawing)
    assert counts(drawing) == (9, 12, 4)
    assert sorted(Counter(degree(drawing)).items()) == [(2, 4), (3, 4), (4, 1)]
    with pytest.raises(ValueError, match=r"is drawn both (blue and red|red and blue)"):
        read_svg(write(tmp_path, SQUARE + body), settings=DEFAULTS.with_(svg_snap_tol=0))


def test_a_drawing_without_black_lines_is_bounded_by_its_outline(tmp_path):
    """Origami Simulator's Origami_Sphere_16Flaps.svg draws no black line: its outline is
    creases, which Origami Simulator takes for boundary (edges with a face on one side).
    So does read_svg; lines that enclose no area, or whose outline passes twice through a
    point, are refused."""
    body = (
        '<line x1="0" y1="0" x2="100" y2="0" stroke="red"/>'
        '<line x1="100" y1="0" x2="100" y2="100" stroke="red"/>'
        '<line x1="100" y1="100" x2="0" y2="100" stroke="blue"/>'
        '<line x1="0" y1="100" x2="0" y2="0" stroke="red"/>'
        '<line x1="0" y1="0" x2="100" y2="100" stroke="blue"/>'
    )
    drawing = read_svg(write(tmp_path, body))
    check_planar(drawing)
    assert counts(drawing) == (4, 5, 2)
    assert Counter(drawing.assignment) == {"B": 4, "V": 1}
    assert drawing.fold_angles.tolist().count(0.0) == 4
    tail = '<line x1="100" y1="100" x2="150" y2="150" stroke="red"/>'
    with pytest.raises(
        ValueError,
        match=r"no boundary: no black lines, and the outline of the lines drawn, taken for "
        r"the sheet's, passes twice through \(100, 100\)",
    ):
        read_svg(write(tmp_path, body + tail))


def test_unequal_scales_in_physical_units(tmp_path):
    size = 'width="100mm" height="100mm" viewBox="0 0 100 50" preserveAspectRatio="none"'
    path = write(tmp_path, SQUARE, size)
    with pytest.raises(ValueError, match="the width, height and viewBox scale x and y differ"):
        read_svg(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("this is no XML", r"not an SVG file: .*pattern\.svg: syntax error"),
        ("<html><body/></html>", r"not an SVG file: .*pattern\.svg: the root element is not <svg>"),
    ],
)
def test_not_svg(tmp_path, text, message):
    path = tmp_path / "pattern.svg"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_svg(path)


def test_missing_file(tmp_path):
    with pytest.raises(ValueError, match=r"cannot read .*absent\.svg: No such file"):
        read_svg(tmp_path / "absent.svg")


def test_merge_tolerance_is_a_setting(tmp_path):
    """A crease end 0.5 units short of a line (3.5e-3 of the diagonal) dangles without
    mending and is joined to the line with a larger svg_merge_tol."""
    body = SQUARE + '<line x1="0" y1="50" x2="99.5" y2="50" stroke="red"/>'
    path = write(tmp_path, body)
    unmended = DEFAULTS.with_(svg_snap_tol=0)
    with pytest.raises(ValueError, match=r"a crease ends inside a face at \(99\.5, 50\)"):
        read_svg(path, settings=unmended)
    drawing = read_svg(path, settings=unmended.with_(svg_merge_tol=5e-3))
    assert counts(drawing) == (6, 7, 2)


# --------------------------------------------------------------------------- slips mended
SLIPS = {
    # slip: (drawn besides the square, (V, E, faces), {letter: count}); a square cut in two by
    # a mountain is (6, 7, 2), {"B": 6, "M": 1}
    "crease short of the boundary": (
        '<line x1="0" y1="50" x2="99" y2="50" stroke="red"/>',
        (6, 7, 2),
        {"B": 6, "M": 1},
    ),
    "crease past the boundary": (
        '<line x1="0" y1="50" x2="101" y2="50" stroke="red"/>',
        (6, 7, 2),
        {"B": 6, "M": 1},
    ),
    "crease past the boundary at both ends": (
        '<line x1="-1.2" y1="50" x2="101" y2="50" stroke="red"/>',
        (6, 7, 2),
        {"B": 6, "M": 1},
    ),
    "crease short of the boundary, not pointing at it": (
        '<line x1="0" y1="50" x2="60" y2="50" stroke="red"/>'
        + '<line x1="60" y1="50" x2="99" y2="49" stroke="red"/>',
        (7, 8, 2),
        {"B": 6, "M": 2},
    ),
    "two creases overlapping in two colours": (
        '<line x1="0" y1="50" x2="51" y2="50" stroke="red"/>'
        + '<line x1="50" y1="50" x2="100" y2="50" stroke="blue"/>'
        + '<line x1="50" y1="0" x2="50" y2="100" stroke="blue"/>',
        (9, 12, 4),
        {"B": 8, "M": 1, "V": 3},
    ),
}


@pytest.mark.parametrize("slip", SLIPS)
def test_slips_within_the_snap_tolerance_are_mended(tmp_path, slip):
    """Slips of under 1 % of the diagonal (1.41 units here) are mended by default
    (Settings.inputs.svg_snap_tol) and refused with svg_snap_tol=0."""
    body, sizes, letters = SLIPS[slip]
    path = write(tmp_path, SQUARE + body)
    drawing = read_svg(path)
    check_planar(drawing)
    assert counts(drawing) == sizes
    assert Counter(drawing.assignment) == letters
    assert any(x == 100 and -51 < y < -48 for x, y in points(drawing.xy))  # on the boundary
    with pytest.raises(ValueError, match=r"lies outside the boundary|ends inside a face|both"):
        read_svg(path, settings=DEFAULTS.with_(svg_snap_tol=0))


def test_slips_beyond_the_snap_tolerance_are_refused(tmp_path):
    path = write(tmp_path, SQUARE + '<line x1="0" y1="50" x2="97" y2="50" stroke="red"/>')
    with pytest.raises(ValueError, match=r"a crease ends inside a face at \(97, 50\): .* within "):
        read_svg(path)
    assert counts(read_svg(path, settings=DEFAULTS.with_(svg_snap_tol=0.03))) == (6, 7, 2)
    with pytest.raises(ValueError, match="svg_snap_tol must be a fraction from 0 to below 1"):
        DEFAULTS.with_(svg_snap_tol=-0.1)


WATERBOMB_UNMENDED = (
    r"the crease from \(135\.014, 1074\.92\) to \(135\.014, 1075\.5\) lies outside the boundary"
)
HYPAR_UNMENDED = r"a crease ends inside a face at \(629\.168, 524\.834\)"


@pytest.mark.parametrize(
    ("name", "merge", "sizes", "letters", "triangles", "shortest", "unmended"),
    [
        pytest.param(
            "huffmanWaterbomb.svg",
            {},
            (440, 1157, 718),
            {"B": 80, "M": 758, "V": 319},
            798,
            53.975,
            None,
            id="huffmanWaterbomb-default",
        ),
        pytest.param(
            "huffmanWaterbomb.svg",
            OLD_MERGE,
            (448, 1165, 718),
            {"B": 88, "M": 758, "V": 319},
            806,
            0.58,
            WATERBOMB_UNMENDED,
            id="huffmanWaterbomb-1e-4",
        ),
        pytest.param(
            "hypar.svg",
            {},
            (97, 284, 188),
            {"B": 4, "M": 96, "V": 88, "U": 96},
            188,
            25.456,
            HYPAR_UNMENDED,
            id="hypar-default",
        ),
        pytest.param(
            "hypar.svg",
            OLD_MERGE,
            (98, 285, 188),
            {"B": 4, "M": 96, "V": 89, "U": 96},
            190,
            0.482,
            HYPAR_UNMENDED,
            id="hypar-1e-4",
        ),
    ],
)
def test_origami_simulator_files_with_slips(
    name, merge, sizes, letters, triangles, shortest, unmended
):
    """Origami Simulator's examples with slips of under 1e-3 of their diagonals: in
    huffmanWaterbomb.svg creases are drawn to points 0.59 units (3.8e-4) past the boundary,
    in hypar.svg a crease ends 0.83 units (6.8e-4) short of a line, near a vertex. With the
    default svg_merge_tol (5e-4: 0.76 and 0.61 units) they read as drawn: the waterbomb's
    creases meet at their drawn ends, which the boundary passes through, and it reads even
    unmended; hypar's crease, extended, ends at the vertex. Their shortest edges are then 54
    and 25 units. With 1e-4 (the default before) the mended ends stay 0.58 and 0.48 units
    from those points: edges that short, and unmended both are refused."""
    from rigidfold.patterns.files import read_pattern_file

    settings = DEFAULTS.with_(**merge)
    drawing = read_svg(DATA / name, settings=settings)
    check_planar(drawing)
    assert counts(drawing) == sizes
    assert Counter(drawing.assignment) == letters
    assert shortest_edge(drawing) == pytest.approx(shortest, abs=1e-3)
    assert len(read_pattern_file(DATA / name, settings=settings).faces) == triangles
    if unmended is None:
        assert counts(read_svg(DATA / name, settings=settings.with_(svg_snap_tol=0))) == sizes
    else:
        with pytest.raises(ValueError, match=unmended):
            read_svg(DATA / name, settings=settings.with_(svg_snap_tol=0))


# a square drawn as four lines, the last of them ending short of the first one's start
GAP = (
    '<line x1="0" y1="0" x2="100" y2="0" stroke="#000"/>'
    '<line x1="100" y1="0" x2="100" y2="100" stroke="#000"/>'
    '<line x1="100" y1="100" x2="0" y2="100" stroke="#000"/>'
    '<line x1="0" y1="100" x2="{x}" y2="{y}" stroke="#000"/>'
    '<line x1="0" y1="0" x2="100" y2="100" stroke="#f00"/>'
)


@pytest.mark.parametrize(("x", "y"), [(0, 1), (0.6, 0.8), (-0.5, 0.5)])
def test_a_boundary_gap_within_the_snap_tolerance_is_closed(tmp_path, x, y):
    """A gap of at most 1 unit (0.7 % of the diagonal, under svg_snap_tol's 1 %) between the
    boundary's two loose ends is closed at the point halfway between them; with
    svg_snap_tol=0 it is refused, the loose end named."""
    path = write(tmp_path, GAP.format(x=x, y=y))
    drawing = read_svg(path)
    check_planar(drawing)
    assert counts(drawing) == (4, 5, 2)
    assert Counter(drawing.assignment) == {"B": 4, "M": 1}
    assert points(drawing.xy) == sorted([(x / 2, -y / 2), (0, -100), (100, -100), (100, 0)])
    gap = math.hypot(x, y)
    with pytest.raises(
        ValueError,
        match=rf"not closed: it ends at \(0, 0\), {gap:.3g} drawing units from its end "
        rf"at \({x:g}, {y:g}\) \(a gap of up to 0 drawing units",
    ):
        read_svg(path, settings=DEFAULTS.with_(svg_snap_tol=0))


def test_a_boundary_gap_beyond_the_snap_tolerance_is_refused(tmp_path):
    path = write(tmp_path, GAP.format(x=0, y=2))
    with pytest.raises(
        ValueError,
        match=r"pattern\.svg: the boundary \(black\) is not closed: it ends at \(0, 0\), 2 drawing "
        r"units from its end at \(0, 2\) \(a gap of up to 1\.41 drawing units between two ends is "
        r"closed; Settings\.inputs\.svg_snap_tol\)$",
    ):
        read_svg(path)
    assert counts(read_svg(path, settings=DEFAULTS.with_(svg_snap_tol=0.015))) == (4, 5, 2)


@pytest.mark.parametrize(
    "body",
    [
        # both lines of a corner drawn 0.8 past it: the stubs cross at the corner
        '<line x1="0" y1="0" x2="100.8" y2="0" stroke="#000"/>'
        '<line x1="100" y1="-0.8" x2="100" y2="100" stroke="#000"/>'
        '<line x1="100" y1="100" x2="0" y2="100" stroke="#000"/>'
        '<line x1="0" y1="100" x2="0" y2="0" stroke="#000"/>'
        '<line x1="0" y1="0" x2="100" y2="100" stroke="#f00"/>',
        # a black stroke 1 unit long over the crease, from a corner
        SQUARE
        + '<line x1="0" y1="0" x2="100" y2="100" stroke="#f00"/>'
        + '<line x1="0" y1="0" x2="0.7" y2="0.7" stroke="#000"/>',
    ],
)
def test_black_stubs_within_the_snap_tolerance_are_dropped(tmp_path, body):
    """A black piece of up to svg_snap_tol from a loose end to where three black lines meet
    (an overshoot past a corner, a black stroke over a crease) is dropped; a crease drawn
    along it stays."""
    path = write(tmp_path, body)
    drawing = read_svg(path)
    check_planar(drawing)
    assert counts(drawing) == (4, 5, 2)
    assert Counter(drawing.assignment) == {"B": 4, "M": 1}
    assert points(drawing.xy) == [(0, -100), (0, 0), (100, -100), (100, 0)]
    with pytest.raises(ValueError, match=r"not closed: it ends at \((100\.8, 0|0\.7, 0\.7)\)"):
        read_svg(path, settings=DEFAULTS.with_(svg_snap_tol=0))


# --------------------------------------------------------------------------- issue 39 item 19
WHIRLPOOL, WEAVE = DATA / "whirlpool.svg", DATA / "huffmanRectangularWeave.svg"


def check_pattern_file(
    path: Path, triangles: int, smallest: float = 1e-5, **settings
) -> CreasePattern:
    """The crease pattern of an SVG file (read_pattern_file): ``triangles`` triangles, up,
    tiling the sheet, none smaller than ``smallest`` of it."""
    from rigidfold.patterns.files import read_pattern_file

    plan = read_pattern_file(path, settings=DEFAULTS.with_(**settings))
    coords = np.column_stack([plan.xy, np.zeros(len(plan.xy))])
    pattern = CreasePattern.from_faces(coords, plan.faces)
    assert pattern.n_faces == triangles
    assert (pattern.face_normals[:, 2] > 0).all()
    a, b = (
        plan.xy[plan.faces[:, 1]] - plan.xy[plan.faces[:, 0]],
        (plan.xy[plan.faces[:, 2]] - plan.xy[plan.faces[:, 0]]),
    )
    area = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 2
    assert area.sum() == pytest.approx(shapely.MultiPoint(plan.xy).convex_hull.area, rel=0.2)
    assert (area > smallest * area.sum()).all()
    return pattern


# Origami Simulator merges points within 3 px before it looks for crossings; whirlpool's
# lines miss the points they are drawn to by up to 0.25 units (3e-4 of its diagonal), the
# weave's by 0.85 units (2.3e-4): the default svg_merge_tol, 5e-4, joins them where 1e-4 (the
# default before) does not


def test_whirlpool_reads():
    """Origami Simulator's whirlpool.svg: its boundary is separate lines whose ends miss each
    other by up to 0.25 units, and a black stroke 4.2 units long lies over a valley inside
    the sheet (Origami Simulator takes it for a boundary edge there). Within svg_snap_tol
    the boundary is closed and the stroke dropped, its valley kept; with the default
    svg_merge_tol (5e-4, 0.41 units) it reads as drawn: 150 vertices, 240 triangles, its
    shortest edge 4.15 units."""
    assert DEFAULTS.inputs.svg_merge_tol == 5e-4
    drawing = read_svg(WHIRLPOOL)
    check_planar(drawing)
    assert counts(drawing) == (150, 389, 240)
    assert Counter(drawing.assignment) == {"B": 58, "M": 120, "V": 211}
    assert {len(p) for p in drawing.polygons} == {3}
    stroke = [
        letter
        for (u, v), letter in zip(drawing.edges, drawing.assignment, strict=True)
        if {(round(x, 1), round(y, 1)) for x, y in drawing.xy[[u, v]]}
        == {(126.6, -175.5), (130.6, -176.8)}
    ]
    assert stroke == ["V"]
    assert shortest_edge(drawing) == pytest.approx(4.153, abs=1e-3)
    check_pattern_file(WHIRLPOOL, 240)
    with pytest.raises(ValueError, match=r"not closed: it ends at \(130\.57, 176\.781\)"):
        read_svg(WHIRLPOOL, settings=DEFAULTS.with_(svg_snap_tol=0))


def test_whirlpool_boundary_is_closed_within_the_snap_tolerance():
    """With svg_merge_tol=1e-4 (0.08 units, the default before) the nine gaps of whirlpool's
    boundary (0.08 to 0.25 units) are not merged: svg_snap_tol closes each. The first gap,
    0.185 units between its ends, is closed at a vertex nearer than that to both ends,
    where a mountain and a valley drawn to them cross 0.15 units before them; the
    drawing reads and triangulates (before lines that cross near their ends were split
    there, a face with corners 0.1 apart was left that could not be cut)."""
    from rigidfold.patterns.files import read_pattern_file

    drawing = read_svg(WHIRLPOOL, settings=DEFAULTS.with_(**OLD_MERGE))
    check_planar(drawing)
    assert counts(drawing) == (183, 446, 264)
    assert Counter(drawing.assignment)["B"] == 61
    ends = np.array([[517.172, -549.847], [517.345, -549.781]])  # the first gap's ends
    gap = np.linalg.norm(ends[0] - ends[1])
    assert np.linalg.norm(drawing.xy[:, None] - ends, axis=2).max(axis=1).min() < gap
    assert len(read_pattern_file(WHIRLPOOL, settings=DEFAULTS.with_(**OLD_MERGE)).faces) == 303


def test_a_face_that_cannot_be_cut_is_named(tmp_path):
    """A face that cannot be cut into triangles (here a sliver of a quadrilateral between
    two creases drawn from one corner, whose corners 0.18 units apart are refused once
    Settings.geometry.triangulation_area_tol is 1e-2) is one line naming its corners and
    its shortest side in the file's coordinates, and the setting that joins them."""
    from rigidfold.patterns.files import read_pattern_file

    body = (
        '<line x1="0" y1="100" x2="100" y2="0" stroke="#f00"/>'
        '<line x1="0" y1="100" x2="100" y2="1" stroke="#00f"/>'
        '<line x1="100" y1="1" x2="50" y2="50.25" stroke="#00f"/>'
    )
    path = write(tmp_path, SQUARE + body)
    assert len(read_pattern_file(path).faces) == 7  # by default: 4 faces, 3 of them quadrilaterals
    with pytest.raises(ValueError) as info:
        read_pattern_file(path, settings=DEFAULTS.with_(triangulation_area_tol=1e-2))
    message = str(info.value)
    assert "\n" not in message
    assert "(49.875, 50.125)" in message
    assert re.fullmatch(
        r".*pattern\.svg: the face with corners (\(\d+\.?\d*, \d+\.?\d*\)(, | and |)){3,}.*"
        r"\(drawing units, y down\) cannot be cut into triangles: it is degenerate or nearly "
        r"so, its shortest side, from \(\S+, \S+\) to \(\S+, \S+\), 0\.\d+ long; lines drawn "
        r"to one point that miss each other by that much are joined with a larger "
        r"Settings\.inputs\.svg_merge_tol",
        message,
    ), message


def test_huffman_rectangular_weave_reads():
    """Origami Simulator's huffmanRectangularWeave.svg: creases drawn at half opacity and
    full, lines that miss the points they are drawn to by 0.85 units (2.3e-4 of the
    diagonal), rectangles with a vertex on a side (refused as degenerate before). With
    svg_merge_tol=1e-4 (the default before) the near misses stay: 1025 vertices, edges of
    0.84 units, slivers of 5e-8 of the sheet among the triangles; with the default (5e-4) it
    reads as drawn: 512 vertices, 353 rectangles and 224 triangles, folds of 90 and 180
    degrees, its shortest edge 83 units."""
    drawing = read_svg(WEAVE, settings=DEFAULTS.with_(**OLD_MERGE))
    check_planar(drawing)
    assert counts(drawing) == (1025, 1705, 681)
    assert shortest_edge(drawing) == pytest.approx(0.841, abs=1e-3)
    check_pattern_file(WEAVE, 1943, smallest=1e-8, **OLD_MERGE)
    drawing = read_svg(WEAVE)
    check_planar(drawing)
    assert counts(drawing) == (512, 1088, 577)
    assert shortest_edge(drawing) == pytest.approx(83.135, abs=1e-3)
    assert Counter(drawing.assignment) == {"B": 92, "M": 464, "V": 532}
    assert Counter(len(p) for p in drawing.polygons) == {3: 224, 4: 353}
    folds = Counter(zip(drawing.assignment, np.abs(drawing.fold_angles).tolist(), strict=True))
    assert folds == {("V", 90): 420, ("M", 90): 240, ("M", 180): 224, ("V", 180): 112, ("B", 0): 92}
    check_pattern_file(WEAVE, 930)


def test_a_polygon_with_a_vertex_on_a_straight_side_triangulates():
    """A face of huffmanRectangularWeave.svg read with svg_merge_tol=1e-4: a rectangle with
    a vertex on its right side, 0.85 units from a corner, its x the corners' to round-off.
    Earcut cuts an ear of three points on that side (no area); the polygon is cut without
    its straight vertex, and the triangle on that side cut again with it."""
    from rigidfold.mesh.triangulate import triangulate_polygon

    x = 482.76599999999996  # as svgelements computes 482.766 from the path's relative moves
    xy = [[231.661, -489.955], [x, -489.955], [482.766, -406.82]]
    xy += [[x, -405.972], [231.661, -405.972]]
    tri, diagonals = triangulate_polygon(xy, area_tol=DEFAULTS.geometry.triangulation_area_tol)
    assert len(tri) == 3 and len(diagonals) == 2
    p = np.array(xy)[np.array(tri)]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 2
    assert (area > 100).all()
    assert area.sum() == pytest.approx(shapely.Polygon(xy).area)


def test_cli_svg_tolerance(tmp_path, capsys):
    """--svg-tolerance sets Settings.inputs.svg_snap_tol; its default is the setting's."""
    path = write(tmp_path, SQUARE + '<line x1="0" y1="50" x2="98" y2="50" stroke="red"/>')
    args = ["optimize", "--surface", "dome", "--pattern", str(path), "--out"]
    assert main([*args, str(tmp_path / "a")]) == 2
    assert "a crease ends inside a face at (98, 50)" in capsys.readouterr().err
    assert main([*args, str(tmp_path / "b"), "--svg-tolerance", "0.02"]) == 0
    assert (tmp_path / "b" / "solution.fold").is_file()
    with pytest.raises(SystemExit) as stop:
        main([*args, str(tmp_path / "c"), "--svg-tolerance", "1.5"])
    assert stop.value.code == 2
    assert "--svg-tolerance: must be a number from 0 to below 1, got '1.5'" in (
        capsys.readouterr().err
    )


# --------------------------------------------------------------------------- Origami Simulator
OS_FILES = {
    # file: ((V, E, faces), assignment counts)
    "simpleVertex.svg": ((9, 12, 4), {"B": 8, "M": 3, "V": 1}),
    "singlesquaretwist.svg": ((16, 24, 9), {"B": 12, "M": 4, "V": 8}),
    "miura-ori.svg": ((182, 337, 156), {"B": 50, "M": 137, "V": 150}),
}


@pytest.mark.parametrize("name", OS_FILES)
def test_origami_simulator_files(name):
    """Origami Simulator's own crease patterns read, and triangulate into crease patterns."""
    sizes, letters = OS_FILES[name]
    drawing = read_svg(DATA / name)
    check_planar(drawing)
    assert counts(drawing) == sizes
    assert Counter(drawing.assignment) == letters
    assert (drawing.unit, drawing.scale) == ("unit", 1.0)
    crease = np.array([a in "MV" for a in drawing.assignment])
    np.testing.assert_array_equal(np.abs(drawing.fold_angles[crease]), 180)
    coords = np.column_stack([drawing.xy, np.zeros(len(drawing.xy))])
    triangles, diagonals = triangulate_polygons(
        coords, drawing.polygons, area_tol=DEFAULTS.geometry.triangulation_area_tol
    )
    pattern = CreasePattern.from_faces(coords, orient_up(coords, triangles))
    assert len(pattern.faces) == sum(len(p) - 2 for p in drawing.polygons)
    assert len(pattern.edges) == len(drawing.edges) + len(diagonals)


MORE_OS_FILES = {
    # file: ((V, E, faces), assignment counts, triangles)
    "waterbomb.svg": ((195, 524, 330), {"B": 58, "M": 246, "V": 220}, 330),
    "reschTriTessellation.svg": ((243, 664, 422), {"B": 60, "M": 451, "V": 153}, 424),
    "polygamiCross.svg": ((144, 278, 135), {"B": 44, "M": 122, "V": 112}, 242),
    "langWedgeDoubleFaced.svg": ((264, 560, 297), {"B": 64, "M": 250, "V": 246}, 462),
    "miura_sharpangle.svg": ((325, 612, 288), {"B": 72, "M": 282, "V": 258}, 576),
    "test.svg": ((25, 54, 30), {"B": 18, "M": 16, "V": 20}, 30),
}


@pytest.mark.parametrize("name", MORE_OS_FILES)
def test_more_origami_simulator_files(name):
    """Origami Simulator's tessellations of tests/data/origami_simulator/README.md (the last
    four for the deployability benchmark) read and triangulate."""
    sizes, letters, triangles = MORE_OS_FILES[name]
    drawing = read_svg(DATA / name)
    check_planar(drawing)
    assert counts(drawing) == sizes
    assert Counter(drawing.assignment) == letters
    check_pattern_file(DATA / name, triangles)


def test_origami_simulator_curved_file():
    with pytest.raises(
        ValueError,
        match=r"wavy_pleats\.svg: <path> \(drawn element 2\) has a curved piece \(CubicBezier\)",
    ):
        read_svg(DATA / "wavy_pleats.svg")


# --------------------------------------------------------------------------- headers, nesting
HEADERS = {
    "empty viewBox": (
        'width="100mm" height="100mm" viewBox="0 0 0 0"',
        r'<svg> has viewBox="0 0 0 0": a viewBox is four finite numbers',
    ),
    "empty viewBox without units": ('viewBox="0 0 0 0"', r'<svg> has viewBox="0 0 0 0"'),
    "tiny viewBox": (
        'width="100mm" height="100mm" viewBox="0 0 1e-300 1e-300"',
        r"\(drawn in mm\) is 1e\+301 m x 1e\+301 m: a crease pattern is 0\.001 m to",
    ),
    "huge viewBox": (
        'width="100mm" height="100mm" viewBox="0 0 1e308 1e308"',
        r'the viewBox="0 0 1e308 1e308" scales the drawing to its width="100mm" and '
        r'height="100mm" by 0 x 0, which cannot be computed with',
    ),
    "width nan": (
        'width="nanmm" height="100mm" viewBox="0 0 100 100"',
        r'<svg> has width="nanmm": a width is a positive finite length',
    ),
    "width overflows": (
        'width="1e400mm" height="100mm" viewBox="0 0 100 100"',
        r'<svg> has width="1e400mm": a width is a positive finite length',
    ),
    "height zero": ('width="100mm" height="0" viewBox="0 0 100 100"', r'<svg> has height="0"'),
    "viewBox of three numbers": ('viewBox="0 0 100"', r'<svg> has viewBox="0 0 100"'),
}


@pytest.mark.parametrize("case", HEADERS)
def test_bad_headers_one_line_exit_2(tmp_path, capsys, case):
    """A width, height or viewBox that svgelements divides by zero on (a ZeroDivisionError
    traceback before) is a one-line error naming what was received."""
    size, message = HEADERS[case]
    path = write(tmp_path, SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="red"/>', size)
    code = main(["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and re.fullmatch(f"rigidfold: error: {re.escape(str(path))}.*\n", err), err
    assert re.search(message, err), err


BAD_TRANSFORMS = {
    "matrix(nan,0,0,1,0,0)": r'<g id="t"> has transform="matrix\(nan,0,0,1,0,0\)": a transform',
    "matrix(1,2)": r'<g id="t"> has transform="matrix\(1,2\)"',
    "scale(1e400)": r'<g id="t"> has transform="scale\(1e400\)"',
    "rotate(inf)": r'<g id="t"> has transform="rotate\(inf\)"',
    "turn(90)": r'<g id="t"> has transform="turn\(90\)"',
    "scale(1e200) scale(1e200)": r"<rect> \(drawn element 1\) is drawn with a transform that "
    r"is not finite, matrix\(nan, nan, nan, nan, 0, 0\)",
    "translate(1e308) translate(1e308)": r"<rect> \(drawn element 1\) is drawn with a "
    r"transform that is not finite, matrix\(nan, nan, nan, nan, nan, nan\)",
}


@pytest.mark.parametrize("transform", BAD_TRANSFORMS)
def test_bad_transforms(tmp_path, transform):
    path = write(tmp_path, f'<g id="t" transform="{transform}">{SQUARE}</g>')
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))}: {BAD_TRANSFORMS[transform]}"):
        read_svg(path)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            SQUARE + '<line x1="0" y1="0" x2="1e400" y2="100" stroke="red"/>',
            r"<line> \(drawn element 2\) has a line from \(0, 0\) to \(nan, nan\): coordinates "
            "must be finite",
        ),
        (
            SQUARE + '<path d="M0,0 L1e308,1e308" stroke="red"/>',
            r"its lines span inf drawing units .* more than 1e\+150",
        ),
        (
            f'<g id="a"><use xmlns:xlink="http://www.w3.org/1999/xlink" xlink:href="#a"/>{SQUARE}'
            "</g>",
            r'its <use> elements refer to each other in a loop \(through id="a"\)$',
        ),
    ],
)
def test_coordinates_svgelements_cannot_compute_with(tmp_path, body, message):
    path = write(tmp_path, body)
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))}: {message}"):
        read_svg(path)


@pytest.mark.parametrize("transform", ["rotate(45 50 50)", "translate(10px, 5px)", "none", ""])
def test_good_transforms(tmp_path, transform):
    path = write(tmp_path, f'<g transform="{transform}">{SQUARE}</g>')
    assert counts(read_svg(path)) == (4, 4, 1)


def test_nesting_depth_is_bounded(tmp_path, capsys):
    """5,000 nested groups (a RecursionError traceback from svgelements before) are refused in
    one line; Settings.limits.max_svg_depth is the limit."""
    deep = 5000
    path = write(tmp_path, "<g>" * deep + SQUARE + "</g>" * deep)
    code = main(["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err == (
        f"rigidfold: error: {path}: its elements nest more than 100 levels deep (at <g>; "
        "Settings.limits.max_svg_depth)\n"
    )
    nested = write(tmp_path, "<g>" * 98 + SQUARE + "</g>" * 98)  # <svg>, 98 <g>, <rect>
    assert counts(read_svg(nested)) == (4, 4, 1)
    with pytest.raises(ValueError, match="nest more than 99 levels deep"):
        read_svg(nested, settings=DEFAULTS.with_(max_svg_depth=99))


# ------------------------------------------------- issue 30, item 3: pieces drawn over each other
def back_and_forth(times: int) -> str:
    """A red crease across the square drawn back and forth ``times`` times in one path."""
    return SQUARE + f'<path d="M0,50 {"L100,50 L0,50 " * times}" stroke="red" fill="none"/>'


def test_a_line_drawn_over_itself_many_times_is_one_line(tmp_path):
    """4,000 pieces along one line (28 KB) took 12 to 25 s and 1.4 GB (every pair of them was
    examined); 8,000 ran out of memory. They are one line first: no more pairs than once."""
    once = read_svg(write(tmp_path, back_and_forth(1)))
    path = write(tmp_path, back_and_forth(2000))
    assert path.stat().st_size > 28_000
    few = DEFAULTS.with_(max_svg_pairs=20)  # the square and the crease meet in a few pairs
    drawing = read_svg(path, settings=few)
    check_planar(drawing)
    assert counts(drawing) == counts(once) == (6, 7, 2)
    assert points(drawing.xy) == points(once.xy)
    assert Counter(drawing.assignment) == {"B": 6, "M": 1}


def test_pieces_that_cannot_be_merged_are_bounded_by_max_svg_pairs(tmp_path):
    """Pieces drawn over each other that are not one crease (each of its own opacity) are
    refused in one line once their pairs pass Settings.limits.max_svg_pairs, before they are
    examined."""
    lines = "".join(
        f'<line x1="0" y1="50" x2="100" y2="50" stroke="red" stroke-opacity="{0.5 + k / 400}"/>'
        for k in range(100)
    )
    path = write(tmp_path, SQUARE + lines)
    assert counts(read_svg(path)) == (6, 7, 2)  # 4,950 pairs and more: below the default
    message = (
        f"{path}: more than 1000 pairs of its 104 line pieces meet, cross or come within the "
        "merge distance of each other (Settings.limits.max_svg_pairs): too many lines cross or are "
        "drawn over each other"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        read_svg(path, settings=DEFAULTS.with_(max_svg_pairs=1000))
    with pytest.raises(ValueError, match="max_svg_pairs must be an integer >= 1, got 0"):
        DEFAULTS.with_(max_svg_pairs=0)


def test_too_many_pairs_one_line_exit_2(tmp_path, capsys):
    """At the default limit, from the command line: 1,001 pieces over each other, exit 2."""
    lines = "".join(
        f'<line x1="0" y1="50" x2="100" y2="50" stroke="red" stroke-opacity="{0.5 + k / 4004}"/>'
        for k in range(1001)
    )
    path = write(tmp_path, SQUARE + lines)
    code = main(["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err == (
        f"rigidfold: error: {path}: more than {DEFAULTS.limits.max_svg_pairs} pairs of its "
        "1005 line "
        "pieces meet, cross or come within the merge distance of each other "
        "(Settings.limits.max_svg_pairs): too many lines cross or are drawn over each other\n"
    )
