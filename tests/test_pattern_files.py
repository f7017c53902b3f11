"""Crease patterns from other tools' files (--pattern FILE.fold | FILE.svg): scale, placement,
fixed creases, rigid panels, units, and the errors of files that cannot be patterns."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code
from rigidfold import patterns
from rigidfold.cli.commands import main
from rigidfold.generate import specs
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import read_fold
from rigidfold.surfaces import Dome

FOLD_EXAMPLES = Path(__file__).parent / "data" / "fold_examples"
SQUARETWIST = FOLD_EXAMPLES / "squaretwist.fold"


def write(path: Path, data: dict) -> Path:
    path.write_text(json.dumps(data))
    return path


def square_with_quad(unit: str | None = None, factor: float = 1.0) -> dict:
    """A 2 x 1 sheet: two unit squares as polygons, the middle crease "J", one square marked
    through ``edges_rigidfold:fixed`` on nothing (for tests to change)."""
    data = {
        "vertices_coords": [
            [x * factor, y * factor] for x, y in [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]
        ],
        "faces_vertices": [[0, 1, 4, 5], [1, 2, 3, 4]],
        "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [1, 4]],
        "edges_assignment": ["B", "B", "B", "B", "B", "B", "J"],
    }
    if unit is not None:
        data["frame_unit"] = unit
    return data


def pairs(fixed: np.ndarray) -> set:
    return {tuple(sorted(p)) for p in fixed.tolist()}


# -------------------------------------------------------------------------------- FOLD
@pytest.mark.parametrize("name", ["diagonal-cp", "squaretwist"])
def test_unitless_fold_is_fitted_into_the_default_size_at_the_origin(name):
    plan = specs.parse_pattern(str(FOLD_EXAMPLES / f"{name}.fold"))
    data = read_fold(FOLD_EXAMPLES / f"{name}.fold", rigid_panels=False)
    assert np.allclose(plan.xy.min(axis=0), 0.0)
    assert max(plan.box) == pytest.approx(3.0) and min(plan.box) <= 3.0 + 1e-12
    # the file's own plan, scaled uniformly (aspect ratio kept)
    raw = data.pattern.coords[:, :2]
    factor = plan.source["metres_per_unit"]
    assert np.allclose(plan.xy, (raw - raw.min(axis=0)) * factor)
    assert np.array_equal(plan.faces, data.pattern.faces)
    assert plan.source == {
        "file": f"{name}.fold",
        "format": "FOLD",
        "unit": "unit",
        "metres_per_unit": factor,
        "up": "z",
        "rigid_panels": False,
        "fitted_into_m": [3.0, 3.0],
    }
    assert plan.metadata()["pattern_file"] == plan.source


def test_size_and_scale_of_a_unitless_file(tmp_path):
    path = write(tmp_path / "cp.fold", square_with_quad())
    assert specs.parse_pattern(str(path), size="12x8").box == pytest.approx((12.0, 6.0))
    assert specs.parse_pattern(str(path), size="4x8").box == pytest.approx((4.0, 2.0))
    scaled = specs.parse_pattern(str(path), scale=2.5)
    assert scaled.box == pytest.approx((5.0, 2.5))
    assert scaled.source["metres_per_unit"] == 2.5 and scaled.source["fitted_into_m"] is None
    with pytest.raises(ValueError, match="give --size or --scale, not both"):
        specs.parse_pattern(str(path), size="3x3", scale=1.0)


def test_a_file_in_a_physical_unit_keeps_its_size(tmp_path):
    mm = specs.parse_pattern(str(write(tmp_path / "mm.fold", square_with_quad("mm", 1000.0))))
    m = specs.parse_pattern(str(write(tmp_path / "m.fold", square_with_quad("m"))))
    assert np.allclose(mm.xy, m.xy) and mm.box == pytest.approx((2.0, 1.0))
    assert mm.source["unit"] == "mm" and mm.source["metres_per_unit"] == 1e-3
    assert mm.source["fitted_into_m"] is None
    for option in ({"size": "3x3"}, {"scale": 2.0}):
        with pytest.raises(ValueError, match=r"drawn in mm \(2 m x 1 m\): --size and --scale"):
            specs.parse_pattern(str(tmp_path / "mm.fold"), **option)


def test_fixed_creases_joins_marks_and_rigid_panels(tmp_path):
    data = square_with_quad("m")
    path = write(tmp_path / "j.fold", data)
    plan = specs.parse_pattern(str(path))
    assert pairs(plan.fixed) == {(1, 4)}  # the "J" edge; the diagonals are free creases
    assert len(plan.faces) == 4
    rigid = specs.parse_pattern(str(path), rigid_panels=True)
    assert len(pairs(rigid.fixed)) == 3 and (1, 4) in pairs(rigid.fixed)
    # edges_rigidfold:fixed marks a crease fixed whatever its letter
    data["edges_assignment"][6] = "V"
    data["edges_rigidfold:fixed"] = [False] * 6 + [True]
    marked = specs.parse_pattern(str(write(tmp_path / "marked.fold", data)))
    assert pairs(marked.fixed) == {(1, 4)}
    # rigid panels: each square one facet; with the middle "J" too, the whole sheet is one
    assert patterns.build(rigid, Dome(box=rigid.box)).n_facets == 1
    data.pop("edges_rigidfold:fixed")
    panels = specs.parse_pattern(str(write(tmp_path / "v.fold", data)), rigid_panels=True)
    shape = patterns.build(panels, Dome(box=panels.box))
    assert shape.fixed.sum() == 2 and shape.n_facets == 2 and len(shape.free_creases) == 1


def test_a_mm_file_gives_the_same_answers_as_its_metre_copy(tmp_path):
    """The issue's check: same DOF and the same optimum; the output is in metres."""
    twist = json.loads(SQUARETWIST.read_text())
    coords = np.array(twist["vertices_coords"], dtype=float)
    metres = {**twist, "frame_unit": "m", "vertices_coords": (coords * 3.0).tolist()}
    millimetres = {**twist, "frame_unit": "mm", "vertices_coords": (coords * 3000.0).tolist()}
    results = []
    for name, data in (("m", metres), ("mm", millimetres)):
        case = case_from_specs("dome", str(write(tmp_path / f"{name}.fold", data)))
        assert case.plan.source["unit"] == name
        results.append((case, case.problem().solve()))
    (case_m, m), (case_mm, mm) = results
    assert np.allclose(case_m.pattern.coords, case_mm.pattern.coords, atol=1e-9)
    assert case_m.pattern.generic_dof == case_mm.pattern.generic_dof
    assert m.converged and mm.converged
    assert np.allclose(m.pattern.coords, mm.pattern.coords, atol=1e-7)
    assert m.F == pytest.approx(mm.F, abs=1e-12)
    out = tmp_path / "out"
    assert (
        main(
            [
                "optimize",
                "--surface",
                "dome",
                "--pattern",
                str(tmp_path / "mm.fold"),
                "--out",
                str(out),
            ]
        )
        == 0
    )
    written = json.loads((out / "solution.fold").read_text())
    assert written["frame_unit"] == "m"
    assert np.allclose(written["vertices_coords"], mm.pattern.coords, atol=1e-9)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("simple.fold", r"face 0 \(0, 1, 2\) is vertical \(edge-on\) in plan: a folded form"),
        ("box.fold", "zero area"),
        ("diagonal-folded.fold", "zero area"),
    ],
)
def test_folded_forms_are_refused_as_patterns(name, message):
    with pytest.raises(ValueError, match=message):
        specs.parse_pattern(str(FOLD_EXAMPLES / name))


