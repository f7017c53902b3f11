"""The structure check's robustness (issue 39): frequencies asked beyond the model's size,
numbers that overflow, units on loads, files written together, the figure's colour bar and
outline, OpenSees's words at exit, the size limit."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from conftest import folded_grid, run_cli
from rigidfold.cli.structure_specs import parse_load, read_structure_options
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate.options import GenerateOptions
from rigidfold.io import write_fold
from rigidfold.mesh import CreasePattern
from rigidfold.structure import (
    MATERIALS,
    Material,
    Pins,
    Point,
    StructureOptions,
    StructureStatus,
    Supports,
    Uniform,
    auto_supports,
    check_structure,
    check_supports,
    write_structure,
)
from rigidfold.structure.design import plan_design
from rigidfold.structure.figure import deflection_figure, deflection_png
from rigidfold.structure.supports import SupportModes


def square(n: int = 3, size: float = 1.0) -> CreasePattern:
    """One flat panel ``size`` square: an n x n vertex grid, every crease fixed."""
    xs = np.linspace(0, size, n)
    X, Y = np.meshgrid(xs, xs)
    faces = []
    for b in range(n - 1):
        for a in range(n - 1):
            v = b * n + a
            faces += [(v, v + 1, v + n + 1), (v, v + n + 1, v + n)]
    p = CreasePattern.from_faces(np.column_stack([X.ravel(), Y.ravel()]), np.array(faces))
    return p.with_fixed(~p.is_boundary_edge)


def checked(p: CreasePattern, **kw):
    rigidity = check_supports(p, Supports(p.boundary_vertices))
    common = dict(material=MATERIALS["plywood"], thickness=0.018, modes=0)
    return check_structure(p, rigidity, **(common | kw))


# ------------------------------------------------------------------ item 3: --modes 1000
def test_more_modes_than_the_model_has_gives_all_it_has():
    check = checked(square(), modes=1000)
    freq = check.response.frequencies
    assert len(freq) >= 1 and np.all(np.isfinite(freq)) and np.all(np.diff(freq) >= 0)
    note = check.response.message
    assert "1000 asked" in note and "stderr" not in note


# ------------------------------------------------------------------ items 8, 10: overflow
@pytest.mark.parametrize(
    "changes",
    [
        {"thickness": 1e300},
        {"loads": ("uniform=1e300",)},
        {"loads": ("point=0:0,0,-1e300",)},
        {"loads": ("pressure=1e306",)},
        {"material": "10e9,0.3,1e308"},
        {"hinge_stiffness": 1e300},
    ],
)
def test_numbers_that_overflow_are_refused_when_the_options_are_made(changes):
    with pytest.raises(RigidfoldError, match="max_structure_value") as err:
        read_structure_options(**changes)
    assert "\n" not in str(err.value)


def test_the_library_refuses_them_too():
    p = square()
    with pytest.raises(RigidfoldError, match="max_structure_value"):
        checked(p, thickness=1e300)
    with pytest.raises(RigidfoldError, match="max_structure_value"):
        checked(p, loads=(Point(4, (0.0, 0.0, -1e300)),))


def test_generate_refuses_them_before_the_run():
    with pytest.raises(RigidfoldError, match="max_structure_value"):
        GenerateOptions(structure=StructureOptions(loads=(Uniform(1e300),)))


@pytest.mark.parametrize(
    "args",
    [
        ("--thickness", "1e300"),
        ("--load", "uniform=1e300"),
        ("--load", "point=4:0,0,-1e300"),
        ("--material", "10e9,0.3,1e308"),
        ("--load", "pressure=1e306"),
    ],
)
def test_cli_refuses_them_in_one_line(square_file, tmp_path, args):
    out = tmp_path / "x"
    res = run_cli("structure", str(square_file), "--out", str(out), *args)
    assert res.returncode == 2, res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert "max_structure_value" in res.stderr
    assert not out.exists() or not any(out.iterdir())


def test_non_finite_displacements_are_not_converged_and_not_drawn(tmp_path):
    """A modulus far below any material's (allowed: only magnitudes above the limit are
    refused): the displacements overflow; the verdict says so, the figure is not drawn and
    structure.json is strict JSON."""
    check = checked(square(), material=Material(1e-300, 0.3, 700.0))
    assert check.status is StructureStatus.NOT_CONVERGED
    assert deflection_png(check) is None
    written = write_structure(check, tmp_path, "square")
    assert [p.name for p in written] == ["structure.json"]
    json.loads((tmp_path / "structure.json").read_text())


# ------------------------------------------------------------------ item 12: files together
def test_files_are_written_together_or_not_at_all(tmp_path, monkeypatch):
    import errno

    import rigidfold.io.files as files

    check = checked(square())
    real = files._create_temp

    def full_disk(directory, name):  # the second file finds the disk full
        if name == "structure.png":
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(directory, name)

    monkeypatch.setattr(files, "_create_temp", full_disk)
    with pytest.raises(RigidfoldError) as err:
        write_structure(check, tmp_path, "square")
    assert "none written" in str(err.value) and "disk is full" in str(err.value)
    assert not list(tmp_path.iterdir())
    monkeypatch.setattr(files, "_create_temp", real)
    names = [p.name for p in write_structure(check, tmp_path, "square")]
    assert names == ["structure.json", "structure.png"]


# ------------------------------------------------------------------ item 15: units on loads
def test_loads_take_units():
    assert parse_load("uniform=0.5kPa") == parse_load("uniform=500Pa") == parse_load("uniform=0.5")
    assert parse_load("pressure=-0.5 kN/m2").kpa == -0.5
    assert parse_load("point=3:0,0,-2kN").force == (0.0, 0.0, -2000.0)
    assert parse_load("point=3:0,0,-2000").force == (0.0, 0.0, -2000.0)
    for bad in ("uniform=0.5kg", "point=3:0,0,-2kPa", "uniform=kPa"):
        with pytest.raises(RigidfoldError, match=r"unit|number"):
            parse_load(bad)


def test_cli_takes_units_on_loads_and_thickness(square_file, tmp_path):
    res = run_cli(
        "structure",
        str(square_file),
        "--out",
        str(tmp_path),
        "--supports",
        "0,2,6,8",
        "--thickness",
        "20mm",
        "--load",
        "uniform=0.5kPa",
        "--modes",
        "0",
        "--json",
    )
    assert res.returncode in (0, 1), res.stderr
    data = json.loads(res.stdout)
    assert data["thickness_m"] == pytest.approx(0.02)
    assert data["loads"] == [{"kind": "uniform", "kPa": 0.5}]


# ------------------------------------------------------------------ item 17: the figure
def test_figure_has_a_colour_bar_and_the_undeformed_outline():
    fig = deflection_figure(checked(square()))
    assert len(fig.axes) == 2  # the 3D view and its colour bar
    assert "displacement (mm)" in fig.axes[1].get_ylabel()
    labels = [c.get_label() for c in fig.axes[0].collections]
    assert "undeformed" in labels


# ------------------------------------------------------------------ item 18: at exit
def test_scripts_do_not_print_opensees_words_at_exit():
    script = textwrap.dedent(
        """
        import sys
        sys.path.insert(0, sys.argv[1])
        from test_structure_issue39 import checked, square
        print(checked(square()).status.value)
        print("done", file=sys.stderr)
        """
    )
    res = subprocess.run(
        [sys.executable, "-c", script, str(Path(__file__).parent)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert res.returncode == 0, res.stderr
    assert "Terminating" not in res.stderr and "Terminating" not in res.stdout
    assert res.stderr.strip().endswith("done")


# ------------------------------------------------------------------ item 6: size
def test_sparse_free_motions_match_the_dense_ones():
    """The sparse free motions (subspace iteration, Rayleigh-Ritz) of a design span the
    same motions as the dense singular value decomposition: the same count, DOF and
    near-mechanisms, and the same stiffness eigenvalues on a set of supports."""
    pattern = folded_grid(6, 0.3)
    dense = SupportModes(pattern, DEFAULTS.with_(structure_sparse_vertices=10_000))
    sparse = SupportModes(pattern, DEFAULTS.with_(structure_sparse_vertices=0))
    assert (sparse.n_modes, sparse.dof, sparse.near) == (dense.n_modes, dense.dof, dense.near)
    supports = Supports(pattern.boundary_vertices[::2])
    a, b = dense.stiffness(supports).eigenvalues, sparse.stiffness(supports).eigenvalues
    np.testing.assert_allclose(a, b, atol=1e-9 * a.max())


def test_sparse_auto_supports_are_rigid_and_each_is_needed():
    pattern = folded_grid(6, 0.3)
    settings = DEFAULTS.with_(structure_sparse_vertices=0, structure_max_support_sets=1)
    chosen = auto_supports(pattern, pattern.boundary_vertices, settings=settings)
    assert chosen.rigid
    dense = DEFAULTS.with_(structure_sparse_vertices=10_000)
    assert check_supports(pattern, chosen.supports, dense).rigid
    for v in chosen.supports.pinned:
        fewer = Supports(np.setdiff1d(chosen.supports.pinned, [v]))
        assert not SupportModes(pattern, dense).rigidity(fewer).rigid


def test_a_design_too_large_is_refused_in_one_line():
    pattern = folded_grid(6, 0.3)
    small = DEFAULTS.with_(structure_sparse_vertices=0, max_structure_bytes=1000)
    with pytest.raises(RigidfoldError, match="max_structure_bytes") as err:
        plan_design(pattern, StructureOptions(), settings=small)
    assert "\n" not in str(err.value)


@pytest.fixture(scope="module")
def square_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("square") / "square.fold"
    write_fold(path, square())
    return path


def test_long_steps_report_progress():
    """A large design (here: any, with ``structure_sparse_vertices`` 0) says each step as it
    starts; a small one stays quiet for its first seconds."""
    lines: list[str] = []
    large = DEFAULTS.with_(structure_sparse_vertices=0)
    options = StructureOptions(supports=Pins((0, 2, 6, 8)), modes=1)
    plan_design(square(), options, settings=large, progress=lines.append).check()
    assert [line.split()[0] for line in lines] == ["supports:", "linear", "natural"]
    assert all(line.endswith(" s)") for line in lines)
    quiet: list[str] = []
    plan_design(square(), options, progress=quiet.append).check()
    assert quiet == []


def test_too_many_flexes_for_the_second_order_check_are_refused_in_one_line():
    """A flat grid on its boundary leaves a first-order motion per inner vertex: their
    second-order check (a stress matrix per constraint on the flexes) is sized first."""
    flat = square(6)
    flat = flat.with_fixed(np.zeros(flat.n_edges, dtype=bool))
    small = DEFAULTS.with_(max_structure_bytes=10_000)
    with pytest.raises(RigidfoldError, match="second-order check") as err:
        check_supports(flat, Supports(flat.boundary_vertices), small)
    assert "\n" not in str(err.value)


# ------------------------------------------------------------------ item 16: fabricate's thickness
def test_structure_reads_the_thickness_fabricate_recorded(tmp_path):
    """``rigidfold fabricate`` writes ``NAME_fabricate.json`` with ``thickness_m``: beside
    the design, or in a run's ``final/thick/`` for ``solutions/NAME.fold``. Without
    ``--thickness`` the check uses it and says so; ``--thickness`` still wins."""
    from rigidfold.fabricate.files import FABRICATE_JSON

    run = tmp_path / "run"
    (run / "solutions").mkdir(parents=True)
    (run / "final" / "thick").mkdir(parents=True)
    design = run / "solutions" / "step.fold"
    write_fold(design, square())
    record = run / "final" / "thick" / FABRICATE_JSON.format("step")
    record.write_text(json.dumps({"file": "solutions/step.fold", "thickness_m": 0.02}))
    common = ["--supports", "0,2,6,8", "--modes", "0", "--json"]
    res = run_cli("structure", str(design), "--out", str(tmp_path / "a"), *common)
    assert res.returncode in (0, 1), res.stderr
    data = json.loads(res.stdout)
    assert data["thickness_m"] == 0.02 and "fabricate" in data["thickness_from"]
    assert "20 mm thick, as fabricate made them" in res.stderr
    res = run_cli(
        "structure", str(design), "--out", str(tmp_path / "b"), "--thickness", "18mm", *common
    )
    data = json.loads(res.stdout)
    assert data["thickness_m"] == pytest.approx(0.018) and data["thickness_from"] == "given"
    record.unlink()
    res = run_cli("structure", str(design), "--out", str(tmp_path / "c"), *common)
    data = json.loads(res.stdout)
    assert data["thickness_m"] == DEFAULTS.structure.thickness
    assert data["thickness_from"].startswith("default")
