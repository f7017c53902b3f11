"""Target surfaces from triangle meshes: file formats, the fit, its derivatives, the footprint,
read errors and problem (6) on a dome given as a mesh.

The generic surface checks (gradient and Hessian against differences, CasADi against NumPy)
run on a MeshSurface too: ``tests/test_surfaces.py``, surface "mesh".
"""

from __future__ import annotations

import pickle
import re
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from conftest import dome_mesh
from rigidfold import patterns
from rigidfold.config import DEFAULTS
from rigidfold.optimize import FormFindingProblem
from rigidfold.surfaces import MESH_FORMATS, Dome, MeshSurface, mesh_surface, read_mesh

DATA = Path(__file__).parent / "data"
DOME = Dome()


def write_mesh(path: Path, vertices: np.ndarray, triangles: np.ndarray) -> Path:
    import trimesh

    trimesh.Trimesh(vertices, triangles, process=False).export(path)
    return path


def write_text(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def fine_dome_obj(tmp_path_factory) -> Path:
    """A fine triangulation of the built-in dome's formula as an OBJ file (121 x 121 vertices)."""
    return write_mesh(tmp_path_factory.mktemp("mesh") / "dome.obj", *dome_mesh(121))


@pytest.fixture(scope="module")
def fine_dome(fine_dome_obj) -> MeshSurface:
    return mesh_surface(fine_dome_obj)


# ---------------------------------------------------------------- files
@pytest.mark.parametrize("kind", MESH_FORMATS)
def test_each_format_reads(tmp_path, kind):
    vertices, triangles = dome_mesh(9)
    path = write_mesh(tmp_path / f"dome.{kind.upper()}", vertices, triangles)
    read_v, read_t = read_mesh(path)
    assert read_v.dtype == np.float64 and read_t.dtype == np.int64
    # STL stores float32 corners, without shared vertices
    assert np.allclose(read_v[read_t], vertices[triangles], atol=1e-6)
    surface = mesh_surface(path)
    assert surface.source == f"dome.{kind.upper()}"
    assert np.allclose(surface.height(vertices[:, 0], vertices[:, 1]), vertices[:, 2], atol=1e-6)


def test_y_up_file_is_turned_z_up():
    vertices, triangles = read_mesh(DATA / "dome_yup.obj", up="y")
    expected, _ = dome_mesh(9)
    assert np.allclose(vertices, expected, atol=1e-6)
    assert np.array_equal(triangles, dome_mesh(9)[1])
    surface = mesh_surface(DATA / "dome_yup.obj", up="y")
    assert surface.bounds.tolist() == [[0.0, 0.0], [3.0, 3.0]]
    with pytest.raises(ValueError, match=r"dome_yup.obj: .*zero area.*y-up\? \(--up y\)"):
        read_mesh(DATA / "dome_yup.obj")


def test_a_scene_of_several_meshes_is_concatenated(tmp_path):
    path = write_text(
        tmp_path / "two.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 2 4 3\n",
    )
    vertices, triangles = read_mesh(path)
    assert len(triangles) == 2
    assert np.allclose(
        np.sort(vertices[triangles].reshape(-1, 3), axis=0)[[0, -1]], [[0, 0, 0], [1, 1, 0]]
    )


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("surface.xyz", "", r"mesh .*surface.xyz: unknown extension '.xyz' \(read: .obj, .stl"),
        ("surface", "", r"unknown extension ''"),
        ("empty.obj", "", r"empty.obj: no triangles"),
        ("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", r"points.obj: no triangles"),
        (
            "bad.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n",
            r"cannot read mesh .*bad.ply as PLY \(\w+: ",
        ),
        (
            "nan.obj",
            "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            r"nan.obj: vertex 0 has non-finite coordinates",
        ),
        (
            "wall.obj",
            "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nf 1 2 3\nf 2 4 3\n",
            r"wall.obj: .*zero area.*--up y",
        ),
    ],
)
def test_read_errors_name_the_file(tmp_path, name, text, match):
    path = write_text(tmp_path / name, text)
    with pytest.raises(ValueError, match=match) as info:
        read_mesh(path)
    assert "\n" not in str(info.value)


def test_missing_file_and_bad_up_axis(tmp_path):
    with pytest.raises(ValueError, match=r"cannot read mesh .*none.obj: no such file"):
        read_mesh(tmp_path / "none.obj")
    (tmp_path / "folder.obj").mkdir()
    with pytest.raises(ValueError, match=r"cannot read mesh .*folder.obj: no such file"):
        read_mesh(tmp_path / "folder.obj")
    with pytest.raises(ValueError, match=r"up must be z or y, got 'x'"):
        read_mesh(DATA / "dome_yup.obj", up="x")


