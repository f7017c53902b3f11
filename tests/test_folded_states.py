"""A design's folded states are states, not crease patterns (issue 47, item 3).

A crease pattern as built or read must have its faces counter-clockwise seen from +z over an
area in plan; a state of it (a solver's shape, a frame of its folding motion) keeps the
pattern's faces whatever its shape, and may be folded past vertical. Before, a motion frame
folded past vertical was checked as a crease pattern: ``generate --surface bezier --seed 1
--pattern grid:4x4 --size 1x1`` reached DOF 1 and then exited 2 with "faces must be
counter-clockwise seen from +z", and ``deform`` on its design failed the same way.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import main_code
from rigidfold.deform import verify
from rigidfold.errors import RigidfoldError
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import read_fold
from rigidfold.mesh import CreasePattern, geometry
from rigidfold.pipeline.checks import traced_motion
from rigidfold.pipeline.workflows import deform_file
from rigidfold.pipeline.writer import verification_frames

GRIDS = [
    ("grid:3x3", "2x1", 3),  # stops at DOF 3; the motion of that design folds past vertical
    ("grid:4x4", "1x1", 1),  # the issue's design: its motion folds past vertical
    ("grid:5x5", "1x1", 1),
    ("grid:6x6", "2x1", 1),
]
"""Small grids on the Bezier surface (pattern, size, seed); the final designs of the first
two have a motion frame whose projection onto the xy plane is negative."""


def _turned_over(coords: np.ndarray) -> np.ndarray:
    """(V, 3) coordinates turned half a turn about the x axis: a rigid motion whose faces,
    seen from +z, are clockwise."""
    return coords * [1.0, -1.0, -1.0]


def test_a_state_past_vertical_is_a_state_and_a_sheet_keeps_its_rule():
    case = case_from_specs("bezier", "grid:3x3", seed=1, size="1x1")
    pattern = case.pattern
    state = pattern.with_coords(_turned_over(pattern.coords))
    # a rigid motion: the same fold angles, the same topology and assignment
    np.testing.assert_allclose(state.fold_angles, pattern.fold_angles, atol=1e-12)
    assert np.array_equal(state.faces, pattern.faces)
    assert not state.with_fixed(pattern.fixed).sheet
    # the flat sheet stood up in the xz plane (zero area in plan) is a state too
    flat = pattern.coords * [1.0, 1.0, 0.0]
    vertical = geometry.from_y_up(flat)
    assert geometry.projected_area(vertical, pattern.faces) == 0
    assert pattern.with_coords(vertical).n_faces == pattern.n_faces
    with pytest.raises(RigidfoldError, match="zero area"):
        CreasePattern(vertical, pattern.faces, pattern.edges, pattern.fixed)
    # a crease pattern built or read keeps the rule
    with pytest.raises(RigidfoldError, match="counter-clockwise"):
        CreasePattern.from_faces(pattern.coords, pattern.faces[:, ::-1])
    with pytest.raises(RigidfoldError, match="counter-clockwise"):
        CreasePattern(_turned_over(pattern.coords), pattern.faces, pattern.edges, pattern.fixed)
    # coordinates are still checked in a state
    bad = pattern.coords.copy()
    bad[0, 0] = np.nan
    with pytest.raises(RigidfoldError, match="non-finite"):
        pattern.with_coords(bad)


@pytest.mark.parametrize(("grid", "size", "seed"), GRIDS)
def test_small_grids_motion_frames_are_written(grid, size, seed):
    """Each grid's final design's motion, traced, is written as FOLD frames (the frames a
    run writes beside its design), those folded past vertical too."""
    case = case_from_specs("bezier", grid, seed=seed, size=size)
    run = generate(case, seed=seed, projection="large")  # the designs of the paper's solver
    assert run.final is not None and run.final_dof <= 3
    pattern = run.final.result.pattern
    check = verify(pattern, run_deform=False, run_motion=True, settings=case.settings)
    motion = traced_motion(check)
    assert motion is not None
    frames = verification_frames(pattern, check)
    assert frames[0]["frame_classes"] == ["creasePattern"]
    assert len(frames) == 1 + len(motion[0])
    plan = [geometry.projected_area(x, pattern.faces) for x in motion[0]]
    assert (min(plan) < 0) == ((grid, size, seed) in GRIDS[:2])
    for frame in frames[1:]:
        # each frame's fold angles are the state's, finite, as many as the edges
        angles = np.asarray(frame["edges_foldAngle"])
        assert angles.shape == (pattern.n_edges,) and np.isfinite(angles).all()


@pytest.fixture(scope="module")
def issue_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("grid4")
    argv = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "grid:4x4"]
    argv += ["--size", "1x1", "--no-deform", "--no-report", "--quiet", "--out", str(out)]
    return out, main_code(argv)


def test_the_issue_run_ends_with_its_design_and_motion(issue_run):
    out, code = issue_run
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stop"] == "target_reached"
    assert summary["verdict"]["final_design"] == summary["solutions"][-1]
    final = out / summary["solutions"][-1]
    raw = json.loads(final.read_text())
    classes = [f.get("frame_classes") for f in raw["file_frames"]]
    assert ["creasePattern"] in classes and classes.count(["foldedForm"]) > 1


def test_deform_reads_and_writes_the_design_folded_past_vertical(issue_run, tmp_path):
    out, _ = issue_run
    summary = json.loads((out / "summary.json").read_text())
    design = out / summary["solutions"][-1]
    result = deform_file(design, tmp_path)
    assert result.verification.motion is not None
    assert result.verification.deformation is not None
    written = read_fold(tmp_path / design.name)
    assert written.pattern.n_vertices == read_fold(design).pattern.n_vertices
