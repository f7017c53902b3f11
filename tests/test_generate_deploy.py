"""``generate --deploy``: the final design's deployment drive as a check of the run (issue
48): its files in final/deploy/, its figures in summary.json, its stage in the verdict, its
curve and driven crease in the report."""

from __future__ import annotations

import json

import pytest

from rigidfold.cli.commands import main
from rigidfold.rundir import SolutionRecord, Stage, load_run

PATTERN_1 = ["--surface", "bezier", "--seed", "1", "--pattern", "1", "--criterion", "shat"]


@pytest.fixture(scope="module")
def deployed(tmp_path_factory):
    out = tmp_path_factory.mktemp("deploy")
    argv = ["generate", *PATTERN_1, "--no-deform", "--quiet", "--deploy", "--out", str(out)]
    return main(argv), out


def test_the_final_design_is_driven_and_its_files_written(deployed, capsys):
    code, out = deployed
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["options"]["drive"]["base"] == "auto"
    final = SolutionRecord.from_dict(summary["per_solution"][-1])
    assert final.passed(Stage.DRIVE) is True
    assert final.drive is not None and final.drive["message"].startswith("drive ")
    data = json.loads((out / "final" / "deploy" / "deploy.json").read_text())
    assert data["drive"]["kind"] in {"crease", "pair", "cable"}
    assert sorted(final.drive["files"]) == sorted(
        f"final/deploy/{n}" for n in ("deploy.json", "deploy.fold", "deploy.csv", "deploy.png")
    )


def test_the_report_shows_the_curve_and_the_driven_crease(deployed):
    _, out = deployed
    run = load_run(out)
    assert run.drive_figure() is not None and run.drive_figure()[:4] == b"\x89PNG"
    html = (out / "report.html").read_text()
    assert 'id="drive"' in html and 'id="deploy.png"' in html
    assert "driven crease" in html  # the 3D view's orange trace
    if json.loads((out / "final" / "deploy" / "deploy.json").read_text())["drive"]["kind"] in (
        "crease",
        "pair",
    ):
        assert run.driven_creases()


def test_a_final_design_that_is_not_dof_1_fails_the_drive_stage(tmp_path, capsys):
    argv = [
        "generate",
        *PATTERN_1,
        "--target-dof",
        "19",
        "--no-deform",
        "--quiet",
        "--no-report",
        "--deploy",
        "--out",
        str(tmp_path),
    ]
    assert main(argv) == 1
    summary = json.loads((tmp_path / "summary.json").read_text())
    final = SolutionRecord.from_dict(summary["per_solution"][-1])
    assert final.passed(Stage.DRIVE) is False
    assert "DOF 19, not 1" in final.drive["message"]