def test_wall_read_y_up_suggests_z_up(tmp_path):
    path = write_text(tmp_path / "flat.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n")
    read_mesh(path, up="y")  # lies flat once turned
    path = write_text(tmp_path / "sheet.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"zero area.*z-up\? \(--up z\)"):
        read_mesh(path, up="y")


def test_a_closed_mesh_is_refused(tmp_path):
    import trimesh

    path = tmp_path / "box.stl"
    trimesh.creation.box((1.0, 1.0, 1.0)).export(path)
    with pytest.raises(ValueError, match=r"box.stl: .*zero area.*not a vertical or closed one"):
        read_mesh(path)


@pytest.mark.parametrize(
    ("vertices", "triangles", "match"),
    [
        (np.zeros((3, 2)), [[0, 1, 2]], r"mesh test: vertices must be an \(N, 3\) array"),
        (np.eye(3), [[0, 1]], r"triangles must be an \(M, 3\) array"),
        (np.eye(3), [[0.0, 1.0, 2.0]], r"triangles must be an \(M, 3\) array"),
        (np.eye(3), np.zeros((0, 3), dtype=int), r"no triangles"),
        (np.eye(3), [[0, 1, 3]], r"refers to vertex 3, but there are 3 vertices"),
        (np.eye(3), [[0, -1, 2]], r"refers to vertex -1"),
    ],
)
def test_bad_arrays(vertices, triangles, match):
    with pytest.raises(ValueError, match=match):
        MeshSurface(vertices, np.asarray(triangles), source="test")


def test_trimesh_stays_out_of_the_import_path():
    code = (
        "import sys, rigidfold.surfaces, rigidfold.generate.case; print('trimesh' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


# ---------------------------------------------------------------- the fit
def test_fit_of_the_dome_mesh_against_the_analytic_dome(fine_dome):
    g = np.linspace(0.0, 3.0, 301)
    x, y = np.meshgrid(g, g)
    error = np.abs(fine_dome.height(x, y) - DOME.height(x, y)).max()
    assert error <= 1e-3  # measured 5.3e-4 (the mesh itself is 5.3e-4 off at the corners)
    assert fine_dome.fit_error <= 1e-3  # measured 5.2e-4
    meta = fine_dome.metadata()
    assert meta == {
        "name": "mesh",
        "source": "dome.obj",
        "vertices": 121 * 121,
        "triangles": 2 * 120 * 120,
        "grid": [65, 65],
        "fit_error_m": fine_dome.fit_error,
        "plan_bounds_m": [0.0, 0.0, 3.0, 3.0],
    }


def test_spline_interpolates_at_grid_nodes_and_is_smooth(fine_dome):
    """Exact at the nodes, and its Hessian (CasADi, through SX) matches second differences."""
    g = np.linspace(0.0, 3.0, 65)
    x, y = np.meshgrid(g[::8], g[::8])
    assert np.allclose(fine_dome.height(x, y), DOME.height(x, y), atol=6e-4)
    rng = np.random.default_rng(4)
    px, py = rng.uniform(0.2, 2.8, 40), rng.uniform(0.2, 2.8, 40)
    fxx, fxy, fyy = fine_dome.hessian(px, py)
    h = 1e-4
    z = fine_dome.height
    dxx = (z(px + h, py) - 2 * z(px, py) + z(px - h, py)) / h**2
    dyy = (z(px, py + h) - 2 * z(px, py) + z(px, py - h)) / h**2
    dxy = (z(px + h, py + h) - z(px + h, py - h) - z(px - h, py + h) + z(px - h, py - h)) / (
        4 * h * h
    )
    for exact, fd in ((fxx, dxx), (fxy, dxy), (fyy, dyy)):
        assert np.abs(exact - fd).max() <= 1e-4
    # near the analytic dome's curvature where the mesh is fine
    assert np.allclose(fxx, DOME.hessian(px, py)[0], atol=0.05)


def test_casadi_height_of_a_column_of_symbols(fine_dome):
    sx, sy = ca.SX.sym("x", 7), ca.SX.sym("y", 7)
    z = fine_dome.height(sx, sy, xp=ca)
    assert z.shape == (7, 1)
    x, y = np.linspace(0.1, 2.9, 7), np.linspace(2.5, 0.3, 7)
    fun = ca.Function("z", [sx, sy], [z, ca.jacobian(z, sx)])
    value, jac = fun(x, y)
    assert np.array_equal(np.asarray(value).ravel(), fine_dome.height(x, y))
    assert np.allclose(np.diag(np.asarray(jac)), fine_dome.gradient(x, y)[0], rtol=1e-12)


def test_disc_footprint_is_continued_smoothly():
    vertices, triangles = dome_mesh(121)
    r = np.hypot(vertices[:, 0] - 1.5, vertices[:, 1] - 1.5)
    disc = MeshSurface(vertices, triangles[(r[triangles] <= 1.4).all(axis=1)])
    assert disc.fit_error <= 1e-3  # measured 1.3e-4
    g = np.linspace(0.2, 2.8, 131)
    x, y = np.meshgrid(g, g)
    inside = np.hypot(x - 1.5, y - 1.5) <= 1.35
    assert np.abs(disc.height(x, y) - DOME.height(x, y))[inside].max() <= 1e-3


def test_overhang_takes_the_highest_hit():
    """A second sheet 1 m above part of a flat one: the surface seen from above."""
    low = [[0, 0, 0], [3, 0, 0], [3, 3, 0], [0, 3, 0]]
    high = [[1, 1, 1], [2, 1, 1], [2, 2, 1], [1, 2, 1]]
    surface = MeshSurface(
        np.array(low + high, dtype=float),
        np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]),
        settings=DEFAULTS.with_(surface_grid_nodes=13),
    )
    # grid nodes lie every 0.25 m: the spline passes through the top there
    assert surface.height(np.array([1.5, 0.25]), np.array([1.5, 2.75])).tolist() == pytest.approx(
        [1.0, 0.0], abs=1e-12
    )
    assert surface.fit_error >= 0.5  # the jump is no smooth surface, and it says so


