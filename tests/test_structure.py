"""rigidfold structure: the shell model against closed forms, reactions against loads, and the
supports' first-order rigidity against an independent rank computation."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import files_of, folded_grid, run_cli, run_cli_size_limited
from rigidfold.cli.structure_specs import parse_limit, parse_load
from rigidfold.config import DEFAULTS
from rigidfold.frame.model import default_support_face
from rigidfold.io import read_fold, write_fold
from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import face_areas
from rigidfold.structure import (
    MATERIALS,
    Material,
    StructureStatus,
    Supports,
    Uniform,
    auto_supports,
    check_structure,
    check_supports,
)

DATA = Path(__file__).parent / "data"


def plate(nx: int, ny: int, lx: float, ly: float) -> CreasePattern:
    """One flat panel lx x ly metres: an nx x ny vertex grid, every crease fixed."""
    xs, ys = np.linspace(0, lx, nx), np.linspace(0, ly, ny)
    X, Y = np.meshgrid(xs, ys)
    faces = []
    for b in range(ny - 1):
        for a in range(nx - 1):
            v = b * nx + a
            faces += [(v, v + 1, v + nx + 1), (v, v + nx + 1, v + nx)]
    p = CreasePattern.from_faces(np.column_stack([X.ravel(), Y.ravel()]), np.array(faces))
    return p.with_fixed(~p.is_boundary_edge)


def solve_plate(p, material, thickness, *, pinned=(), clamped=(), kpa=1.0, modes=0):
    supports = Supports(np.array(pinned, dtype=np.int64), np.array(clamped, dtype=np.int64))
    rigidity = check_supports(p, supports)
    assert rigidity.rigid
    return check_structure(
        p,
        rigidity,
        material=material,
        thickness=thickness,
        loads=(Uniform(kpa),),
        self_weight=False,
        modes=modes,
    )


def independent_kernel(pattern: CreasePattern, pinned) -> int:
    """Dimension of the first-order motions of ``pattern`` with ``pinned`` vertices held,
    from the rigid-folding constraint Jacobian (edge lengths, fixed creases) of
    rigidfold.mechanism.rigid_folding, its gauge rows replaced by the pinned vertices' rows:
    no frame model, no support search."""
    cons = RigidFoldingConstraints(pattern, default_support_face(pattern))
    J = cons.jacobian(cons.x0)[0].toarray()[:-6]
    rows = np.zeros((3 * len(pinned), J.shape[1]))
    for k, v in enumerate(pinned):
        rows[3 * k : 3 * k + 3, 3 * v : 3 * v + 3] = np.eye(3)
    A = np.vstack([J, rows])
    sv = np.linalg.svd(A, compute_uv=False)
    return A.shape[1] - int(np.sum(sv > 1e-9 * sv[0]))


# ------------------------------------------------------------------ closed forms
def test_plate_strip_between_plate_and_beam_formula():
    """4 m x 0.5 m, 50 mm, E = 10 GPa, nu = 0.3, pinned along both short ends, 1 kPa:
    w = 5 q L^4 / (384 D) with D = E t^3 / 12 (plate, cylindrical bending) or E t^3 / 12
    (beam, per unit width); the shell lies between them within 3 %."""
    mat, t, L = Material(10e9, 0.3, 700.0), 0.05, 4.0
    p = plate(17, 3, L, 0.5)
    ends = np.flatnonzero(np.isclose(p.coords[:, 0], 0) | np.isclose(p.coords[:, 0], L))
    check = solve_plate(p, mat, t, pinned=ends)
    w = float(np.abs(check.response.displacements[:, 2]).max())
    w_plate = 5 * 1e3 * L**4 / (384 * mat.plate_rigidity(t))
    w_beam = 5 * 1e3 * L**4 / (384 * mat.E * t**3 / 12)
    assert 0.97 * w_plate <= w <= 1.03 * w_beam
    assert check.balance_error < 1e-6


def test_cantilever_tip_deflection():
    """A 2 m x 0.5 m cantilever plate clamped along one short side, 20 mm, nu = 0 (plate and
    beam coincide), 1 kPa: tip deflection q L^4 / (8 D) within 3 %; first frequency
    1.875^2 / (2 pi) sqrt(D / (rho t L^4)) within 3 %."""
    mat, t, L = Material(10e9, 0.0, 700.0), 0.02, 2.0
    p = plate(9, 3, L, 0.5)
    root = np.flatnonzero(np.isclose(p.coords[:, 0], 0))
    check = solve_plate(p, mat, t, clamped=root, modes=1)
    D = mat.plate_rigidity(t)
    w = float(np.abs(check.response.displacements[:, 2]).max())
    assert w == pytest.approx(1e3 * L**4 / (8 * D), rel=0.03)
    f1 = 1.875**2 / (2 * math.pi) * math.sqrt(D / (mat.density * t * L**4))
    assert check.response.frequencies[0] == pytest.approx(f1, rel=0.03)


def test_simply_supported_square_plate():
    """A 2 m square plate, 20 mm, nu = 0.3, pinned along its boundary, 1 kPa: Timoshenko's
    w_max = 0.00406 q a^4 / D and f_11 = pi / a^2 sqrt(D / (rho t)) within 3 %."""
    mat, t, a = Material(10e9, 0.3, 700.0), 0.02, 2.0
    p = plate(9, 9, a, a)
    check = solve_plate(p, mat, t, pinned=p.boundary_vertices, modes=1)
    D = mat.plate_rigidity(t)
    w = float(np.abs(check.response.displacements[:, 2]).max())
    assert w == pytest.approx(0.00406 * 1e3 * a**4 / D, rel=0.03)
    f11 = math.pi / a**2 * math.sqrt(D / (mat.density * t))
    assert check.response.frequencies[0] == pytest.approx(f11, rel=0.03)


def test_nonlinear_matches_linear_under_a_small_load_and_stiffens_under_a_large_one():
    """Geometrically nonlinear (corotational): the linear answer while the deflection is a
    small part of the thickness; less deflection once the strip, its ends held apart,
    carries the load as a membrane too."""
    mat, t, L = Material(10e9, 0.3, 700.0), 0.05, 4.0
    p = plate(9, 3, L, 0.5)
    ends = np.flatnonzero(np.isclose(p.coords[:, 0], 0) | np.isclose(p.coords[:, 0], L))
    rigidity = check_supports(p, Supports(ends))
    for kpa, same in ((0.01, True), (2.0, False)):
        common = dict(
            material=mat,
            thickness=t,
            loads=(Uniform(kpa),),
            self_weight=False,
            modes=0,
        )
        lin = check_structure(p, rigidity, **common)
        nonlin = check_structure(p, rigidity, nonlinear=True, **common)
        assert nonlin.response.converged and nonlin.response.load_factor == pytest.approx(1.0)
        if same:
            assert nonlin.max_displacement == pytest.approx(lin.max_displacement, rel=0.01)
        else:
            assert nonlin.max_displacement < 0.9 * lin.max_displacement


# ------------------------------------------------------------------ a small design
@pytest.fixture(scope="module")
def design() -> CreasePattern:
    """A generic folded 4 x 4 grid of DOF 9."""
    return folded_grid(4, 0.3)


@pytest.fixture(scope="module")
def chosen(design):
    return auto_supports(design, design.boundary_vertices)


def test_auto_supports_are_first_order_rigid(design, chosen):
    """The chosen supports leave no first-order motion by an independent rank computation;
    removing any one of them is reported as a mechanism, and is one."""
    assert chosen.rigid and chosen.dof == 9
    pinned = chosen.supports.pinned
    assert set(pinned) <= set(design.boundary_vertices.tolist())
    assert len(pinned) >= math.ceil((chosen.dof + 6) / 3)
    assert independent_kernel(design, pinned) == 0
    for v in pinned:
        fewer = Supports(np.setdiff1d(pinned, [v]))
        left = check_supports(design, fewer)
        assert not left.rigid
        assert left.mode is not None and "mechanism" in left.mode
        assert independent_kernel(design, fewer.pinned) >= 1


def test_reactions_balance_the_loads(design, chosen):
    loads = (
        parse_load("uniform=0.6"),
        parse_load("pressure=0.4"),
        parse_load("point=5:100,-50,-800"),
    )
    check = check_structure(
        design, chosen, material=MATERIALS["plywood"], thickness=0.018, loads=loads, modes=2
    )
    total = check.total_load
    assert check.response.converged
    assert np.linalg.norm(check.response.reactions.sum(axis=0) + total) <= 1e-3 * np.linalg.norm(
        total
    )
    assert check.balance_error < 1e-3
    d = check.to_dict()
    assert set(d["reactions_N"]) == {str(v) for v in chosen.supports.pinned}
    assert len(d["frequencies_Hz"]) == 2 and d["frequencies_Hz"][0] > 0
    assert d["max_von_mises_Pa"] > 0 and d["max_displacement_m"] > 0


def test_self_weight_is_the_panels_weight(design, chosen):
    mat = MATERIALS["steel"]
    check = check_structure(design, chosen, material=mat, thickness=0.004, modes=0)
    area = float(face_areas(design.coords, design.faces).sum())
    expected = mat.density * DEFAULTS.structure.gravity * 0.004 * area
    assert check.total_load[2] == pytest.approx(-expected, rel=1e-9)
    assert check.balance_error < 1e-3


def test_hinge_springs_carry_moments(design, chosen):
    k = 50.0
    check = check_structure(
        design,
        chosen,
        material=MATERIALS["plywood"],
        thickness=0.018,
        hinge_stiffness=k,
        modes=0,
    )
    rows = check.hinge_table()
    assert rows and max(r["max_moment_Nm_per_m"] for r in rows) > 0
    for r in rows:
        assert r["max_moment_Nm_per_m"] == pytest.approx(k * math.radians(r["max_rotation_deg"]))


def test_stiffer_hinges_deflect_less(design, chosen):
    common = dict(material=MATERIALS["plywood"], thickness=0.018, modes=0)
    free = check_structure(design, chosen, **common)
    stiff = check_structure(design, chosen, hinge_stiffness=1e4, **common)
    assert stiff.max_displacement < free.max_displacement


# ------------------------------------------------------------------ inputs
def test_material_presets_and_custom():
    from rigidfold.cli.units import parse_material

    assert parse_material("steel").E == 210e9
    assert parse_material("Aluminium").density == 2700
    custom = parse_material("10e9, 0.3, 700")
    assert (custom.E, custom.nu, custom.density) == (10e9, 0.3, 700)
    for bad in ("wood", "1,2", "1e9,0.6,700", "-1,0.3,7", "a,b,c", "1e9,0.3,nan"):
        with pytest.raises(ValueError):
            parse_material(bad)
    for material in (*MATERIALS.values(), custom, Material(2.1e11, 0.3, 7850.5)):
        assert Material.from_key(material.key) == material  # a record's one word
    assert MATERIALS["steel"].key == "steel" and custom.key == "10000000000,0.3,700"


def test_limit_and_load_parsing():
    assert parse_limit("L/250") == 250 and parse_limit("l/ 300") == 300
    for bad in ("L/0", "L/-3", "span", "L/x"):
        with pytest.raises(ValueError):
            parse_limit(bad)
    assert parse_load("uniform=1.2") == Uniform(1.2)
    assert parse_load("point=3:0,0,-10").force == (0.0, 0.0, -10.0)
    for bad in ("snow=1", "uniform=", "point=3:1,2", "point=x:1,2,3", "uniform=inf"):
        with pytest.raises(ValueError):
            parse_load(bad)


# ------------------------------------------------------------------ command line
@pytest.fixture(scope="module")
def design_file(tmp_path_factory, design):
    path = tmp_path_factory.mktemp("design") / "grid.fold"
    write_fold(path, design)
    return path


def test_cli_auto_writes_json_and_figure(design_file, tmp_path):
    out = tmp_path / "s"
    res = run_cli(
        "structure",
        str(design_file),
        "--out",
        str(out),
        "--load",
        "uniform=0.5",
        "--limit",
        "L/10",
        "--modes",
        "1",
        "--json",
    )
    assert res.returncode == 0, res.stderr
    data = json.loads(res.stdout)
    assert data["status"] == StructureStatus.PASSED
    assert data["supports"]["first_order_rigid"] and data["supports"]["chosen"] == "auto"
    assert (out / "structure.png").stat().st_size > 0
    saved = json.loads((out / "structure.json").read_text())
    for key in (
        "supports",
        "reactions_N",
        "total_load_N",
        "max_displacement_m",
        "max_displacement_at",
        "frequencies_Hz",
        "hinges",
        "max_von_mises_Pa",
    ):
        assert key in saved
    assert saved["balance_error"] < 1e-3


def test_a_failed_overwrite_keeps_the_earlier_files_and_names_the_cause(design_file, tmp_path):
    """Issue 47, item 5: ``structure --overwrite`` removed the earlier structure.json and
    structure.png before writing, so a write past the file size limit lost both. The new
    files are written aside first: the earlier ones stay as they were, and the message
    names the limit."""
    out = tmp_path / "s"
    args = ["structure", str(design_file), "--out", str(out), "--load", "uniform=0.5"]
    assert run_cli(*args).returncode in (0, 1)  # written whatever the verdict
    before = files_of(out)
    assert sorted(before) == ["structure.json", "structure.png"]
    res = run_cli_size_limited(min(len(b) for b in before.values()) // 2, *args, "--overwrite")
    err = res.stderr.strip()
    assert res.returncode == 2 and "file size limit" in err.splitlines()[-1], err
    assert files_of(out) == before


def test_cli_deflection_limit_decides_the_exit_code(design_file, tmp_path):
    res = run_cli(
        "structure",
        str(design_file),
        "--out",
        str(tmp_path),
        "--load",
        "uniform=5",
        "--limit",
        "L/100000",
        "--modes",
        "0",
    )
    assert res.returncode == 1
    assert "deflection" in res.stdout


def test_cli_supports_that_leave_a_mechanism(design_file, design, chosen, tmp_path):
    fewer = ",".join(str(v) for v in chosen.supports.pinned[1:])
    res = run_cli("structure", str(design_file), "--out", str(tmp_path), "--supports", fewer)
    assert res.returncode == 1
    assert "mechanism that folds crease" in res.stdout
    saved = json.loads((tmp_path / "structure.json").read_text())
    assert saved["status"] == "mechanism" and saved["supports"]["mode"]
    assert "reactions_N" not in saved


@pytest.mark.parametrize(
    "args",
    [
        ("--material", "cheese"),
        ("--load", "snow=1"),
        ("--limit", "L/0"),
        ("--supports", "1,999"),
        ("--thickness", "-1"),
        ("--actuators", "0"),
        ("--load", "point=999:0,0,-1"),
    ],
)
def test_cli_bad_input_is_one_line_exit_2(design_file, tmp_path, args):
    res = run_cli("structure", str(design_file), "--out", str(tmp_path / "x"), *args)
    assert res.returncode == 2
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert not (tmp_path / "x" / "structure.json").exists()


# ------------------------------------------------------------------ the 12 m x 8 m roof
@pytest.fixture(scope="module")
def roof() -> CreasePattern:
    """The README's roof: ``rigidfold generate --pattern grid:9x6 --size 12x8 --surface expr
    --expr "0.06*x*(12-x)/6 + 0.05*y*(8-y)" --no-deform``, its final design (DOF 1)."""
    return read_fold(DATA / "roof_12x8_dof1.fold").pattern


def test_roof_stands_on_auto_supports_under_self_weight(roof):
    """--supports auto and self-weight: first-order rigid by an independent rank
    computation, the reactions balance the panels' weight to 0.1 %, and removing any one
    support is reported as a mechanism (and is one, by the same rank computation)."""
    chosen = auto_supports(roof, roof.boundary_vertices)
    assert chosen.rigid and chosen.dof == 1
    pinned = chosen.supports.pinned
    assert independent_kernel(roof, pinned) == 0
    mat = MATERIALS["plywood"]
    check = check_structure(roof, chosen, material=mat, thickness=0.018, modes=0)
    area = float(face_areas(roof.coords, roof.faces).sum())
    weight = mat.density * DEFAULTS.structure.gravity * 0.018 * area
    assert check.total_load[2] == pytest.approx(-weight, rel=1e-9)
    assert check.response.converged and check.balance_error < 1e-3
    assert check.status is not StructureStatus.MECHANISM
    for v in pinned:
        fewer = check_supports(roof, Supports(np.setdiff1d(pinned, [v])))
        assert not fewer.stable and "mechanism" in fewer.mode
        assert independent_kernel(roof, fewer.supports.pinned) >= 1
