"""Step 9 (OpenSees large-deformation check), the folding motion and `rigidfold deform`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from conftest import run_cli
from rigidfold.case import make_case
from rigidfold.cli import main
from rigidfold.deform import TubeSection, deform, folding_motion, verify
from rigidfold.develop import develop
from rigidfold.generate import generate
from rigidfold.io import read_fold, write_fold
from rigidfold.mesh.geometry import edge_lengths
from rigidfold.patterns import miura
from rigidfold.report import verification_frames


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
    assert np.allclose(motion.frames[-1], shape.coords, atol=1e-12)
    assert motion.max_length_error < 1e-8
    for frame in motion.frames:
        assert np.allclose(edge_lengths(frame, shape.edges), shape.edge_lengths, rtol=1e-8)


def test_one_dof_path_trace_of_a_miura_reaches_the_plane():
    from rigidfold.deform.motion import trace_one_dof_path

    shape = miura(3, 3, height=0.5)
    trace = trace_one_dof_path(shape)
    assert trace.reached_flat and trace.measure[-1] <= 0.1
    assert np.all(np.diff(trace.measure) < 0)  # a Miura-ori unfolds monotonically
    for x in trace.frames_towards_flat(10):
        frame = x.reshape(-1, 3)
        assert np.allclose(edge_lengths(frame, shape.edges), shape.edge_lengths, rtol=1e-10)
    assert trace_one_dof_path(locked_miura(shape)) is None  # 0 DOF: no path
    assert trace_one_dof_path(make_case("bezier", "1", seed=0).pattern) is None  # 21 DOF


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
    run = generate(make_case("bezier", "1", seed=1), criterion="shat", seed=1)
    assert run.final_dof == 1
    return run.solutions[-1].result.pattern


def test_generated_one_dof_shape_passes_steps_8_and_9(one_dof_solution):
    check = verify(one_dof_solution)
    dev, d, m = check.development, check.deformation, check.motion
    assert dev.D < 1e-8 and dev.flipped == 0 and dev.overlaps == 0
    assert d.reached_plane and d.mean_dl_mm < 0.25 and d.mean_drho_fix_deg < 0.05
    assert m.status == "ok" and m.max_length_error < 1e-3
    assert np.abs(m.frames[0][:, 2]).max() < 1e-9
    assert np.allclose(m.frames[-1], one_dof_solution.coords, atol=1e-9)
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


def count_calls(monkeypatch, module, name: str, result=None) -> dict:
    """Replace ``module.name`` by a wrapper that counts its calls (returning ``result``
    instead of calling it, when given)."""
    real, calls = getattr(module, name), {"n": 0}

    def wrapper(*args, **kwargs):
        calls["n"] += 1
        return real(*args, **kwargs) if result is None else result(*args)

    monkeypatch.setattr(module, name, wrapper)
    return calls


def test_motion_halvings_have_their_own_setting(monkeypatch):
    from rigidfold.config import DEFAULTS
    from rigidfold.deform import motion as motion_module

    shape = miura(3, 3)
    calls = count_calls(monkeypatch, motion_module, "_newton", lambda c, x, t, s: (x, False))
    monkeypatch.setattr(motion_module, "trace_one_dof_path", lambda *a, **k: None)
    settings = DEFAULTS.with_(motion_max_halvings=2, deform_max_halvings=6)
    m = folding_motion(shape, np.zeros((shape.n_vertices, 2)), settings=settings)
    assert m.status == "failed" and calls["n"] == 3  # the first step and two halvings


def test_motion_level_tol_takes_effect(monkeypatch):
    from rigidfold.config import DEFAULTS
    from rigidfold.deform import motion as motion_module

    shape = miura(3, 3)
    calls = count_calls(monkeypatch, motion_module, "_newton")
    flat = develop(shape).coords2d
    m = folding_motion(shape, flat, settings=DEFAULTS.with_(motion_level_tol=1.0))
    assert m.status == "ok" and calls["n"] == 0  # every level counts as reached
    assert folding_motion(shape, flat).status == "ok" and calls["n"] > 0


def test_motion_stall_settings_take_effect(monkeypatch):
    from rigidfold.config import DEFAULTS
    from rigidfold.deform import motion as motion_module

    shape = miura(3, 3)
    cons = motion_module._Constraints(shape, 0)
    calls = count_calls(monkeypatch, motion_module._Constraints, "__call__")
    x = shape.coords.ravel().copy()
    # a negative folding measure cannot be reached: Newton stalls
    stall = DEFAULTS.with_(motion_stall_iter=1, motion_stall_ratio=0.0)
    _, ok = motion_module._newton(cons, x, -1.0, stall)
    assert not ok and calls["n"] == 3  # iterations 0 and 1, then the final residual
    calls["n"] = 0
    motion_module._newton(cons, x, -1.0, DEFAULTS)
    assert calls["n"] > 3


def test_path_trace_settings_take_effect(monkeypatch):
    from rigidfold.config import DEFAULTS
    from rigidfold.deform.motion import trace_one_dof_path

    shape = miura(3, 3, height=0.5)
    turned = trace_one_dof_path(shape, settings=DEFAULTS.with_(motion_turn_back=-1.0))
    assert not turned.reached_flat and "turns back" in turned.message
    assert len(turned.points) == 2  # the first step already counts as turning back
    stuck = DEFAULTS.with_(motion_max_iter=1, motion_arc_min_step=1.0)
    trace = trace_one_dof_path(shape, settings=stuck)
    assert "could not be continued" in trace.message and len(trace.points) == 1