def test_pickles(fine_dome):
    copy = pickle.loads(pickle.dumps(fine_dome))
    x, y = np.array([0.3, 1.7]), np.array([2.2, 0.9])
    assert np.array_equal(copy.height(x, y), fine_dome.height(x, y))


# ---------------------------------------------------------------- the footprint
def test_check_finite_names_the_first_point_outside():
    vertices, triangles = dome_mesh(31)
    r = np.hypot(vertices[:, 0] - 1.5, vertices[:, 1] - 1.5)
    disc = MeshSurface(vertices, triangles[(r[triangles] <= 1.41).all(axis=1)], source="disc.obj")
    disc.check_finite(np.array([1.5, 1.0]), np.array([1.5, 2.0]))
    with pytest.raises(
        ValueError,
        match=r"plan point 2 at \(x, y\) = \(0.2, 0.3\) lies outside "
        r"the footprint of mesh disc.obj \(plan box x 0.1..2.9, y 0.1..2.9 m\)",
    ):
        disc.check_finite(np.array([1.5, 1.0, 0.2, 0.1]), np.array([1.5, 2.0, 0.3, 0.1]))
    with pytest.raises(ValueError, match=r"plan point 0 at \(x, y\) = \(nan, 1\)"):
        disc.check_finite(np.array([np.nan]), np.array([1.0]))


def test_footprint_tolerance(fine_dome):
    tol = DEFAULTS.inputs.surface_footprint_tol * 3.0
    fine_dome.check_finite(np.array([-0.9 * tol, 3.0 + 0.9 * tol]), np.array([1.0, 3.0]))
    with pytest.raises(ValueError, match=r"plan point 1 at"):
        fine_dome.check_finite(np.array([1.0, 3.0 + 1.1 * tol]), np.array([1.0, 2.0]))


def test_grid_settings_are_checked():
    for nodes in (3, 514, 10.0, True):
        with pytest.raises(ValueError, match="surface_grid_nodes must be an integer from 4 to 513"):
            DEFAULTS.with_(surface_grid_nodes=nodes)
    with pytest.raises(ValueError, match="surface_footprint_tol must be a finite number >= 0"):
        DEFAULTS.with_(surface_footprint_tol=-1.0)


def test_a_coarse_grid_still_has_four_nodes_a_side():
    vertices = np.array([[0, 0, 0], [10, 0, 1], [10, 0.02, 1], [0, 0.02, 0]], dtype=float)
    strip = MeshSurface(vertices, np.array([[0, 1, 2], [0, 2, 3]]))
    assert strip.grid_shape == (65, 4)
    assert strip.height(np.array([5.0]), np.array([0.01]))[0] == pytest.approx(0.5)


# ---------------------------------------------------------------- problem (6)
def test_form_finding_on_the_dome_mesh(fine_dome):
    """Pattern 11 on the dome given as a mesh: converges like on the built-in dome."""
    pattern = patterns.build(patterns.PaperPattern("11"), fine_dome)
    result = FormFindingProblem(pattern, fine_dome).solve()
    assert result.converged
    assert result.F <= DEFAULTS.design.f_tol  # measured 2e-17
    c = result.pattern.coords
    assert np.abs(c[:, 2] - DOME.height(c[:, 0], c[:, 1])).max() <= DEFAULTS.design.dz + 1e-3