def test_upside_down_face_is_refused(tmp_path):
    data = square_with_quad("m")
    data["vertices_coords"][2] = [0.5, 0.0]  # the right square folds back over the left one
    data["vertices_coords"][3] = [0.5, 1.0]
    data["faces_vertices"] = [[0, 1, 4, 5], [1, 2, 3, 4]]
    with pytest.raises(ValueError, match="upside down"):
        specs.parse_pattern(str(write(tmp_path / "over.fold", data)))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--pattern", "1", "--scale", "2"], "pattern '1' takes no scale"),
        (["--pattern", "grid:3x3", "--rigid-panels"], "takes no rigid panels"),
        (["--pattern", "missing.fold"], "cannot read missing.fold"),
        (["--pattern", "cp.svgz"], "unknown pattern 'cp.svgz'"),
        (["--pattern", "1", "--scale", "-1"], "must be a positive number"),
    ],
)
def test_bad_pattern_options_one_line_exit_2(tmp_path, capsys, args, message):
    code = main_code(["optimize", "--surface", "dome", *args, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err
    assert not (tmp_path / "o").exists()


def test_unknown_unit_is_refused(tmp_path, capsys):
    path = write(tmp_path / "ft.fold", square_with_quad("ft"))
    code = main(
        ["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path / "o")]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "frame_unit 'ft' is not a unit rigidfold knows" in err[0]
