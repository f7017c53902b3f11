"""Pattern specs: grid:NXxNY of any size and diagonals, mesh:POLYGON footprints, bad specs."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rigidfold import patterns
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.generate import specs
from rigidfold.generate.specs import case_from_specs
from rigidfold.mesh import CreasePattern
from rigidfold.pipeline.workflows import analyze_file
from rigidfold.surfaces import Bezier, Dome, HyperbolicParaboloid


def crease_pattern(plan: patterns.Plan) -> CreasePattern:
    return CreasePattern.from_faces(plan.xy, plan.faces)


def triangles(xy: np.ndarray, faces: np.ndarray, mirror=lambda p: p) -> set:
    return {tuple(sorted(map(tuple, np.round(mirror(xy[f]), 9).tolist()))) for f in faces}


# ------------------------------------------------------------------------------ grids
@pytest.mark.parametrize(
    ("spec", "diagonals", "name"),
    [("7x7", None, "1"), ("7x7", "parallel", "1p"), ("11x11", "centre", "11")],
)
def test_grid_is_the_paper_pattern_exactly(spec, diagonals, name):
    grid = specs.parse_pattern(f"grid:{spec}", diagonals=diagonals)
    paper = specs.parse_pattern(name)
    assert np.array_equal(grid.xy, paper.xy) and grid.xy.dtype == paper.xy.dtype
    assert np.array_equal(grid.faces, paper.faces) and grid.faces.dtype == paper.faces.dtype


@pytest.mark.parametrize("diagonals", patterns.DIAGONALS)
@pytest.mark.parametrize(
    ("nx", "ny", "size"),
    [(15, 9, "12x8"), (8, 7, "6x4"), (7, 8, "3x3"), (8, 8, "5x5"), (2, 3, "1x2.5")],
)
def test_grid_sizes_and_diagonals(nx, ny, size, diagonals):
    plan = specs.parse_pattern(f"grid:{nx}x{ny}", size=size, diagonals=diagonals)
    width, height = specs.parse_size(size)
    shape = crease_pattern(plan)
    assert (shape.n_vertices, shape.n_faces) == (nx * ny, 2 * (nx - 1) * (ny - 1))
    assert plan.box == (width, height)
    assert sorted(map(tuple, shape.coords[shape.corners, :2].tolist())) == [
        (0, 0),
        (0, height),
        (width, 0),
        (width, height),
    ]
    inner = sorted(len(side.inner) for side in shape.boundary_sides)
    assert inner == sorted([nx - 2, nx - 2, ny - 2, ny - 2])
    assert np.all(shape.face_normals[:, 2] > 0)
    assert shape.generic_dof == len(shape.interior_edges) - 3 * len(shape.interior_vertices)
    flaps = int((np.bincount(shape.edges.ravel()) == 2).sum())  # degree-2 corners
    odd = nx % 2 and ny % 2
    expected = {"centre": 0, "parallel": 2, "alternate": 0 if odd else 2}[diagonals]
    assert flaps == (2 if (nx, ny) == (2, 3) else expected)  # one column: 2 flaps whatever


@pytest.mark.parametrize(
    ("nx", "ny", "mirrors"), [(15, 9, "xy"), (8, 7, "y"), (7, 8, "x"), (8, 8, "")]
)
def test_centre_diagonals_mirror_symmetry(nx, ny, mirrors):
    """Mirror-symmetric about x = W/2 with an odd count along x... as the grid docstring says."""
    w, h = 6.0, 4.0
    plan = specs.parse_pattern(f"grid:{nx}x{ny}", size=(w, h))
    tris = triangles(plan.xy, plan.faces)
    about_x = triangles(plan.xy, plan.faces, lambda p: np.column_stack([w - p[:, 0], p[:, 1]]))
    about_y = triangles(plan.xy, plan.faces, lambda p: np.column_stack([p[:, 0], h - p[:, 1]]))
    assert (about_x == tris, about_y == tris) == ("x" in mirrors, "y" in mirrors)


# ------------------------------------------------------------------------------ meshes
HEXAGON = ";".join(
    f"{3 * math.cos(k * math.pi / 3):.6f},{3 * math.sin(k * math.pi / 3):.6f}" for k in range(6)
)
FOOTPRINTS = {
    "rectangle": "0,0;12,0;12,8;0,8",
    "L-shape": "0,0;6,0;6,3;3,3;3,6;0,6",
    "hexagon": HEXAGON,
    "trapezoid": "0,0;10,0;7,4;2,4",
}
# smallest plan angle reached (degrees), default edge length, theta_min = 30 degrees
MIN_ANGLE = {"rectangle": 31.04, "L-shape": 31.30, "hexagon": 30.42, "trapezoid": 30.11}


@pytest.mark.parametrize("name", list(FOOTPRINTS))
def test_mesh_footprints_reach_theta_min(name):
    plan = specs.parse_pattern(f"mesh:{FOOTPRINTS[name]}")
    shape = crease_pattern(plan)
    angles = np.degrees(shape.corner_angles)
    assert angles.min() >= math.degrees(DEFAULTS.design.theta_min)
    assert angles.min() == pytest.approx(MIN_ANGLE[name], abs=0.01)
    assert np.all(shape.face_normals[:, 2] > 0)
    # placed at (0, 0); the footprint's corners are the pattern's corners, first and in order
    assert np.array_equal(plan.xy.min(axis=0), [0.0, 0.0])
    n = len(plan.footprint)
    assert np.array_equal(plan.xy[:n], plan.footprint)
    assert sorted(shape.corners.tolist()) == list(range(n)) and len(shape.boundary_sides) == n
    # every boundary vertex lies on a side of the footprint: the sides stay straight
    for side in shape.boundary_sides:
        b1, b2, c = side.line
        assert (
            np.abs(b1 * plan.xy[side.inner, 0] + b2 * plan.xy[side.inner, 1] + c).max(initial=0.0)
            < 1e-12
        )
    lengths = shape.edge_lengths
    assert lengths.max() <= 1.5 * plan.edge_length


def test_mesh_edge_length_and_angle_cap():
    square = "mesh:0,0;3,0;3,3;0,3"
    assert specs.parse_pattern(square).edge_length == 0.5  # sqrt(9) / 6
    coarse = specs.parse_pattern(square, edge_length=1.0)
    fine = specs.parse_pattern(square, edge_length=0.25)
    assert len(coarse.faces) < len(fine.faces)
    tiny = specs.parse_pattern("mesh:0,0;0.03,0;0.03,0.02;0,0.02", edge_length=0.002)
    assert len(tiny.faces) > 0.0006 / (math.sqrt(3) / 4 * 0.002**2)  # an area bound of 1.7e-6
    steep = DEFAULTS.with_(theta_min=math.radians(40), theta_max=math.radians(150))
    capped = specs.parse_pattern(square, settings=steep)  # Triangle ends at the 33-degree cap
    angles = np.degrees(crease_pattern(capped).corner_angles)
    assert angles.min() >= math.degrees(DEFAULTS.inputs.mesh_angle_cap)


def test_mesh_keeps_sharp_input_angles():
    """A footprint corner sharper than theta_min stays (where the geometry does not allow)."""
    plan = specs.parse_pattern("mesh:0,0;10,0;0,1")
    angles = np.degrees(crease_pattern(plan).corner_angles)
    assert angles.min() == pytest.approx(math.degrees(math.atan(0.1)))


def test_mesh_from_file_clockwise_closed_and_translated(tmp_path):
    path = tmp_path / "roof.txt"
    path.write_text(
        "# an L, clockwise, closed, offset\n10 20\n10 26\n13 26\n\n13,23\n16,23\n16 20\n10 20\n"
    )
    plan = specs.parse_pattern(f"mesh:{path}")
    inline = specs.parse_pattern("mesh:0,0;6,0;6,3;3,3;3,6;0,6")
    assert np.array_equal(plan.footprint, inline.footprint)
    assert np.allclose(plan.xy, inline.xy, atol=1e-12) and np.array_equal(plan.faces, inline.faces)


# ------------------------------------------------------------------------------ bad specs
BAD = [
    ("7", {}, "unknown pattern '7'"),
    ("grid", {}, "unknown pattern 'grid'"),
    ("1:grid", {}, "unknown pattern '1:grid'"),
    ("grid:7", {}, "got 'grid:7'"),
    ("grid:axb", {}, "got 'grid:axb'"),
    ("grid:1x5", {}, "got 1 x 5"),
    ("grid:7x0", {}, "got 7 x 0"),
    ("grid:1000x1000", {}, "1996002 triangles"),
    ("grid:7x7", {"size": "0x3"}, "got '0x3'"),
    ("grid:7x7", {"size": "-2x3"}, "got '-2x3'"),
    ("grid:7x7", {"size": "nanx3"}, "got 'nanx3'"),
    ("grid:7x7", {"size": "3xinf"}, "got '3xinf'"),
    ("grid:7x7", {"size": "12"}, "got '12'"),
    ("grid:7x7", {"diagonals": "random"}, "unknown diagonals 'random'"),
    ("grid:7x7", {"edge_length": 0.5}, "pattern 'grid:7x7' takes no edge length"),
    ("1", {"size": "12x8"}, "pattern '1' takes no size"),
    ("11", {"diagonals": "parallel"}, "pattern '11' takes no diagonals"),
    ("mesh:0,0;1,0;1,1", {"size": "2x2"}, "takes no size"),
    ("mesh:0,0;2,0;2,2;0,2", {"edge_length": -1.0}, "got -1"),
    ("mesh:0,0;2,0;2,2;0,2", {"edge_length": 1e308}, "at most 1e+06 m, the largest plan"),
    ("mesh:0,0;2,0;2,2;0,2", {"edge_length": math.inf}, "got inf"),
    ("mesh:0,0;2,0;2,2;0,2", {"edge_length": 1e-4}, "more than 20000"),
    ("mesh:0,0;1,1;1,0;0,1", {}, "not a simple polygon: its sides intersect at [0.5 0.5]"),
    ("mesh:0,0;2,0;2,2;1,0;0,2", {}, "not a simple polygon"),
    ("mesh:0,0;1,0", {}, "at least 3 (x, y) points, got 2"),
    ("mesh:0,0;1,0;1,1;1,0;0,1", {}, "point (1, 0) is repeated (points 2, 4)"),
    ("mesh:0,0;1,0;2,0", {}, "'0,0; 1,0; 2,0' has zero area"),
    ("mesh:0,0;1,0;nan,1", {}, "point 3 is not finite: (nan, 1)"),
    ("mesh:0,0;1,0;1,x", {}, "footprint: point 3 is not an 'x,y' pair of numbers: '1,x'"),
    ("mesh:no/such/file.txt", {}, "'no/such/file.txt' is neither"),
]


@pytest.mark.parametrize(("spec", "options", "message"), BAD)
def test_bad_specs_one_line(spec, options, message):
    with pytest.raises(ValueError) as info:
        specs.parse_pattern(spec, **options)
    assert message in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--pattern", "grid:1x5"], "got 1 x 5"),
        (["--pattern", "grid:7x7", "--size", "12by8"], "got '12by8'"),
        (["--pattern", "mesh:0,0;1,1;1,0;0,1"], "not a simple polygon"),
        (["--pattern", "1", "--edge-length", "0.3"], "pattern '1' takes no edge length"),
        (["--pattern", "grid:7x7", "--diagonals", "random"], "invalid choice: 'random'"),
        (["--pattern", "mesh:0,0;1,0;1,1", "--edge-length", "0"], "must be a positive number"),
        (["--pattern", "mesh:0,0;1,0;1,1", "--edge-length", "1e308"], "got 1e+308 m"),
    ],
)
def test_cli_bad_specs_exit_2(tmp_path, capsys, args, message):
    argv = ["optimize", "--surface", "dome", *args, "--out", str(tmp_path / "o")]
    try:
        code = main(argv)
    except SystemExit as stop:  # argparse's own errors
        code = stop.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------------------ surfaces
def test_builtin_surfaces_scale_to_the_plan_box():
    box = (12.0, 8.0)
    corners = (np.array([0.0, 12.0, 0.0, 12.0]), np.array([0.0, 0.0, 8.0, 8.0]))
    bez = Bezier(3, box=box)
    h = Bezier(3).heights
    assert np.allclose(bez.height(*corners), [h[0, 0], h[3, 0], h[0, 3], h[3, 3]])
    assert np.allclose(bez.height(4.0, 8 / 3), Bezier(3).height(1.0, 1.0))
    dome = Dome(box=box)
    scale = math.hypot(6, 4) / math.hypot(1.5, 1.5)
    assert np.allclose(dome.height(*corners), 0.0, atol=1e-12)
    assert dome.height(6.0, 4.0) == pytest.approx(1.5 * scale)
    assert [str(p) for p in dome.mirror_planes] == ["x = 6", "y = 4"]
    hp = HyperbolicParaboloid(box=box)
    assert hp.height(12.0, 8.0) == pytest.approx(0.4 / scale * 6 * 4)
    assert [str(p) for p in hp.mirror_planes] == ["x - y = 2", "x + y = 10"]
    assert repr(dome) == "Dome(box=(12, 8))" and repr(bez) == "Bezier(3, box=(12, 8))"
    assert dome.metadata()["plan_box_m"] == [12.0, 8.0]


def test_make_case_scales_the_surface_and_records_the_pattern():
    case = case_from_specs("dome", "grid:9x7", size="6x4", symmetric=True)
    assert case.surface.box == (6.0, 4.0)
    corners = case.pattern.coords[case.pattern.corners]
    assert np.allclose(corners[:, 2], 0.0, atol=1e-12)
    meta = case.metadata()
    assert meta["pattern"] == "grid:9x7" and meta["plan_size_m"] == [6.0, 4.0]
    assert meta["diagonals"] == "centre" and meta["edge_length_m"] is None
    result = case.problem().solve()
    assert result.converged
    paper = case_from_specs("dome", "11").metadata()
    assert (paper["pattern"], paper["plan_size_m"], paper["diagonals"]) == ("11", [3.0, 3.0], None)
    mesh = case_from_specs("hp", f"mesh:{HEXAGON}", edge_length=1.0).metadata()
    assert mesh["edge_length_m"] == 1.0 and len(mesh["footprint_m"]) == 6
    assert json.loads(json.dumps(mesh)) == mesh


# ------------------------------------------------------------------------------ end to end
def test_generate_on_a_6_by_4_grid(tmp_path):
    """A 6 m x 4 m roof on grid:7x5 down to DOF 1 (the 12 m x 8 m grid:15x9 run of
    docs/benchmarks.md takes minutes, most of them tracing the folding motion of its 41
    solutions)."""
    expr = "0.06*x*(6-x) + 0.05*y*(4-y)"
    argv = ["generate", "--pattern", "grid:7x5", "--size", "6x4", "--surface", "expr"]
    code = main([*argv, "--expr", expr, "--no-deform", "--quiet", "--out", str(tmp_path)])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["final_dof"] == 1 and summary["stop"] == "target_reached"
    # with the deployability check, a design of the target DOF deploys by construction
    assert summary["final_deploys"] is True
    assert code == 0 and summary["verdict"]["outcome"] == "passed", summary["verdict"]
    assert summary["case"]["plan_size_m"] == [6.0, 4.0]
    files = sorted((tmp_path / "solutions").glob("*.fold"))
    # several creases per solve far from the target (--batch auto), one near it
    assert len(files) == summary["n_solutions"] >= 2
    dofs = [int(path.stem.split("_dof_")[1]) for path in files]
    assert dofs[0] == summary["initial_dof"] and dofs[-1] == 1
    # the run counts the DOF with a clear gap (its deployability check is on: issue 49):
    # near-mechanisms within dof_gap of the threshold are modes, so analyse with that count
    m = DEFAULTS.mechanism
    gap = DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
    for path in files:
        analysis = analyze_file(path, settings=gap)
        meta = analysis.data.metadata
        assert meta["F"] <= 1e-7 and meta["status"] == "converged"
        assert meta["pattern"] == "grid:7x5" and meta["plan_size_m"] == [6.0, 4.0]
        assert len(analysis.mechanism.locked_creases) == 0
    assert analysis.mechanism.dof == 1
    xy = analysis.data.pattern.coords[:, :2]
    assert np.allclose(xy.min(axis=0), [0, 0], atol=1e-6)
    assert np.allclose(np.ptp(xy, axis=0), [6, 4], atol=1e-6)


# ------------------------------------- issue 30, item 5: the real triangle count of a pattern
def circle(n: int, radius: float = 3.0) -> str:
    """A mesh: footprint of n corners on a circle."""
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return ";".join(f"{radius * math.cos(a):.9f},{radius * math.sin(a):.9f}" for a in angle)


def test_mesh_footprint_with_many_corners_is_refused_before_triangle(tmp_path, capsys):
    """A polygon of 30,000 corners made 178,266 triangles (the limit was checked on an
    estimate from the area): its outline points are counted before Triangle runs."""
    path = tmp_path / "outline.txt"
    path.write_text(circle(30_000).replace(";", "\n"))
    code = main(
        ["optimize", "--surface", "dome", "--pattern", f"mesh:{path}", "--out", str(tmp_path / "o")]
    )
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "has 30000 points on its outline: at least 29998 triangles, more than 20000 " in err
    assert "(Settings.limits.max_pattern_faces)" in err and not (tmp_path / "o").exists()


def test_mesh_pattern_is_checked_on_its_real_triangle_count():
    """Triangle's refinement adds points: the count after it is checked, not only the
    estimate from the area (here 7) and the outline's points (40)."""
    spec = f"mesh:{circle(40)}"
    plan = specs.parse_pattern(spec, edge_length=3.0)
    assert len(plan.faces) == 120
    settings = DEFAULTS.with_(max_pattern_faces=100)
    with pytest.raises(ValueError) as info:
        specs.parse_pattern(spec, edge_length=3.0, settings=settings)
    assert str(info.value) == (
        f"pattern {spec!r} has 120 triangles, more than 100 (Settings.limits.max_pattern_faces)"
    )