# ----------------------------------------------- issue 30, item 4: the size of a target mesh
def fan(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A cone of n long thin triangles around its apex over the unit disc (a fan)."""
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    rim = np.column_stack([np.cos(angle), np.sin(angle), np.zeros(n)])
    vertices = np.vstack([[0.0, 0.0, 1.0], rim])
    k = np.arange(n)
    return vertices, np.column_stack([np.zeros(n, dtype=np.int64), k + 1, (k + 1) % n + 1])


def test_a_fan_is_fitted_in_linear_memory():
    """A fan's triangles have bounding boxes over most of the plan: every point was paired
    with most triangles (20,000 of them: 67 s and 5.5 GB, then a MemoryError). The pairs are
    now found along each triangle's columns of buckets, in batches of bounded size."""
    import tracemalloc

    from rigidfold.surfaces.mesh import _candidates

    vertices, triangles = fan(4000)
    plan = vertices[triangles][:, :, :2]
    g = np.linspace(-1, 1, 65)
    points = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    batches = list(_candidates(points, plan, 1e-5, batch=10_000))
    pairs = sum(len(p) for p, _ in batches)
    # about the triangles' widths in bucket columns (4,000 x some 40), not the points in
    # their boxes (about a third of 4,225 points x 4,000 triangles before)
    assert pairs < len(points) * len(triangles) / 50
    assert max(len(p) for p, _ in batches) <= 10_000 + 4225  # a batch, or one column's points
    for p, t in batches:
        assert len(np.unique(p * len(triangles) + t)) == len(p)  # each pair once
    tracemalloc.start()
    surface = MeshSurface(vertices, triangles, source="fan")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 200e6, peak
    assert surface.fit_error < 0.05  # the cone's tip and rim smoothed by the spline
    assert float(surface.height(0.5, 0.0)) == pytest.approx(0.5, abs=0.02)


def test_candidates_are_a_superset_of_the_hits():
    """Every point inside (or within the tolerance of) a triangle is a candidate of it."""
    from rigidfold.surfaces.mesh import _candidates

    rng = np.random.default_rng(3)
    plan = rng.uniform(0, 1, (300, 3, 2))
    plan[:100] *= [1.0, 0.02]  # thin ones
    points = rng.uniform(-0.1, 1.1, (2000, 2))
    tol = 0.01
    found = set()
    for p, t in _candidates(points, plan, tol, batch=777):
        found.update(zip(p.tolist(), t.tolist(), strict=True))
    import shapely

    polygons = shapely.polygons(plan)
    near = shapely.STRtree(polygons).query(shapely.points(points), "dwithin", distance=tol)
    assert set(zip(*near.tolist(), strict=True)) <= found


def test_too_many_triangles_are_refused_in_one_line(tmp_path):
    """Settings.limits.max_mesh_triangles bounds a target mesh: MeshSurface and read_mesh refuse one
    line; a binary STL file by its header, before trimesh loads it (a 2-million-face STL took
    8.9 GB before)."""
    small = DEFAULTS.with_(max_mesh_triangles=100)
    vertices, triangles = fan(200)
    message = (
        "200 triangles, more than 100 (Settings.limits.max_mesh_triangles): decimate the mesh; the "
        "surface is sampled on at most 513 x 513 grid nodes"
    )
    with pytest.raises(ValueError, match=f"^mesh fan: {re.escape(message)}$"):
        MeshSurface(vertices, triangles, source="fan", settings=small)
    path = write_mesh(tmp_path / "fan.obj", vertices, triangles)
    with pytest.raises(ValueError, match=f"^{re.escape(f'mesh {path}: {message}')}$"):
        read_mesh(path, settings=small)
    stl = tmp_path / "huge.stl"  # 2,000,000 triangles by its header, sparse on disk
    with stl.open("wb") as file:
        file.write(b"\0" * 80 + (2_000_000).to_bytes(4, "little"))
        file.truncate(84 + 50 * 2_000_000)
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            "import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30)); "
            "from rigidfold.cli.commands import main; sys.exit(main(sys.argv[1:]))",
            "optimize",
            "--surface",
            f"mesh:{stl}",
            "--pattern",
            "1",
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == (
        f"rigidfold: error: mesh {stl}: 2000000 triangles, more than 500000 "
        "(Settings.limits.max_mesh_triangles): decimate the mesh; the surface is sampled on at "
        "most "
        "513 x 513 grid nodes\n"
    )
    with pytest.raises(ValueError, match="max_mesh_triangles must be an integer >= 1"):
        DEFAULTS.with_(max_mesh_triangles=0)
