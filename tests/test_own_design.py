"""The user's own design through the command line: every source of a pattern and of a target
surface, end to end, and the bad inputs of each (one line, exit code 2)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import dome_mesh, main_code
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.surfaces import Dome

DATA = Path(__file__).parent / "data"
SIMPLE_VERTEX = DATA / "origami_simulator" / "simpleVertex.svg"
SQUARETWIST = DATA / "fold_examples" / "squaretwist.fold"


@pytest.fixture(scope="module")
def dome_obj(tmp_path_factory) -> Path:
    """The built-in dome's formula as a fine OBJ mesh (121 x 121 vertices, 28 800 triangles)."""
    import trimesh

    vertices, triangles = dome_mesh(121)
    path = tmp_path_factory.mktemp("mesh") / "dome.obj"
    trimesh.Trimesh(vertices, triangles, process=False).export(path)
    return path


def test_obj_dome_works_like_the_built_in_dome(dome_obj, tmp_path, capsys):
    """The issue's check: optimize --pattern 11 on the OBJ dome converges, every vertex within
    dz (+1e-3 m) of the analytic dome, and the fit error is reported and <= 1e-3 m."""
    out = tmp_path / "o"
    code = main(["optimize", "--surface", f"mesh:{dome_obj}", "--pattern", "11", "--out", str(out)])
    assert code == 0, capsys.readouterr()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["F"] <= 1e-7
    surface = summary["case"]["surface"]
    assert surface["name"] == "mesh" and surface["source"] == "dome.obj"
    assert surface["fit_error_m"] <= 1e-3
    coords = np.array(json.loads((out / "solution.fold").read_text())["vertices_coords"])
    dz = coords[:, 2] - Dome().height(coords[:, 0], coords[:, 1])
    assert np.abs(dz).max() <= DEFAULTS.design.dz + 1e-3
    # the fitted surface against the analytic dome, on a grid finer than the fit's
    fitted = case_from_specs(f"mesh:{dome_obj}", "11").surface
    x, y = np.meshgrid(np.linspace(0, 3, 201), np.linspace(0, 3, 201))
    assert np.abs(fitted.height(x, y) - Dome().height(x, y)).max() <= 1e-3


def test_a_y_up_mesh_and_a_fold_surface(tmp_path):
    yup = case_from_specs("mesh:" + str(DATA / "dome_yup.obj"), "1", up="y")
    assert yup.surface.metadata()["source"] == "dome_yup.obj"
    # a coarse 9 x 9 mesh of the dome, drawn y-up: read z-up it is the dome, to its facets
    assert np.allclose(yup.pattern.coords[:, 2], Dome().height(*yup.plan.xy.T), atol=0.1)
    # the 3D shape of a FOLD file as the target: a solution of the built-in dome
    out = tmp_path / "o"
    assert main(["optimize", "--surface", "dome", "--pattern", "11", "--out", str(out)]) == 0
    target = case_from_specs(f"fold:{out / 'solution.fold'}", "11")
    assert target.surface.metadata()["source"] == "solution.fold"
    assert target.problem().solve().converged


def test_a_mesh_is_placed_at_the_origin_like_the_pattern(dome_obj, tmp_path):
    import trimesh

    vertices, triangles = dome_mesh(31)
    moved = tmp_path / "moved.stl"
    shifted = vertices + np.array([100.0, -50.0, 7.0])
    trimesh.Trimesh(shifted, triangles, process=False).export(moved)
    here, there = case_from_specs(f"mesh:{dome_obj}", "1"), case_from_specs(f"mesh:{moved}", "1")
    assert np.allclose(there.pattern.coords[:, 2] - 7.0, here.pattern.coords[:, 2], atol=2e-3)


@pytest.mark.parametrize(
    ("pattern", "surface"),
    [(str(SIMPLE_VERTEX), "dome"), (str(SQUARETWIST), "hp")],
)
def test_generate_on_a_pattern_from_another_tool(tmp_path, capsys, pattern, surface):
    out = tmp_path / "run"
    options = ["--no-deform", "--quiet", "--out", str(out)]
    code = main_code(["generate", "--surface", surface, "--pattern", pattern, *options])
    summary = json.loads((out / "summary.json").read_text())
    assert code in (0, 1) and summary["n_solutions"] >= 1
    assert summary["case"]["pattern_file"]["file"] == Path(pattern).name
    assert summary["case"]["plan_size_m"][0] == pytest.approx(3.0)
    assert capsys.readouterr().out.strip().splitlines()[-1].endswith(".fold")


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


BAD = {
    "self-intersecting footprint": (
        ["--pattern", "mesh:0,0;2,2;2,0;0,2"],
        "is not a simple polygon: its sides intersect",
    ),
    "SVG without boundary": (
        ["--pattern", "{tmp}/red.svg"],
        "no boundary",
    ),
    "mesh that does not cover the plan": (
        ["--surface", "mesh:{dome}", "--pattern", "grid:5x5", "--size", "4x3"],
        "lies outside the footprint of mesh dome.obj",
    ),
    "zero-plan-area FOLD": (
        ["--pattern", str(DATA / "fold_examples" / "box.fold")],
        "zero area",
    ),
    "unknown unit": (["--pattern", "{tmp}/ft.fold"], "frame_unit 'ft' is not a unit"),
    "missing mesh": (["--surface", "mesh:{tmp}/none.obj"], "cannot read mesh"),
    "unknown mesh format": (["--surface", "mesh:{tmp}/red.svg"], "unknown extension"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_own_design_one_line_exit_2(case, tmp_path, dome_obj, capsys):
    _write(
        tmp_path / "red.svg",
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">'
        '<line x1="0" y1="0" x2="10" y2="10" stroke="#ff0000"/></svg>',
    )
    ft = {
        "frame_unit": "ft",
        "vertices_coords": [[0, 0], [1, 0], [0, 1]],
        "faces_vertices": [[0, 1, 2]],
    }
    _write(tmp_path / "ft.fold", json.dumps(ft))
    args, needle = BAD[case]
    args = [a.format(tmp=tmp_path, dome=dome_obj) for a in args]
    defaults = {"--surface": "dome", "--pattern": "1"}
    for flag, value in defaults.items():
        if flag not in args:
            args = [flag, value, *args]
    out = tmp_path / "o"
    code = main_code(["optimize", *args, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and needle in err[0], err
    assert "Traceback" not in err[0] and not out.exists()
