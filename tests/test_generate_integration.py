"""``rigidfold generate --thickness T`` and ``--structure`` (issues 31 and 32): the final
design's thick panels and structure check run inside the run, into DIR/final/thick/ and
DIR/final/structure/, recorded in summary.json, judged by the verdict and shown in the
report; runs written before them still read."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.generate import GenerateOptions
from rigidfold.rundir import Stage, load_run
from rigidfold.structure import StructureOptions, Uniform
from rigidfold.study import STUDY_OPTIONS, StudyConfig

FAST = [
    "generate",
    "--surface",
    "bezier",
    "--seed",
    "1",
    "--pattern",
    "1",
    "--target-dof",
    "18",
    "--quiet",
    "--no-deform",
]
"""A short run: three creases fixed on the paper's pattern 1 (seconds)."""


@pytest.fixture(scope="module")
def passing(tmp_path_factory):
    out = tmp_path_factory.mktemp("built")
    argv = [*FAST, "--thickness", "20mm", "--structure", "--limit", "L/20", "--out", str(out)]
    return out, main_code(argv)


@pytest.fixture(scope="module")
def failing(tmp_path_factory):
    """Panels far too thick for the pattern's small panels, and a limit no design meets."""
    out = tmp_path_factory.mktemp("built_bad")
    argv = [*FAST, "--thickness", "0.4", "--structure", "--limit", "L/100000"]
    return out, main_code([*argv, "--no-report", "--out", str(out)])


def _final(out: Path) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    return summary, summary["per_solution"][summary["final_step"]]


def test_thick_panels_and_structure_pass_and_are_written(passing):
    out, code = passing
    assert code == 0
    summary, record = _final(out)
    fab = record["fabrication"]
    assert fab["status"] == "collision_free" and fab["thickness_m"] == pytest.approx(0.02)
    assert fab["panels"] >= 1 and 0 <= fab["trimming_loss"] < 1
    assert fab["min_gap_m"] >= fab["required_gap_m"]
    a, b = fab["closest"]["panels"]
    assert a != b and 0 <= fab["closest"]["fraction"] <= 1
    for name in fab["files"]:
        assert (out / name).is_file() and name.startswith("final/thick/")
    stem = Path(summary["solutions"][-1]).stem
    for suffix in ("_solids.glb", "_solids.obj", "_solids.3dm", "_hinges.csv", "_fabricate.json"):
        assert (out / "final" / "thick" / f"{stem}{suffix}").is_file()
    st = record["structure"]
    assert st["status"] == "passed" and st["serviceability_ok"] is True
    assert st["max_displacement_m"] <= st["allowed_displacement_m"]
    assert st["balance_error"] < 1e-3  # the reactions balance the loads
    assert (out / "final" / "structure" / "structure.json").is_file()
    assert (out / st["figure"]).is_file()
    assert summary["fabrication"]["checked"] == 1 and summary["fabrication"]["collision_free"] == 1
    assert summary["structure"] == {
        "checked": 1,
        "passed": 1,
        "max_displacement_m": st["max_displacement_m"],
    }
    assert summary["verdict"]["outcome"] == "passed"
    # only the final design gets them
    assert all(r["fabrication"] is None for r in summary["per_solution"][:-1])


def test_report_shows_thick_panels_and_structure(passing):
    out, _ = passing
    text = (out / "report.html").read_text()
    assert '<h2 id="thick">Thick panels</h2>' in text and 'id="thick3d"' in text
    assert "closest pair" in text and "trimming loss" in text
    assert '<h2 id="structure">Structure</h2>' in text and "Reactions" in text
    assert 'alt="deflected shape" src="data:image/png;base64,' in text
    assert "<b>thick panels</b>: passed" in text and "<b>structure</b>: passed" in text
    assert text.count("plotly.js v") == 1  # the library embedded once, for both views


def test_thick_panels_read_back_from_their_file(passing):
    out, _ = passing
    run = load_run(out)
    thick, note = run.thick_panels()
    assert thick is not None and note == ""
    record = run.final_record
    assert len(thick.names) == record.fabrication["panels"]
    assert sorted(thick.panel.tolist()) == list(range(len(thick.names)))
    assert thick.closest == tuple(record.fabrication["closest"]["panels"])
    for verts, faces in zip(thick.vertices, thick.faces, strict=True):
        assert len(faces) and faces.max() < len(verts)
        # a closed solid: every edge is shared by exactly two triangles
        edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        assert set(counts.tolist()) == {2}
    assert {c.name: c.word for c in run.checks()}["thick panels"] == "passed"
    assert run.structure_figure().startswith(b"\x89PNG")


