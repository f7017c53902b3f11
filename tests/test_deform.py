"""Step 9 (OpenSees large-deformation check), the folding motion and `rigidfold deform`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from conftest import run_cli
from rigidfold.cli.commands import main
from rigidfold.deform import TubeSection, deform, folding_motion, verify
from rigidfold.develop import develop
from rigidfold.frame.model import default_support_face
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import read_fold, write_fold
from rigidfold.mesh.geometry import best_fit, edge_lengths
from rigidfold.patterns import miura
from rigidfold.pipeline import verification_frames


def locked_miura(shape):
    """The same Miura-ori with one free crease made rigid: it can no longer unfold."""
    fixed = shape.fixed.copy()
    fixed[shape.free_creases[len(shape.free_creases) // 2]] = True
    return shape.with_fixed(fixed)


@pytest.fixture(scope="module")
def miura_checks():
    shape = miura(3, 3)
    return shape, deform(shape), deform(locked_miura(shape))


def test_tube_section_is_the_papers():
    sec = TubeSection(0.020, 0.001, 200e9, 0.3)
    assert sec.A == pytest.approx(math.pi / 4 * (0.020**2 - 0.018**2))
    assert sec.I == pytest.approx(math.pi / 64 * (0.020**4 - 0.018**4))
    assert sec.J == pytest.approx(2 * sec.I) and sec.G == pytest.approx(200e9 / 2.6)


def test_miura_reaches_the_plane_without_deformation(miura_checks):
    _, free, _ = miura_checks
    assert free.reached_plane and free.steps == 20 and free.load_factor == pytest.approx(1.0)
    assert free.mean_dl_mm < 0.1 and free.max_dl_mm < 0.1
    assert free.max_drho_fix_deg < 1e-3
    # the frames of the analysis go from the folded shape to the plane
    assert np.abs(free.frames[-1][:, 2]).max() < 1e-6
    assert len(free.history) == free.steps


def test_locked_miura_must_deform_at_least_ten_times_more(miura_checks):
    _, free, locked = miura_checks
    assert locked.mean_dl_mm >= 10 * max(free.mean_dl_mm, 1e-6)
    assert locked.mean_dl_mm > 0.1
    assert not locked.reached_plane


def test_miura_motion_is_exactly_rigid():
    shape = miura(4, 3)
    motion = folding_motion(shape, develop(shape).coords2d)
    assert motion.status == "ok"
    assert np.abs(motion.frames[0][:, 2]).max() < 1e-9
    # the last frame is the designed shape, turned and moved as a rigid body
    assert np.allclose(best_fit(motion.frames[-1:], shape.coords)[0], shape.coords, atol=1e-12)
    assert motion.max_length_error < 1e-8
    for frame in motion.frames:
        assert np.allclose(edge_lengths(frame, shape.edges), shape.edge_lengths, rtol=1e-8)
    # the support panel (the panel of the support triangle) holds still
    panel = motion.support_vertices(shape)
    assert default_support_face(shape) in motion.support_faces
    assert np.array_equal(
        motion.support_faces,
        np.flatnonzero(shape.facets == shape.facets[default_support_face(shape)]),
    )
    assert np.abs(motion.frames[:, panel] - motion.frames[0, panel]).max() < 1e-9


def test_symmetric_dome_one_dof_shape_turns_back_before_the_plane():
    """The DOF-1 shape of the symmetric dome (Sec. 6.5, criterion S): its one folding path
    reaches 0.288 of the design's folding measure and then folds up again, so the motion
    fails, with the reason, and so does the OpenSees check (docs/results.md)."""
    from pathlib import Path

    from rigidfold.io.fold import pattern_from_fold

    shape = pattern_from_fold(Path(__file__).parent / "data" / "dome_sym_dof1.fold")
    motion = folding_motion(shape, develop(shape).coords2d)
    assert motion.status == "failed"
    assert "turns back at m = 0.288" in motion.message
    assert len(motion.frames) >= 2  # the part that was traced, kept for inspection


@pytest.fixture(scope="module")
def one_dof_solution():
    run = generate(case_from_specs("bezier", "1", seed=1), criterion="shat", seed=1)
    assert run.final_dof == 1
    return run.solutions[-1].result.pattern


def test_generated_one_dof_shape_passes_steps_8_and_9(one_dof_solution):
    check = verify(one_dof_solution)
    dev, d, m = check.development, check.deformation, check.motion
    assert dev.D < 1e-8 and dev.flipped == 0 and dev.overlaps == 0
    assert d.reached_plane and d.mean_dl_mm < 0.25 and d.mean_drho_fix_deg < 0.05
    assert m.status == "ok" and m.max_length_error < 1e-3
    assert np.abs(m.frames[0][:, 2]).max() < 1e-9
    # the designed shape, turned and moved so that its support panel lies on the development
    last = best_fit(m.frames[-1:], one_dof_solution.coords)[0]
    assert np.allclose(last, one_dof_solution.coords, atol=1e-9)
    panel = m.support_vertices(one_dof_solution)
    assert np.abs(m.frames[1:, panel] - m.frames[-1, panel]).max() < 1e-9
    # the flat frame is the development: its panel agrees to the development's accuracy
    assert np.abs(m.frames[0, panel] - m.frames[-1, panel]).max() < 1e-7
    frames = verification_frames(one_dof_solution, check)
    assert frames[0]["frame_classes"] == ["creasePattern"]
    assert [f["frame_classes"] for f in frames[1:]] == [["foldedForm"]] * len(m.frames)
    # every motion frame carries its own fold angles: 0 flat, the design's when folded
    angles = np.array([f["edges_foldAngle"] for f in frames[1:]])
    assert np.abs(angles[0]).max() < 1e-6
    assert np.allclose(angles[-1], np.degrees(one_dof_solution.fold_angles), atol=1e-6)
    assert np.all(np.abs(angles[1:-1]).max(axis=1) < np.abs(angles[-1]).max() + 1e-6)
    letters = [f["edges_assignment"] for f in frames[1:]]
    assert all(row == letters[-1] for row in letters) and "M" in letters[0]


def test_deform_cli_json_and_files(tmp_path, capsys):
    src = write_fold(tmp_path / "miura.fold", miura(3, 3))
    out = tmp_path / "out"
    assert main(["deform", str(src), "--out", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["reached_plane"] is True and report["steps"] == 20
    assert report["mean_dl_mm"] < 0.1 and report["max_drho_fix_deg"] < 1e-3
    assert {"mean_dl_mm", "max_dl_mm", "mean_drho_fix_deg", "max_drho_fix_deg"} <= set(report)
    history = json.loads((out / "miura_deform.json").read_text())["deformation"]["history"]
    assert len(history) == 20 and history[-1]["load_factor"] == pytest.approx(1.0)
    flat = read_fold(out / "miura.fold", frame=2).pattern  # first motion frame: flat
    assert np.abs(flat.coords[:, 2]).max() < 1e-9


def test_deform_fold_file_holds_the_support_panel_in_every_motion_frame(tmp_path, capsys):
    """The motion frames of the FOLD file that ``rigidfold deform`` writes: the support panel
    (recorded in ``rigidfold:motion``) keeps its coordinates in every frame, and each frame
    carries its own fold angles and assignments."""
    from rigidfold.config import DEFAULTS
    from rigidfold.io.fold import edge_assignments

    shape = miura(3, 3)
    src = write_fold(tmp_path / "miura.fold", shape)
    assert main(["deform", str(src), "--out", str(tmp_path / "out")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[2] == "large deformation reached the plane, folding motion traced: they agree"
    raw = json.loads((tmp_path / "out" / "miura.fold").read_text())
    diagram = next(f for f in raw["file_frames"] if f["frame_classes"] == ["creasePattern"])
    motion = [f for f in raw["file_frames"] if "folding motion" in f["frame_title"]]
    assert 3 <= len(motion) <= DEFAULTS.deformation.motion_frames
    support = raw["rigidfold:motion"]["support_faces"]
    assert (
        support
        == np.flatnonzero(shape.facets == shape.facets[default_support_face(shape)]).tolist()
    )
    assert len(support) == 2  # a Miura-ori's panels are quads: two triangles, one fixed crease
    panel = np.unique(np.asarray(diagram["faces_vertices"])[support])
    coords = np.array([f["vertices_coords"] for f in motion])
    assert np.abs(coords[:, panel] - coords[0, panel]).max() < 1e-9
    assert np.abs(coords[0, :, :2] - np.asarray(diagram["vertices_coords"])).max() < 1e-12
    assert np.abs(coords[0, :, 2]).max() == 0.0  # the flat frame is the development diagram
    letters = edge_assignments(shape)  # the design's: B boundary, J fixed, M and V creases
    for frame in motion:
        assert frame["edges_assignment"] == letters
        assert len(frame["edges_foldAngle"]) == shape.n_edges
    # flat: every angle 0, each crease keeps the letter of the way it folds (FOLD's crease
    # pattern convention); folded: the design's angles
    assert np.abs(motion[0]["edges_foldAngle"]).max() < 1e-6
    assert np.allclose(motion[-1]["edges_foldAngle"], np.degrees(shape.fold_angles), atol=1e-6)
    halfway = np.abs(motion[len(motion) // 2]["edges_foldAngle"])
    assert 0 < halfway.max() < np.abs(np.degrees(shape.fold_angles)).max()


@pytest.fixture(scope="module")
def free_miura():
    """A Miura-ori whose quads are cut into free triangles: 9 DOF, developable, rigid-foldable."""
    shape = miura(3, 3)
    return shape.with_fixed(np.zeros(shape.n_edges, dtype=bool))


TRACER_STOPS = {"path_max_steps": 1}
"""Settings under which the motion tracer gives up at once (one continuation step)."""


def test_verdicts_agree_on_a_rigid_foldable_miura(miura_checks):
    check = verify(miura_checks[0])
    verdicts = check.verdicts
    assert verdicts.agreement == "agree" and verdicts.reason == ""
    assert verdicts.line == "large deformation reached the plane, folding motion traced: they agree"
    assert check.to_dict()["verdicts"]["agreement"] == "agree"
    assert verify(miura_checks[0], run_deform=False).verdicts is None


def test_verdicts_differ_when_the_analysis_stops_short_of_the_plane():
    from rigidfold.config import DEFAULTS

    check = verify(miura(3, 3), settings=DEFAULTS.with_(deform_load_tol=0.51))  # stops at 0.5
    verdicts = check.verdicts
    assert (verdicts.plane, verdicts.motion, verdicts.agreement) == (False, True, "differ")
    assert verdicts.line.startswith(
        "large deformation did not reach the plane, folding motion traced: they differ, because "
        "a rigid-folding path to the plane exists"
    )
    assert check.deformation.message in verdicts.reason


def test_verdicts_differ_when_the_tracer_stops_on_a_shape_of_several_dof(free_miura):
    """At 9 DOF the folding path is not unique: the tracer follows one and, with a budget of
    one step, gives up; the OpenSees frame reaches the plane all the same, hardly
    deforming."""
    from rigidfold.config import DEFAULTS

    check = verify(free_miura, settings=DEFAULTS.with_(**TRACER_STOPS))
    assert check.motion.status == "failed" and check.motion.dof == 9
    assert check.deformation.reached_plane and check.deformation.max_dl_mm < 1e-3
    verdicts = check.verdicts
    assert verdicts.agreement == "differ"
    assert verdicts.line.startswith(
        "large deformation reached the plane, folding motion not traced: they differ, because "
        "with 9 DOF the folding path is not unique: the motion tracer follows one"
    )
    assert "got there along another (max |dl| = " in verdicts.reason
    assert verify(free_miura).verdicts.agreement == "agree"  # with the default settings


def test_deform_cli_says_why_the_verdicts_differ(free_miura, tmp_path, capsys, monkeypatch):
    import functools

    import rigidfold.pipeline.workflows
    from rigidfold.config import DEFAULTS

    tight = DEFAULTS.with_(**TRACER_STOPS)
    real = rigidfold.pipeline.workflows.deform_file
    monkeypatch.setattr(
        rigidfold.pipeline.workflows, "deform_file", functools.partial(real, settings=tight)
    )
    src = write_fold(tmp_path / "free.fold", free_miura)
    assert main(["deform", str(src), "--out", str(tmp_path / "out")]) == 0  # reached the plane
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith("folding motion: failed")
    assert lines[2].startswith(
        "large deformation reached the plane, folding motion not traced: they differ, because "
        "with 9 DOF"
    )
    assert main(["deform", str(src), "--out", str(tmp_path / "out"), "--json"]) == 0
    verdicts = json.loads(capsys.readouterr().out)["verdicts"]
    assert verdicts["agreement"] == "differ" and verdicts["line"] == lines[2]


def test_deform_cli_locked_shape_exits_1(tmp_path):
    src = write_fold(tmp_path / "locked.fold", locked_miura(miura(3, 3)))
    proc = run_cli("deform", str(src), "--out", str(tmp_path / "o"), "--json")
    assert proc.returncode == 1
    assert json.loads(proc.stdout)["reached_plane"] is False


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("{oops", "invalid JSON"),
        (
            '{"vertices_coords": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], '
            '"faces_vertices": [[0, 1, 2], [0, 1, 3], [0, 1, 2]]}',
            "edge",
        ),
    ],
)
def test_deform_cli_bad_input(tmp_path, content, needle):
    bad = tmp_path / "bad.fold"
    bad.write_text(content)
    proc = run_cli("deform", str(bad), "--out", str(tmp_path / "o"))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and needle in proc.stderr
    assert "Traceback" not in proc.stderr


def test_load_factor_tol_and_penalty_settings_take_effect(miura_checks):
    from rigidfold.config import DEFAULTS
    from rigidfold.deform import DeformStatus

    shape, free, _ = miura_checks
    half = deform(shape, settings=DEFAULTS.with_(deform_load_tol=0.51))  # ends at 0.5
    assert half.steps == 10 and half.load_factor == pytest.approx(0.5)
    assert half.status is DeformStatus.FAILED and "from the plane" in half.message
    loose = deform(shape, settings=DEFAULTS.with_(deform_penalty=1.0))  # pins barely hold
    assert loose.history != free.history
