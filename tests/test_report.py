"""`rigidfold report DIR`: the HTML page, the figures and the 3D view of a generate run."""

from __future__ import annotations

import html
import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from rigidfold.cli.commands import main
from rigidfold.generate.specs import case_from_specs
from rigidfold.pipeline.workflows import report_run
from rigidfold.reporting import page, render_figures, view_figure
from rigidfold.reporting.view3d import best_fit
from rigidfold.rundir import SCHEMA_VERSION, load_run, read_log, target_surface

PNG = b"\x89PNG\r\n\x1a\n"
FIGURES = ["development", "dof_and_F", "surface_fit", "fold_angles", "deformation"]


def generate(out, *extra: str) -> None:
    args = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "grid:4x4"]
    assert main([*args, "--quiet", "--out", str(out), *extra]) == 0


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A small finished run with Steps 8-9 on every solution: DOF 9 -> 6, four solutions."""
    out = tmp_path_factory.mktemp("run")
    generate(out, "--target-dof", "6", "--check", "all")
    return out


@pytest.fixture
def copy(run_dir, tmp_path):
    """A copy of the run to change, without its report."""
    return shutil.copytree(
        run_dir, tmp_path / "run", ignore=shutil.ignore_patterns("report.html", "figures")
    )


@pytest.fixture(scope="module")
def reported(run_dir):
    return report_run(run_dir)


class _Links(HTMLParser):
    """Every URL an HTML page would load or link: src, href, srcset, poster, data, action."""

    def __init__(self) -> None:
        super().__init__()
        self.urls: list[str] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag, attrs) -> None:
        self.tags.append(tag)
        for name, value in attrs:
            if name in ("src", "href", "srcset", "poster", "data", "action") and value:
                self.urls.append(value)


def test_report_writes_one_page_and_the_figures(reported, run_dir):
    assert reported.html == run_dir / "report.html"
    assert [p.name for p in reported.figures] == [f"{n}.png" for n in FIGURES]
    for path in reported.figures:
        assert path.parent == run_dir / "figures"
        assert path.read_bytes().startswith(PNG)
    info = reported.to_dict()
    summary = json.loads((run_dir / "summary.json").read_text())
    assert info["final_design"] == summary["solutions"][-1] == "solutions/step_03_dof_06.fold"
    assert (info["final_dof"], info["n_lock"]) == (6, summary["n_lock"])
    assert info["checks"] == {
        "development": "passed",
        "folding motion": "passed",
        "large deformation": "passed",
        "fit to the target": "passed",
    }
    assert 0 < info["size_bytes"] < 10e6
    assert sorted(p.name for p in run_dir.iterdir() if p.name.startswith(".")) == []


def test_page_opens_with_the_answer(reported):
    text = reported.html.read_text()
    answer = text[: text.index('id="view"')]
    # the verdict generate judged its exit code by (summary.json), word for word
    assert (
        '"verdict ok">Passed; the target DOF was reached and every check of the final '
        "design passed." in answer
    )
    for label, value in [("final DOF", "6"), ("target DOF", "6"), ("N_lock", "0")]:
        assert f"<dt>{label}</dt><dd>{value}</dd>" in answer
    assert "<dd>solutions/step_03_dof_06.fold</dd>" in answer
    for check in ("development", "folding motion", "large deformation"):
        assert f"<b>{check}</b>: passed" in answer
    for k in range(4):  # every solution in the table
        assert f"solutions/step_{k:02d}_dof_{9 - k:02d}.fold" in text


def test_page_is_self_contained(reported):
    text = reported.html.read_text()
    links = _Links()
    links.feed(text)
    assert links.urls and all(u.startswith(("data:image/png;base64,", "#")) for u in links.urls)
    assert "link" not in links.tags and "iframe" not in links.tags
    assert not re.search(r"<script[^>]*\bsrc=", text)
    assert not re.search(r"@import|@font-face|url\(\s*['\"]?(https?:)?//", text)
    assert "Plotly.newPlot" in text and "plotly.js v" in text  # the library is embedded


def test_not_a_generate_run_is_one_line_exit_2(tmp_path, copy, capsys):
    cases = {
        tmp_path / "missing": "is not a directory",
        tmp_path: "is not a rigidfold generate run: it has no summary.json",
    }
    for path, words in cases.items():
        with pytest.raises(ValueError, match=words):
            report_run(path)
        assert main(["report", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err
    (copy / "summary.json").write_text('{"stop": "running"}')
    with pytest.raises(ValueError, match=r"not the summary of rigidfold generate \(no stop_re"):
        report_run(copy)
    (copy / "summary.json").write_text("[1, 2")
    with pytest.raises(ValueError, match=r"cannot read .*summary\.json"):
        report_run(copy)


def test_missing_solution_file_and_malformed_log(run_dir, copy):
    (copy / "solutions" / "step_02_dof_07.fold").unlink()
    with pytest.raises(ValueError, match=r"step_02_dof_07\.fold' listed in summary\.json"):
        report_run(copy)
    shutil.copy(run_dir / "solutions" / "step_02_dof_07.fold", copy / "solutions")
    (copy / "log.jsonl").write_text('{"schema_version": 1}\n3\n')
    with pytest.raises(ValueError, match=r"log\.jsonl', line 2: 3 is not a JSON object"):
        report_run(copy)
    assert not (copy / "report.html").exists()


def test_report_writes_no_file_through_a_link(copy, tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text("keep")
    (copy / "report.html").symlink_to(outside)
    (copy / "figures").mkdir()
    (copy / "figures" / "development.png").symlink_to(outside)
    report_run(copy)
    assert outside.read_text() == "keep"
    for path in (copy / "report.html", copy / "figures" / "development.png"):
        assert path.is_file() and not path.is_symlink()


def test_cli_report_prints_the_page(run_dir, capsys):
    assert main(["report", str(run_dir)]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"wrote {run_dir / 'report.html'} (") and "5 figures" in out
    assert main(["report", str(run_dir), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["final_design"] == "solutions/step_03_dof_06.fold"


def test_view_colours_by_distance_to_target_and_folds_from_flat(run_dir):
    run = load_run(run_dir)
    final = run.final
    assert final is not None and run.surface is not None
    view = view_figure(final, run.surface)
    mesh = view["data"][0]
    x, y, z = final.coords.T
    dz_mm = (z - run.surface.height(x, y)) * 1e3
    assert np.allclose(mesh["intensity"], dz_mm, atol=1e-3)
    assert mesh["cmin"] == -mesh["cmax"] == pytest.approx(-np.abs(dz_mm).max(), abs=1e-9)
    assert [t["name"] for t in view["data"][1:]] == [
        "flat crease",
        "fixed crease",
        "mountain",
        "valley",
        "boundary",
        "target surface",
    ]
    assert view["data"][-1]["type"] == "surface" and view["data"][-1]["opacity"] < 1
    frames = view["frames"]
    assert [f["name"] for f in frames] == [f"{10 * k}%" for k in range(11)]
    assert view["layout"]["sliders"][0]["active"] == 10
    flat = np.column_stack([frames[0]["data"][0][a] for a in "xyz"])
    folded = np.column_stack([frames[-1]["data"][0][a] for a in "xyz"])
    assert np.linalg.svd(flat - flat.mean(axis=0), compute_uv=False)[2] < 1e-4  # a plane
    assert np.allclose(folded, final.coords, atol=1e-4)  # the design, where it is


def test_best_fit_undoes_a_rigid_motion():
    rng = np.random.default_rng(3)
    target = rng.normal(size=(12, 3))
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))  # a rotation
    frames = np.stack([target, target @ q.T + [1.0, -2.0, 0.5]])
    assert np.allclose(best_fit(frames, target), target[None])


@pytest.mark.parametrize(
    ("name", "options"),
    [("bezier", {"seed": 4}), ("dome", {}), ("hp", {}), ("expr", {"expr": "0.2*sin(x)*y"})],
)
def test_target_surface_is_rebuilt_from_the_summary(name, options):
    case = case_from_specs(name, "grid:3x3", size="2x1.5", **options)
    surface, note = target_surface(case.metadata()["surface"])
    assert note == "" and surface is not None
    x, y = np.meshgrid(np.linspace(0, 2, 5), np.linspace(0, 1.5, 4))
    assert np.allclose(surface.height(x, y), case.surface.height(x, y), rtol=0, atol=1e-12)


def test_unknown_surface_reports_without_the_fit(copy):
    summary = json.loads((copy / "summary.json").read_text())
    summary["case"]["surface"] = {"name": "mesh:terrain.csv"}
    (copy / "summary.json").write_text(json.dumps(summary))
    report = report_run(copy)
    assert "surface_fit.png" not in [p.name for p in report.figures]
    text = html.unescape(report.html.read_text())
    assert "the target surface 'mesh:terrain.csv' cannot be rebuilt" in text
    assert report.to_dict()["checks"]["large deformation"] == "passed"


def test_lock_and_exceed_attempts_are_drawn(copy):
    last = read_log(copy / "log.jsonl")[-1].to_dict()
    with (copy / "log.jsonl").open("a") as log:  # appended, as the run writer does
        for line in (
            {**last, "index": 4, "outcome": "lock", "dof": 5, "locked": [7]},
            {**last, "index": 5, "outcome": "exceed", "dof": None, "F": None, "locked": []},
        ):
            log.write(json.dumps(line) + "\n")
    run = load_run(copy)
    figures = render_figures(run)
    assert [f.name for f in figures] == [f"{n}.png" for n in FIGURES]
    text = page(run, figures, view_figure(run.final, run.surface))
    assert "Attempts (6, log.jsonl)" in text


def test_run_without_step_9_says_not_run(tmp_path):
    generate(tmp_path, "--target-dof", "8", "--no-deform")
    report = report_run(tmp_path)
    assert report.to_dict()["checks"] == {
        "development": "passed",
        "folding motion": "passed",
        "large deformation": "not run",
        "fit to the target": "passed",
    }
    assert "deformation.png" not in [p.name for p in report.figures]
    assert "Passed; the target DOF was reached and every check" in report.html.read_text()


def test_run_without_solution_and_unfinished_run(copy):
    summary = json.loads((copy / "summary.json").read_text())
    first = {**read_log(copy / "log.jsonl")[0].to_dict(), "outcome": "initial_failed", "dof": None}
    header = json.dumps({"schema_version": SCHEMA_VERSION})
    (copy / "log.jsonl").write_text(f"{header}\n{json.dumps(first)}\n")
    failed = {
        **summary,
        "stop": "initial_failed",
        "stop_reason": "no developable polyhedron from the initial shape (exceed)",
        "final_dof": None,
        "solutions": [],
        "per_solution": [],
        "verdict": None,  # as before generate judged it (the report judges by itself)
    }
    (copy / "summary.json").write_text(json.dumps(failed))
    report = report_run(copy)
    assert [p.name for p in report.figures] == ["dof_and_F.png"]
    text = html.unescape(report.html.read_text())
    assert '<p class="verdict bad">No solution; target DOF 6 not reached: no developable' in text
    assert "<dt>final design</dt><dd>none</dd>" in text and "Plotly" not in text
    (copy / "summary.json").write_text(json.dumps({**summary, "stop": "running", "verdict": None}))
    text = report_run(copy).html.read_text()
    assert '"verdict none">Every check passed; the run has not finished' in text


def test_the_solutions_table_says_whether_deformation_and_motion_agree(reported):
    text = reported.html.read_text()
    assert "<th>deformation vs motion</th>" in text
    assert text.count("<td>agree</td>") == 4  # every solution of the run


# ----------------------------------------------------------------- issue 30, item 25
MESH = Path(__file__).parent / "data" / "dome_yup.obj"


def test_a_mesh_target_is_shown_with_its_fit(tmp_path):
    """A ``mesh:`` target is stored in the run (target_surface.json, the fitted spline's
    grid, named in summary.json), so the report draws the overlay, the deviation colours
    and surface_fit.png: the same heights as the run's surface."""
    out = tmp_path / "run"
    argv = ["generate", "--surface", f"mesh:{MESH}", "--up", "y", "--pattern", "grid:4x4"]
    assert main([*argv, "--target-dof", "8", "--no-deform", "--quiet", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["target_surface"] == "target_surface.json"
    report = report_run(out)
    assert "surface_fit.png" in [p.name for p in report.figures]
    text = html.unescape(report.html.read_text())
    assert "cannot be rebuilt" not in text and "the target surface is the grey overlay" in text
    run = load_run(out)
    case = case_from_specs(f"mesh:{MESH}", "grid:4x4", up="y")
    x, y = np.meshgrid(np.linspace(0, 3, 7), np.linspace(0, 3, 5))
    assert run.surface is not None
    assert np.allclose(run.surface.height(x, y), case.surface.height(x, y), rtol=0, atol=1e-12)
    assert view_figure(run.final, run.surface)["data"][-1]["name"] == "target surface"
    # a damaged or missing fit file: the report is written without the fit, saying why
    (out / "target_surface.json").write_text('{"x": [0, 1], "y": [0, 1], "z": [[0, "a"]]}')
    text = html.unescape(report_run(out).html.read_text())
    assert "the target surface could not be rebuilt" in text and "target_surface.json" in text
    (out / "target_surface.json").unlink()
    assert "surface_fit.png" not in [p.name for p in report_run(out).figures]


def test_a_fit_at_the_dz_bound_is_flagged(copy):
    """The final design touches the dz bound: the report says so (a larger --dz, or
    another pattern, may fit the target better)."""
    summary = json.loads((copy / "summary.json").read_text())
    text = html.unescape(report_run(copy).html.read_text())
    assert "dz bound" not in text
    reached = summary["per_solution"][-1]["fit"]["max_abs_dz_m"]
    summary["case"]["dz_m"] = reached
    (copy / "summary.json").write_text(json.dumps(summary))
    text = html.unescape(report_run(copy).html.read_text())
    assert f"at the dz bound: max |z - target| = {reached * 1e3:.1f} mm = dz" in text


def test_a_failed_check_of_an_earlier_solution_is_not_drawn_failed(copy):
    """The development diagram of step 1 failed, the final design's passed: under the green
    "Passed" the check says which step failed instead of "FAILED"."""
    summary = json.loads((copy / "summary.json").read_text())
    summary["per_solution"][1]["development"]["status"] = "failed"
    (copy / "summary.json").write_text(json.dumps(summary))
    report = report_run(copy)
    text = html.unescape(report.html.read_text())
    answer = text[: text.index('id="view"')]
    assert '"verdict ok">Passed' in answer
    assert "<b>development</b>: FAILED" not in answer
    assert "<b>development</b>: passed by the final design" in answer
    assert "failed at step 1 (not the final design)" in answer
    assert report.to_dict()["checks"]["development"] == "passed by the final design"
    summary["per_solution"][-1]["development"]["status"] = "failed"  # the final's: FAILED
    (copy / "summary.json").write_text(json.dumps(summary))
    answer = html.unescape(report_run(copy).html.read_text())
    assert "<b>development</b>: FAILED" in answer and "failed at step 1, 3" in answer


def test_an_interrupted_run_says_so(copy):
    """Issue 30, item 21: summary.json of a run stopped by Ctrl-C says "interrupted"; the
    report says the run was interrupted, not that the target was not reached."""
    summary = json.loads((copy / "summary.json").read_text())
    interrupted = {**summary, "stop": "interrupted", "stop_reason": "interrupted", "verdict": None}
    (copy / "summary.json").write_text(json.dumps(interrupted))
    text = html.unescape(report_run(copy).html.read_text())
    assert "the run was interrupted (Ctrl-C or SIGTERM): this is its state then" in text
    assert "not reached" not in text[: text.index('id="view"')]