def test_svg_and_fold_files_are_checked_on_their_triangles(tmp_path, capsys):
    """An SVG of 110 x 110 grid lines (23,762 triangles) reached CasADi and failed there with a
    RuntimeError; a FOLD file of too many faces was never checked."""
    lines = "".join(
        f'<line x1="{x:.4f}" y1="0" x2="{x:.4f}" y2="100" stroke="red"/>'
        f'<line x1="0" y1="{x:.4f}" x2="100" y2="{x:.4f}" stroke="blue"/>'
        for x in 100 * np.arange(1, 111) / 111
    )
    svg = tmp_path / "grid.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
        f'<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>{lines}</svg>'
    )
    code = main(
        ["optimize", "--surface", "dome", "--pattern", str(svg), "--out", str(tmp_path / "o")]
    )
    assert code == 2 and capsys.readouterr().err == (
        f"rigidfold: error: {svg}: its 12321 faces make 24642 triangles, more than 20000 "
        "(Settings.limits.max_pattern_faces)\n"
    )
    xy, faces = patterns.grid(9, 9, 3.0, 3.0)
    fold = tmp_path / "grid.fold"
    fold.write_text(
        json.dumps(
            {
                "vertices_coords": np.column_stack([xy, np.zeros(len(xy))]).tolist(),
                "faces_vertices": faces.tolist(),
            }
        )
    )
    assert len(specs.parse_pattern(str(fold)).faces) == 128
    small = DEFAULTS.with_(max_pattern_faces=100)
    with pytest.raises(ValueError, match=r"has 128 triangles, more than 100 \(Settings"):
        specs.parse_pattern(str(fold), settings=small)
    with pytest.raises(ValueError, match=r"make 24642 triangles, more than 100 \(Settings"):
        specs.parse_pattern(str(svg), settings=small)
    assert not (tmp_path / "o").exists()
