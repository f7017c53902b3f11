"""``Settings.design.theta_widen`` (``--theta-widen``): the sector-angle bounds widened to a
crease pattern's own plan angles where the plan breaks them (by default for patterns read
from files only), so that problem (6) does not start by redrawing the designer's slivers
(issue 49: drawn patterns)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rigidfold.config import DEFAULTS, THETA_WIDEN, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.generate.case import plan_corner_angles, widened_angle_bounds
from rigidfold.generate.case_options import SettingsOptions
from rigidfold.generate.specs import case_from_specs, parse_pattern

DATA = Path(__file__).parent / "data" / "origami_simulator"
PAPER = DEFAULTS.design


def test_files_by_default():
    assert DEFAULTS.design.theta_widen == THETA_WIDEN[0] == "files"


@pytest.mark.parametrize(
    ("name", "surface"),
    [("cross", "hp"), ("MoosersTrainRigid-Gardner", "hp"), ("frogBase", "dome")],
)
def test_a_drawn_plan_lies_strictly_inside_its_widened_bounds(name, surface):
    case = case_from_specs(surface, str(DATA / f"{name}.svg"), seed=1)
    plan = plan_corner_angles(case.plan)
    d, room = case.settings.design, DEFAULTS.design.theta_widen_room
    assert d.theta_min < plan.min() and plan.max() < d.theta_max
    # the side the plan breaks only, with its room; the other bound as given
    if plan.min() < PAPER.theta_min:
        assert math.isclose(d.theta_min, (1 - room) * plan.min())
    else:
        assert d.theta_min == PAPER.theta_min
    if plan.max() > PAPER.theta_max:
        assert math.isclose(d.theta_max, plan.max() + room * (math.pi - plan.max()))
    else:
        assert d.theta_max == PAPER.theta_max
    assert d.dz == PAPER.dz and case.settings.mechanism == DEFAULTS.mechanism
    assert len(case.notes) == 1 and "--theta-widen none" in case.notes[0]
    # the record of the case says which bounds the run had
    assert case.metadata()["theta_min_deg"] == pytest.approx(math.degrees(d.theta_min))
    # the lifted shape's tolerances are the case's
    assert case.pattern.settings.design == d


def test_the_paper_patterns_keep_the_papers_bounds():
    """Pattern 2's plan has 26.6-degree corners: the paper ran it with 30 degrees; Tables
    5-8 stay as they are. Under 'all' its bounds widen too."""
    assert plan_corner_angles(parse_pattern("2")).min() < PAPER.theta_min
    case = case_from_specs("bezier", "2", seed=1)
    assert case.settings is DEFAULTS and case.notes == ()
    wide = case_from_specs("bezier", "2", seed=1, settings=DEFAULTS.with_(theta_widen="all"))
    assert wide.settings.design.theta_min < PAPER.theta_min and wide.notes


@pytest.mark.parametrize("spec", ["grid:5x5", "mesh:0,0;3,0;3,2;0,2"])
def test_rigidfolds_own_triangulations_keep_the_bounds(spec):
    case = case_from_specs("dome", spec)
    assert case.settings is DEFAULTS and case.notes == ()


def test_none_keeps_the_bounds_given():
    none = DEFAULTS.with_(theta_widen="none")
    case = case_from_specs("hp", str(DATA / "cross.svg"), seed=1, settings=none)
    assert case.settings is none and case.notes == ()


def test_a_plan_inside_the_bounds_or_at_them_widens_nothing():
    """miura-ori.svg (43.5-83.8 degrees) and reschTriTessellation.svg (angles drawn at 30
    degrees, rounded below it by the file's coordinates) keep the bounds."""
    for name in ("miura-ori", "reschTriTessellation"):
        case = case_from_specs("dome", str(DATA / f"{name}.svg"))
        assert case.settings is DEFAULTS, name
        assert plan_corner_angles(case.plan).min() > PAPER.theta_min - PAPER.theta_widen_tol


def test_a_drawing_refused_under_the_given_bounds_loads_with_its_own():
    """A pattern whose lifted shape breaks the paper's bounds far (many slivers) is refused
    with them, and loads with bounds widened to its plan."""
    path = str(DATA / "airplane.svg")
    with pytest.raises(RigidfoldError, match="sector angles"):
        case_from_specs("dome", path, settings=DEFAULTS.with_(theta_widen="none"))
    case = case_from_specs("dome", path)
    assert case.settings.design.theta_min < PAPER.theta_min


def test_widening_is_idempotent():
    case = case_from_specs("hp", str(DATA / "cross.svg"), seed=1)
    assert widened_angle_bounds(case.plan, case.settings) is case.settings


def test_the_command_lines_option_and_bad_values():
    assert SettingsOptions(theta_widen="none").settings().design.theta_widen == "none"
    assert SettingsOptions().settings().design.theta_widen == "files"
    with pytest.raises(RigidfoldError, match="theta_widen must be one of"):
        Settings().with_(theta_widen="some")
    for room in (0.0, 1.0, -0.1, float("nan")):
        with pytest.raises(RigidfoldError, match="theta_widen_room"):
            Settings().with_(theta_widen_room=room)
    assert np.isfinite(DEFAULTS.design.theta_widen_tol)


def test_a_folded_fold_files_angles_are_its_panels_not_its_projections(tmp_path):
    """A 3D FOLD file (a design of rigidfold, a folded form) is read in plan by its
    projection, whose angles are no panel's: its widening looks at the angles in 3D."""
    from rigidfold.io.fold_write import write_fold

    lifted = case_from_specs("hp", "grid:5x5").pattern  # 3D, angles 38-97 degrees
    path = write_fold(tmp_path / "folded.fold", lifted)
    case = case_from_specs("hp", str(path))
    drawn = plan_corner_angles(case.plan)
    np.testing.assert_allclose(np.sort(drawn.ravel()), np.sort(lifted.corner_angles.ravel()))
    flat = np.column_stack([case.plan.xy, np.zeros(len(case.plan.xy))])
    projected = case.pattern.with_coords(flat).corner_angles
    assert not np.allclose(np.sort(projected.ravel()), np.sort(drawn.ravel()))
    assert case.settings is DEFAULTS  # its panels' angles lie inside the paper's bounds


HELD_PATTERN = DATA / "whirlpool.svg"
"""A twist tessellation whose zigzag boundary is all corners, which (8) holds on the surface:
two of its triangles have all three vertices there."""


def test_a_triangle_held_at_three_corners_keeps_its_angles_and_no_bounds():
    """On the plane z = 0.6 y the one held triangle whose lifted angles break the bounds made
    problem (6) infeasible from the start; its angles are constants of the problem, so they
    keep no bounds, the case says so in a note, and the first solve finds the developable
    shape (the plane itself is one)."""
    case = case_from_specs("expr", str(HELD_PATTERN), expr="0.6*y")
    problem = case.problem()
    held = problem.nlp.held
    corners = np.zeros(case.pattern.n_vertices, dtype=bool)
    corners[case.pattern.corners] = True
    assert np.array_equal(held, np.flatnonzero(corners[case.pattern.faces].all(axis=1)))
    lo, hi = problem.nlp.theta_bounds
    n_faces = case.pattern.n_faces
    rows = (np.arange(3)[:, None] * n_faces + held).ravel()
    assert np.isneginf(lo[rows]).all() and np.isposinf(hi[rows]).all()
    others = np.setdiff1d(np.arange(3 * n_faces), rows)
    d = case.settings.design
    assert (lo[others] == d.theta_min).all() and (hi[others] == d.theta_max).all()
    angles = case.pattern.corner_angles[held]
    assert ((angles < d.theta_min) | (angles > d.theta_max)).any()  # what the bounds broke
    assert any("all three vertices at corners of the plan" in n for n in case.notes)
    result = problem.solve(fixed=case.pattern.fixed.copy())
    assert result.converged and result.F <= d.f_tol
    assert result.max_violation <= 1e-6  # the held angles count for nothing


def test_a_pattern_without_held_triangles_keeps_every_bound():
    case = case_from_specs("bezier", "1", seed=1)
    problem = case.problem(build_ipopt=False)
    assert problem.nlp.held.size == 0
    lo, hi = problem.nlp.theta_bounds
    assert (lo == case.settings.design.theta_min).all()
    assert (hi == case.settings.design.theta_max).all()
    assert not any("corners of the plan" in n for n in case.notes)
