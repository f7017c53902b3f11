"""Thin sheets in ``fabricate`` (issue 47, item 8).

The clearance that panels without a common hinge keep over the motion is a share of the
thickness (``Settings.fabricate.clearance_share``, 5 %), never below a floor
(``clearance_min``, 0.01 mm): before, it was 1 mm whatever the thickness, a whole vertex
relief at 1 mm, which the check could not prove (a false collision after minutes of
halving). A thickness too thin for the solids' geometry next to the design's size is
refused in one line, instead of "trimmed away ... keeps 100 % of its area".
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from conftest import main_code
from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.build import check_thickness

DATA = Path(__file__).parent / "data"
AFRAME = DATA / "aframe.fold"
ROOF = DATA / "roof_12x8_dof1.fold"


def _fabricate(design: Path, out: Path, *args: str) -> tuple[int, str, str, dict | None]:
    """(exit code, stdout, stderr, NAME_fabricate.json or None) of ``rigidfold fabricate``."""
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main_code(["fabricate", str(design), "--out", str(out), *args])
    path = out / f"{design.stem}_fabricate.json"
    summary = json.loads(path.read_text()) if path.exists() else None
    return code, stdout.getvalue(), stderr.getvalue(), summary


def test_the_clearance_is_a_share_of_the_thickness_with_a_floor():
    fab = DEFAULTS.fabricate
    assert fab.clearance_share == 0.05 and fab.clearance_min == 1e-5
    assert fab.clearance(0.020) == pytest.approx(1e-3)  # 1 mm at 20 mm, as before
    assert fab.clearance(0.018) == pytest.approx(0.9e-3)
    assert fab.clearance(0.001) == pytest.approx(5e-5)  # 0.05 mm at 1 mm: not a whole relief
    assert fab.clearance(1e-4) == pytest.approx(1e-5)  # the floor below 0.2 mm
    # the clearance stays well inside the vertex relief (one thickness), whatever the sheet
    for t in (1e-3, 0.018, 0.05):
        assert fab.clearance(t) < fab.vertex_relief * t / 10
    with pytest.raises(RigidfoldError, match="fabricate_clearance_share"):
        Settings().with_(fabricate_clearance_share=-0.1)


@pytest.mark.parametrize(("thickness", "gap"), [("1mm", 5e-5), ("20mm", 1e-3)])
def test_the_check_requires_the_clearance_of_its_thickness(tmp_path, thickness, gap):
    code, out, _, summary = _fabricate(AFRAME, tmp_path, "--thickness", thickness)
    assert code == 0 and out.strip().splitlines()[-1].startswith("collision-free")
    assert summary is not None
    assert summary["check"]["required_gap_m"] == pytest.approx(gap)
    assert summary["check"]["proven_gap_m"] >= summary["check"]["required_gap_m"]


def test_a_thin_roof_deploys_without_deepened_reliefs():
    """The 12 m x 8 m roof at 1 mm: the gaps near its relief vertices are a share of the
    thickness, which the 0.05 mm clearance lets the check prove (with 1 mm it reported a
    collision between panels 16 and 18, proven only down to 0.99 mm)."""
    from rigidfold.exports import read_design
    from rigidfold.fabricate import Panels, design_motion, fabricate_panels

    design = read_design(ROOF)
    panels = Panels(design.pattern, design.coords2d, "bottom")
    motion, _ = design_motion(panels)
    assert motion is not None
    fab = fabricate_panels(panels, motion, 1e-3, search=False)
    assert fab.ok and fab.relief_rounds == 0
    assert fab.clearance is not None and fab.clearance.clearance == pytest.approx(5e-5)
    assert fab.clearance.bound >= 5e-5


def test_too_thin_for_the_design_is_refused_in_one_line(tmp_path):
    code, _, err, summary = _fabricate(AFRAME, tmp_path, "--thickness", "1e-5mm")
    assert code == 2 and summary is None
    (line,) = err.strip().splitlines()
    assert "thickness 1e-05 mm is too thin for a design 1.61 m across" in line
    assert "Settings.fabricate.thinnest" in line
    # the limit is a share of the design's size: one micrometre on a metre
    assert check_thickness(2e-6, [[0, 0, 0], [1, 0, 0]]) == pytest.approx(1e-6)
    with pytest.raises(RigidfoldError, match="too thin"):
        check_thickness(1e-7, [[0, 0, 0], [1, 0, 0]])


def test_a_trimmed_panel_is_named_by_what_it_lost(tmp_path):
    """The walls' bevels on the inside at 1 m take most of the floor: the message gives the
    share it keeps, below the limit, never a share that would pass."""
    code, out, _, summary = _fabricate(AFRAME, tmp_path, "--thickness", "1000mm", "--side", "top")
    assert code == 1 and summary is not None and summary["status"] == "panel_trimmed_away"
    last = out.strip().splitlines()[-1]
    assert "panel 0 keeps 14% of its area x thickness (less than 20%)" in last
    assert "100%" not in last


def test_a_study_written_with_the_fixed_clearance_is_resumed():
    """A study builds no thick panels: its stored ``fabricate_clearance`` (the fixed 1 mm of
    before) and the new fields it lacks are not a difference."""
    from rigidfold.study import StudyConfig
    from rigidfold.study.store import config_differences

    current = StudyConfig().as_dict()
    stored = json.loads(json.dumps(current))
    del (
        stored["settings"]["fabricate_clearance_share"],
        stored["settings"]["fabricate_clearance_min"],
    )
    stored["settings"]["fabricate_clearance"] = 1e-3
    assert config_differences(stored, current) == []
    stored["settings"]["path_step"] = 2 * current["settings"]["path_step"]
    assert config_differences(stored, current) == ["settings.path_step"]


def test_generate_refuses_too_thin_panels_before_the_run(tmp_path):
    stderr = io.StringIO()
    argv = ["generate", "--surface", "bezier", "--pattern", "grid:3x3", "--size", "1x1"]
    argv += ["--quiet", "--no-deform"]
    with contextlib.redirect_stderr(stderr):
        code = main_code([*argv, "--thickness", "1e-5mm", "--out", str(tmp_path / "run")])
    assert code == 2
    (line,) = stderr.getvalue().strip().splitlines()
    assert "too thin for a design" in line
    assert not (tmp_path / "run" / "log.jsonl").exists()  # refused before the first solve
