"""--supports service: the rigid set of auto, grown where the design deflects most until the
deflection limit is met; every pin kept is needed, and a search that cannot meet the limit
says so."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import folded_grid, run_cli
from rigidfold.cli.structure_specs import read_structure_options
from rigidfold.config import DEFAULTS
from rigidfold.io import read_fold, write_fold
from rigidfold.structure import Auto, Pins, Service, StructureStatus, Supports, check_supports
from rigidfold.structure.design import StructureOptions, plan_design
from test_structure import independent_kernel

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def roof():
    return read_fold(DATA / "roof_12x8_dof1.fold").pattern


def test_service_supports_meet_the_limit_that_auto_misses(roof):
    """The roof on free hinges: auto's pins hold the mechanism but let it sag far past
    L/250; service keeps them, adds boundary pins, meets the limit, and each added pin is
    needed (without any one of them the same analysis misses the limit)."""
    auto = plan_design(roof, StructureOptions(supports=Auto(), modes=0)).check()
    assert auto.rigidity.rigid and auto.status is StructureStatus.DEFLECTION
    assert "--supports service pins more vertices" in auto.message  # what may meet it
    plan = plan_design(roof, StructureOptions(supports=Service(), modes=0))
    check = plan.check()
    assert check.status is StructureStatus.PASSED and check.chosen == "service"
    growth = check.growth
    assert growth is not None and growth.passed
    pins = check.rigidity.supports.pinned
    rigid = auto.rigidity.supports.pinned
    np.testing.assert_array_equal(growth.rigid, rigid)
    assert set(rigid) <= set(pins) <= set(roof.boundary_vertices)
    assert sorted(growth.added.tolist()) == sorted(set(pins) - set(rigid))
    assert len(growth.added) >= 1
    assert independent_kernel(roof, pins) == 0  # rigid, by an independent rank count
    steps = [t[0] for t in growth.trail]
    assert steps[0] == "rigid" and set(steps) <= {"rigid", "add", "drop", "keep"}
    added = [t[1] for t in growth.trail if t[0] == "add"]
    dropped = [t[1] for t in growth.trail if t[0] == "drop"]
    assert sorted(set(added) - set(dropped)) == sorted(growth.added.tolist())
    before_pruning = [t for t in growth.trail if t[0] in ("rigid", "add")]
    assert all(d > a for _, _, _, d, a in before_pruning[:-1])  # added while it failed
    assert check.max_displacement <= check.allowed_displacement
    for v in growth.added:
        fewer = check_supports(roof, Supports(np.setdiff1d(pins, [v])))
        assert fewer.rigid
        assert plan._check(fewer, modes=0).status is StructureStatus.DEFLECTION
    data = check.to_dict()["supports"]
    assert data["chosen"] == "service"
    assert data["service"]["added_for_deflection"] == growth.added.tolist()
    assert data["service"]["passed"] is True


def test_a_search_that_cannot_meet_the_limit_says_how_far_it_went():
    """An unreachable limit: the search pins every candidate (or stops at
    service_max_pins), keeps them all (none can be taken away) and fails the limit."""
    design = folded_grid(4, 0.3)
    boundary = design.boundary_vertices
    check = plan_design(design, StructureOptions(supports=Service(), limit=1e9, modes=0)).check()
    assert check.status is StructureStatus.DEFLECTION and not check.growth.passed
    assert f"pins alone did not meet it ({len(boundary)} pinned of {len(boundary)}" in check.message
    np.testing.assert_array_equal(check.rigidity.supports.pinned, boundary)
    assert [t[0] for t in check.growth.trail] == ["rigid"] + ["add"] * (
        len(boundary) - len(check.growth.rigid)
    )
    capped = DEFAULTS.with_(structure_service_max_pins=2)
    few = plan_design(
        design,
        StructureOptions(supports=Service(), limit=1e9, modes=0),
        settings=capped,
    ).check()
    assert len(few.growth.added) == 2 and len(few.growth.trail) == 3
    assert not few.growth.passed and few.status is StructureStatus.DEFLECTION


def test_cli_service_reports_the_added_pins(tmp_path):
    design = folded_grid(4, 0.3)
    path = tmp_path / "grid.fold"
    write_fold(path, design)
    res = run_cli(
        "structure",
        str(path),
        "--out",
        str(tmp_path / "s"),
        "--supports",
        "service",
        "--limit",
        "L/1e9",
        "--modes",
        "0",
    )
    assert res.returncode == 1, res.stderr
    assert "chosen for the deflection" in res.stdout and "added for the deflection" in res.stdout
    saved = json.loads((tmp_path / "s" / "structure.json").read_text())
    assert saved["status"] == "deflection" and saved["supports"]["chosen"] == "service"
    assert saved["supports"]["service"]["passed"] is False
    assert saved["supports"]["pinned"] == design.boundary_vertices.tolist()


@pytest.mark.parametrize(
    "text, words",
    [
        ("serv", "got 'serv' (did you mean service?)"),
        ("x1", "got 'x1'"),
        ("1,,a", "got '1,,a'"),
    ],
)
def test_a_misspelt_support_word_is_one_line_naming_the_choices(text, words):
    with pytest.raises(ValueError) as err:
        read_structure_options(supports=text)
    message = str(err.value)
    assert message.startswith("supports must be auto, service or comma-separated vertex indices")
    assert words in message and "\n" not in message


def test_where_pins_alone_miss_the_limit_the_hinge_stiffness_that_meets_it_is_named():
    """Only auto's pins may be used and they miss L/1000: the verdict names a hinge
    stiffness that meets it (checked again with the supports given), close to the least
    (20 % less does not), and an unreachable limit is said to be out of reach of hinges."""
    design = folded_grid(4, 0.3)
    pins = tuple(plan_design(design).rigidity.supports.pinned.tolist())
    options = StructureOptions(supports=Service(), candidates=pins, limit=1000.0, modes=0)
    check = plan_design(design, options).check()
    assert check.status is StructureStatus.DEFLECTION and check.growth.searched_hinges
    k, largest = check.growth.hinge_hint
    assert largest <= check.allowed_displacement
    assert "N m/rad per m would" in check.message
    given = StructureOptions(supports=Pins(pins), limit=1000.0, modes=0)
    assert plan_design(design, given.replace(hinge_stiffness=k)).check().passed
    softer = plan_design(design, given.replace(hinge_stiffness=k / 1.2)).check()
    assert softer.status is StructureStatus.DEFLECTION
    data = check.to_dict()["supports"]["service"]["hinge_stiffness_that_meets_the_limit"]
    assert data == {"Nm_per_rad_per_m": k, "max_displacement_m": largest}
    never = StructureOptions(supports=Service(), candidates=pins, limit=1e9, modes=0)
    out = plan_design(design, never).check()
    assert out.growth.hinge_hint is None and "nor would stiffer hinges" in out.message