def test_failing_thick_panels_and_limit_fall_short(failing):
    out, code = failing
    assert code == 1
    summary, record = _final(out)
    assert record["fabrication"]["status"] != "collision_free"
    assert record["structure"]["status"] == "deflection"
    shortfalls = summary["verdict"]["shortfalls"]
    assert any(s.startswith(Stage.FABRICATION.message) for s in shortfalls)
    assert any(s.startswith(Stage.STRUCTURE.message) for s in shortfalls)
    assert "L/100000" in summary["verdict"]["message"]
    assert list((out / "final" / "thick").glob("*_solids.obj"))  # written all the same
    words = {c.name: c.word for c in load_run(out).checks()}
    assert words["thick panels"] == words["structure"] == "FAILED"


@pytest.mark.parametrize(
    "changes",
    [
        {"target_dof": -1},
        {"seed": -1},
        {"material": "unobtainium"},
        {"fabricate": 0.02},
        {"structure": True},
    ],
)
def test_options_are_validated(changes):
    with pytest.raises(RigidfoldError):
        GenerateOptions(**changes)


def test_options_round_trip_and_studies_do_not_store_them():
    structure = StructureOptions(thickness=0.018, loads=(Uniform(0.5),), limit=300.0)
    opts = GenerateOptions(fabricate=FabricateOptions(0.018), structure=structure)
    assert len(opts.structure.loads) == 1 and opts.structure.limit == 300.0
    assert GenerateOptions.from_dict(json.loads(json.dumps(opts.to_dict()))) == opts
    stored = StudyConfig(STUDY_OPTIONS).as_dict()
    assert set(stored) == {
        "deform",
        "target_dof",
        "solver",
        "settings",
        "lookahead",
        "deploy_check",
        "check",
    }


@pytest.mark.parametrize(
    "extra",
    [
        ["--thickness", "0mm"],
        ["--thickness", "thick"],
        ["--structure", "--supports", "9999"],
        ["--structure", "--load", "point=9999:0,0,-1"],
        ["--structure", "--material", "1,2"],
    ],
)
def test_bad_options_exit_2_before_the_run(tmp_path, extra):
    assert main_code([*FAST, *extra, "--out", str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x" / "summary.json").exists()


STEP9_RUN = ["generate", "--surface", "dome", "--pattern", "grid:3x3", "--quiet", "--no-report"]
"""Three solutions, DOF 5 -> 3, with Step 9 on the final design (seconds)."""


def test_step9_takes_the_users_material(tmp_path):
    """Issue 32, item 1: with --material, Step 9's frame is of strips of the user's panels
    (not the paper's steel tubes), so its figures differ; without, the paper's tubes."""
    figures = {}
    for name, extra in (("tubes", []), ("plywood", ["--material", "plywood"])):
        out = tmp_path / name
        assert main_code([*STEP9_RUN, *extra, "--out", str(out)]) == 1  # DOF 3: falls short
        summary = json.loads((out / "summary.json").read_text())
        assert summary["options"]["material"] == (None if name == "tubes" else "plywood")
        (deformed,) = [r["deformation"] for r in summary["per_solution"] if r["deformation"]]
        assert deformed["reached_plane"]
        figures[name] = deformed["max_dl_mm"]
    assert figures["tubes"] != pytest.approx(figures["plywood"], rel=1e-3)
    from rigidfold.config import DEFAULTS
    from rigidfold.material import MATERIALS

    assert GenerateOptions().panel_material == MATERIALS[DEFAULTS.structure.material]
    assert GenerateOptions(material=MATERIALS["steel"]).panel_material == MATERIALS["steel"]


def test_a_check_that_cannot_run_is_a_failed_stage_not_a_lost_run(tmp_path, monkeypatch):
    """A structure check that cannot run on the final design (a RigidfoldError from the
    analysis) fails its stage with its message: the run still ends with its verdict,
    summary.json and report (nothing computed is lost)."""
    import rigidfold.pipeline.checks as checks

    def cannot(*args, **kwargs):
        raise RigidfoldError("the shell model is singular\nat load step 1")

    monkeypatch.setattr(checks, "structure_check", cannot)
    out = tmp_path / "run"
    assert main_code([*FAST, "--structure", "--out", str(out)]) == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["verdict"]["outcome"] == "fell_short"
    message = "the structure could not be checked: the shell model is singular at load step 1"
    assert any(message in s for s in summary["verdict"]["shortfalls"])
    assert summary["per_solution"][-1]["structure"]["status"] == "error"
    assert message in (out / "report.html").read_text()
    assert Stage.STRUCTURE in load_run(out).summary.per_solution[-1].failed_stages()
