"""`rigidfold generate` and `rigidfold analyze` from the command line."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rigidfold.generate.steps as generate_module
from conftest import run_cli, run_cli_size_limited
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.io import fold_dict, read_fold, write_fold
from rigidfold.mesh.geometry import best_fit
from rigidfold.patterns import miura
from rigidfold.rundir import read_log


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    out = tmp_path_factory.mktemp("gen")
    code = main(
        [
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
            "--out",
            str(out),
        ]
    )
    assert code == 0
    return out


def test_generate_writes_solutions_log_and_summary(generated):
    names = sorted(p.name for p in (generated / "solutions").glob("*.fold"))
    assert names == [f"step_{k:02d}_dof_{21 - k:02d}.fold" for k in range(4)]
    # the development diagram (and its SVG) of the final design only (issue 49: outputs off
    # the search's path); the other solutions' records say it was not computed
    assert [p.name for p in (generated / "solutions").glob("*.svg")] == ["step_03_dof_18.svg"]
    summary = json.loads((generated / "summary.json").read_text())
    assert (summary["initial_dof"], summary["final_dof"], summary["n_reduce"]) == (21, 18, 3)
    assert summary["n_lock"] == 0 and summary["n_exceed"] == 0
    assert set(summary["time_s"]) == {
        "build",
        "solve",
        "analysis",
        "selection",
        "path",
        "develop",
        "deform",
        "motion",
    }
    dev = summary["development"]
    assert dev["max_D"] < 1e-8 and dev["flipped"] == 0 and dev["overlaps"] == 0
    assert len(summary["per_solution"]) == 4
    assert [s["development"]["status"] for s in summary["per_solution"]] == ["not_computed"] * 3 + [
        "converged"
    ]
    assert summary["time_s"]["develop"] > 0
    for name in names[:-1]:  # a FOLD file without a diagram frame reads back whole
        data = read_fold(generated / "solutions" / name)
        assert data.metadata["dof"] == 21 - int(name[5:7]) and "development" not in data.metadata
    # --no-deform: no Step 9; the development of the final design, the folding motion of the
    # final design (--check final, the default), its path traced for the deployability check
    assert summary["deformation"]["checked"] == 0 and summary["time_s"]["deform"] == 0.0
    assert summary["motion"]["traced"] == 1 and summary["motion"]["max_length_error"] < 1e-8
    assert [s["motion"] is None for s in summary["per_solution"]] == [True] * 3 + [False]
    assert summary["n_path"] == 0 and summary["final_deploys"] is True
    assert summary["per_solution"][-1]["deployability"]["deploys"] is True
    assert summary["verdict"] == {
        "outcome": "passed",
        "message": "the target DOF was reached and every check of the final design passed",
        "shortfalls": [],
        "warnings": [],
        "final_design": "solutions/step_03_dof_18.fold",
    }
    for entry in summary["per_solution"]:
        fit = entry["fit"]
        assert 0 <= fit["rms_dz_m"] <= fit["max_abs_dz_m"] <= DEFAULTS.design.dz + 1e-6
    log = read_log(generated / "log.jsonl")
    assert len(log) == summary["n_solves"] + summary["n_repeats"]
    assert [a.index for a in log] == list(range(len(log)))
    assert {"fixed_added", "score", "status", "F", "locked", "solve_time"} <= set(log[1].to_dict())
    last = read_fold(generated / "solutions" / names[-1])
    assert len(last.pattern.fixed_creases) == 3
    assert last.metadata["dof"] == 18
    assert last.metadata["development"]["D"] < 1e-8
    assert read_fold(generated / "solutions" / names[-1], frame=1).frame_classes == [
        "creasePattern"
    ]
    raw = json.loads((generated / "solutions" / names[-1]).read_text())
    motion = [f for f in raw["file_frames"] if f["frame_classes"] == ["foldedForm"]]
    assert len(motion) == 11
    assert np.abs(np.asarray(motion[0]["vertices_coords"])[:, 2]).max() < 1e-9
    # the last motion frame is the design, turned and moved so that its support panel lies
    # where it lies in the flat frame
    folded = best_fit(np.array([motion[-1]["vertices_coords"]]), last.pattern.coords)[0]
    assert np.allclose(folded, last.pattern.coords, atol=1e-9)


def test_analyze_json_on_a_generated_solution(generated):
    path = sorted((generated / "solutions").glob("*.fold"))[-1]
    proc = run_cli("analyze", str(path), "--json")
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["dof"] == 18
    assert report["locked_edges"] == []


def test_analyze_miura_quads(tmp_path):
    """A Miura-ori written with quad faces (as other tools do) has 1 DOF, no lock."""
    shape = miura(4, 3)
    data = fold_dict(shape)
    quads = [
        [int(v) for v in shape.faces[2 * k]] + [int(shape.faces[2 * k + 1][2])]
        for k in range(shape.n_faces // 2)
    ]
    data["faces_vertices"] = quads
    keep = [k for k, a in enumerate(data["edges_assignment"]) if a != "J"]
    data["edges_vertices"] = [data["edges_vertices"][k] for k in keep]
    data["edges_assignment"] = [data["edges_assignment"][k] for k in keep]
    data["edges_foldAngle"] = [data["edges_foldAngle"][k] for k in keep]
    path = tmp_path / "miura.fold"
    path.write_text(json.dumps(data))
    proc = run_cli("analyze", str(path), "--json")
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["dof"] == 1 and report["locked_edges"] == []


def test_analyze_reports_locked_creases(tmp_path, capsys):
    from conftest import degree_n_vertex

    shape = degree_n_vertex(4, seed=4)
    fixed = np.zeros(shape.n_edges, dtype=bool)
    fixed[shape.interior_edges[0]] = True
    write_fold(tmp_path / "v4.fold", shape.with_fixed(fixed))
    assert main(["analyze", str(tmp_path / "v4.fold"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["dof"] == 0
    assert sorted(report["locked_edges"]) == sorted(shape.interior_edges[1:].tolist())
    assert main(["analyze", str(tmp_path / "v4.fold")]) == 0
    assert "DOF: 0" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("{not json", "invalid JSON"),
        ('{"vertices_coords": [[0, 0, 0]]}', "faces_vertices"),
        ("[1, 2]", "object"),
    ],
)
def test_analyze_bad_files_one_line_exit_2(tmp_path, content, message):
    path = tmp_path / "bad.fold"
    path.write_text(content)
    proc = run_cli("analyze", str(path))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and message in proc.stderr
    assert "Traceback" not in proc.stderr


def test_analyze_missing_file():
    proc = run_cli("analyze", "no/such/file.fold")
    assert proc.returncode == 2 and "cannot read" in proc.stderr


def test_generate_interrupt_leaves_valid_files(tmp_path, monkeypatch, capsys):
    calls = {"n": 0}
    real = generate_module._classify

    def interrupting(*args, **kwargs):  # the third solve's verdict: after two solutions
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(generate_module, "_classify", interrupting)
    code = main(
        [
            "generate",
            "--surface",
            "bezier",
            "--seed",
            "1",
            "--pattern",
            "1",
            "--quiet",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 130
    assert "interrupted" in capsys.readouterr().err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_solutions"] == 2
    assert summary["stop"] == "interrupted"  # never "running"
    # no design is named: none is known to deploy (no path was traced)
    assert summary["verdict"]["outcome"] == "fell_short"
    assert summary["verdict"]["final_design"] is None
    assert "no design is known to deploy" in summary["verdict"]["message"]
    assert len(read_log(tmp_path / "log.jsonl")) == 2
    for path in (tmp_path / "solutions").glob("*.fold"):
        read_fold(path)
    assert not list(tmp_path.rglob("*.tmp"))
    assert not (tmp_path / ".rigidfold-run.lock").exists()  # released on interrupt too


def test_generate_bad_options(tmp_path):
    proc = run_cli(
        "generate",
        "--surface",
        "bezier",
        "--pattern",
        "1",
        "--criterion",
        "best",
        "--out",
        str(tmp_path),
    )
    assert proc.returncode == 2 and "invalid choice" in proc.stderr
    proc = run_cli(
        "generate",
        "--surface",
        "bezier",
        "--pattern",
        "1",
        "--target-dof",
        "-2",
        "--out",
        str(tmp_path),
    )
    assert proc.returncode == 2 and "--target-dof" in proc.stderr


SHORT_RUN = ["--surface", "dome", "--pattern", "grid:3x3", "--no-deform", "--quiet"]
"""A run that stops at DOF 3 (no candidate crease succeeds) in a few seconds."""


def test_generate_that_falls_short_exits_1_and_says_why(tmp_path, capsys):
    assert main(["generate", *SHORT_RUN, "--out", str(tmp_path)]) == 1
    last = capsys.readouterr().out.strip().splitlines()[-1]
    final = tmp_path / "solutions" / "step_02_dof_03.fold"
    assert last.startswith(
        "fell short: target DOF 1 not reached: final DOF 3 (no candidate crease succeeds); "
    )
    assert last.endswith(f"; final design: {final}")
    # most solves after the first missed F <= f_tol: the verdict says what that means
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert f"; {summary['n_exceed']} of the " in last and "no shape within dz" in last
    assert final.is_file()
    verdict = summary["verdict"]
    assert verdict["outcome"] == "fell_short"
    assert verdict["final_design"] == "solutions/step_02_dof_03.fold"


def test_an_earlier_run_is_refused_unless_overwrite(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["generate", *SHORT_RUN, "--out", str(out)]) == 1
    (out / "notes.txt").write_text("mine")
    stale = out / "solutions" / "step_99_dof_99.fold"
    stale.write_text("{}")
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "keep.txt").write_text("keep")
    shutil.rmtree(out / "figures")  # the report's figures: a link to elsewhere instead
    (out / "figures").symlink_to(outside, target_is_directory=True)
    capsys.readouterr()
    assert main(["generate", *SHORT_RUN, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert (
        len(err) == 1
        and "holds an earlier run (summary.json, log.jsonl, report.html, solutions, figures, final)"
        in err[0]
    )
    assert stale.exists()  # refused: nothing touched
    assert main(["generate", *SHORT_RUN, "--out", str(out), "--overwrite"]) == 1
    # a file the earlier run did not record stays, whatever its name (issue 47, item 4)
    assert stale.read_text() == "{}" and (out / "notes.txt").read_text() == "mine"
    # the link was removed, not followed; the new run's figures are a directory of their own
    assert not (out / "figures").is_symlink() and (out / "figures").is_dir()
    assert [p.name for p in outside.iterdir()] == ["keep.txt"]
    assert (outside / "keep.txt").read_text() == "keep"
    assert len(list((out / "solutions").glob("*.fold"))) == 3 + 1


def test_a_report_that_cannot_be_written_is_not_bad_input(tmp_path):
    """Issue 47, item 5: a run that passed and whose report.html could not be written (here
    past the file size limit) exited 2, as if its input were bad. It exits 1, and its
    summary.json's verdict names the cause."""
    out = tmp_path / "run"
    args = ["generate", "--surface", "dome", "--pattern", "grid:3x3", "--no-deform"]
    res = run_cli_size_limited(200_000, *args, "--quiet", "--out", str(out))
    assert res.returncode == 1, res.stderr
    assert "Traceback" not in res.stderr and "bug" not in res.stderr
    summary = json.loads((out / "summary.json").read_text())
    verdict = summary["verdict"]
    assert summary["stop"] != "running" and verdict["outcome"] == "fell_short"
    assert "report.html" in verdict["message"] and "file size limit" in verdict["message"]
    assert not (out / "report.html").exists()
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]


def test_a_directory_in_use_by_a_running_generate_is_refused(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / ".rigidfold-run.lock").write_text(f"{os.getpid()}\n")  # a live process holds it
    for extra in ([], ["--overwrite"]):
        assert main(["generate", *SHORT_RUN, "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"in use by another rigidfold run (pid {os.getpid()})" in err[0]
    assert sorted(p.name for p in out.iterdir()) == [".rigidfold-run.lock"]
    # a lock whose process is gone is taken over, and released at the end
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    (out / ".rigidfold-run.lock").write_text(dead.stdout)
    assert main(["generate", *SHORT_RUN, "--out", str(out)]) == 1
    assert not (out / ".rigidfold-run.lock").exists() and (out / "summary.json").is_file()


def test_overwrite_never_removes_an_input_file(tmp_path, capsys):
    """An earlier solution used as the pattern of a new run into the same directory."""
    out = tmp_path / "run"
    assert main(["generate", *SHORT_RUN, "--out", str(out)]) == 1
    solution = out / "solutions" / "step_02_dof_03.fold"
    before = solution.read_bytes()
    capsys.readouterr()
    argv = ["generate", "--surface", "dome", "--pattern", str(solution), "--no-deform", "--quiet"]
    assert main([*argv, "--out", str(out), "--overwrite"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"--overwrite would remove the input file '{solution}'" in err[0]
    assert solution.read_bytes() == before and (out / "summary.json").is_file()


def test_generate_refuses_to_replace_its_input(tmp_path, capsys):
    """A surface read from a file generate would write (here DIR/summary.json) is refused,
    naming the input, before anything is written (issue 30)."""
    assert (
        main(["optimize", "--surface", "dome", "--pattern", "grid:3x3", "--out", str(tmp_path)])
        == 0
    )
    out = tmp_path / "run"
    out.mkdir()
    surface = out / "summary.json"
    before = (tmp_path / "solution.fold").read_bytes()
    surface.write_bytes(before)
    capsys.readouterr()
    argv = ["generate", "--surface", f"fold:{surface}", "--pattern", "grid:3x3", "--quiet"]
    for extra in ([], ["--overwrite"]):
        assert main([*argv, "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"would replace the input file '{surface}'" in err[0]
        assert sorted(p.name for p in out.iterdir()) == ["summary.json"]
        assert surface.read_bytes() == before


DEFORM_RUN = ["--surface", "dome", "--pattern", "grid:3x3", "--quiet", "--no-report"]
"""SHORT_RUN with Step 9: three solutions, DOF 5 -> 3, in a few seconds."""


def test_generate_states_both_verdicts_of_the_final_design(tmp_path, capsys, monkeypatch):
    """The large-deformation analysis and the folding motion: both verdicts of every solution
    in summary.json, the final design's in one line before the last; and, when they differ
    (the motion tracer given a budget of one step), the reason."""
    import rigidfold.pipeline.checks

    assert main(["generate", *DEFORM_RUN, "--check", "all", "--out", str(tmp_path / "a")]) == 1
    lines = capsys.readouterr().out.strip().splitlines()
    agree = "large deformation reached the plane, folding motion traced: they agree"
    assert lines[-2] == f"final design: {agree}"
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert [s["verdicts"]["line"] for s in summary["per_solution"]] == [agree] * 3
    assert summary["exports"][-1] == "final/step_02_dof_03.os.fold"
    assert (tmp_path / "a" / "final" / "step_02_dof_03.os.fold").is_file()

    real = rigidfold.pipeline.checks.verify
    tight = DEFAULTS.with_(path_max_steps=1)  # the tracer gives up after one step
    monkeypatch.setattr(
        rigidfold.pipeline.checks,
        "verify",
        lambda pattern, **kw: real(pattern, **{**kw, "path": None, "settings": tight}),
    )
    assert main(["generate", *DEFORM_RUN, "--out", str(tmp_path / "b")]) == 1
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-2].startswith(
        "final design: large deformation reached the plane, folding motion not traced: they "
        "differ, because with "
    )
    assert "DOF the folding path is not unique" in lines[-2]
    assert "folding motion not traced for the final design" in lines[-1]
    final = json.loads((tmp_path / "b" / "summary.json").read_text())["per_solution"][-1]
    assert final["verdicts"]["agreement"] == "differ"
    assert final["verdicts"]["line"] == lines[-2].removeprefix("final design: ")


# ------------------------------------------------- issue 30, item 20: --target-dof 0 and 50
def test_target_dof_0_saves_and_names_the_dof_0_shape(tmp_path, capsys):
    """``--target-dof 0``: the DOF-0 shape the run ends at is a solution, written and named
    as the final design (was: "passed" naming the DOF-1 file, the DOF-0 shape never saved).
    A DOF-0 design has no mechanism: no folding motion or Step 9 is asked of it, a note says
    so."""
    argv = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "grid:4x4"]
    argv += ["--target-dof", "0", "--no-deploy-check"]  # a rigid design: it cannot deploy
    code = main([*argv, "--no-deform", "--quiet", "--out", str(tmp_path)])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (
        code == 0
        and summary["final_dof"] == 0
        and summary["stop_reason"] == ("target DOF 0 reached")
    )
    final = summary["verdict"]["final_design"]
    assert final == summary["solutions"][-1] and final.endswith("_dof_00.fold")
    assert last.startswith("passed: ") and last.endswith(f"final design: {tmp_path / final}")
    assert "a DOF-0 design has no mechanism: it does not fold" in last
    assert read_fold(tmp_path / final).pattern.n_vertices == 16
    proc = run_cli("analyze", str(tmp_path / final))
    assert proc.returncode == 0 and "DOF: 0" in proc.stdout
    assert (tmp_path / "final" / Path(final).with_suffix(".obj").name).is_file()


def test_target_dof_at_or_above_the_initial_dof_says_so(tmp_path, capsys):
    """``--target-dof 50`` on a 9-DOF shape: the run says the initial DOF is already at or
    below the target (no crease was fixed), not only "the target DOF was reached"."""
    code = main(["generate", *SHORT_RUN, "--target-dof", "50", "--out", str(tmp_path)])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert code == 0
    assert "the initial DOF 5 is already at or below the target DOF 50" in last
    verdict = json.loads((tmp_path / "summary.json").read_text())["verdict"]
    assert any("already at or below the target DOF 50" in w for w in verdict["warnings"])


# ----------------------------------------- issue 30, item 21: Ctrl-C and SIGTERM in a solve
SIGNAL_IN_SOLVE = """
import os, signal, sys
# as in a terminal: a shell without job control starts background commands with SIGINT
# ignored, and Python keeps that (then Ctrl-C cannot reach the run at all)
signal.signal(signal.SIGINT, signal.default_int_handler)
from rigidfold.optimize import hessian
real = hessian.ClosedFormHessian.values
calls = []
def values(self, *args):  # IPOPT is running: its Hessian callback is being evaluated
    calls.append(1)
    if len(calls) == 3:
        os.kill(os.getpid(), getattr(signal, sys.argv[1]))
    return real(self, *args)
hessian.ClosedFormHessian.values = values
from rigidfold.cli.launch import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_during_an_ipopt_solve_is_an_interrupt(tmp_path, name):
    """Ctrl-C (SIGINT) or SIGTERM while IPOPT runs: CasADi catches the KeyboardInterrupt
    its callback raised and IPOPT ends as a failed solve ("NonIpopt_Exception_Thrown"), which
    was reported as "no developable polyhedron from the initial shape", exit 1. It is an
    interrupt: exit 130, one line, summary.json's stop "interrupted" (never "running")."""
    out = tmp_path / "run"
    argv = ["generate", "--surface", "dome", "--pattern", "grid:6x6", "--quiet", "--out", str(out)]
    proc = subprocess.run(
        [sys.executable, "-c", SIGNAL_IN_SOLVE, name, *argv],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"rigidfold: interrupted; 0 solutions, log.jsonl and summary.json are in {out}"
    ]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stop"] == "interrupted" and summary["stop_reason"] == "interrupted"
    assert summary["n_solutions"] == 0 and summary["verdict"]["final_design"] is None
    assert not (out / ".rigidfold-run.lock").exists()


def test_an_ipopt_solve_raises_keyboard_interrupt(monkeypatch):
    """In Python too: a SIGINT while IPOPT runs raises KeyboardInterrupt from ``solve``
    instead of returning a failed solve."""
    import signal

    from rigidfold.generate.specs import case_from_specs
    from rigidfold.optimize import hessian

    real, calls = hessian.ClosedFormHessian.values, []

    def values(self, *args):
        calls.append(1)
        if len(calls) == 3:
            os.kill(os.getpid(), signal.SIGINT)
        return real(self, *args)

    monkeypatch.setattr(hessian.ClosedFormHessian, "values", values)
    problem = case_from_specs("dome", "grid:5x5").problem()
    # as in a terminal (a process started in the background may have SIGINT ignored)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            problem.solve()
        assert len(calls) == 3  # stopped at once
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)


def test_sigterm_to_a_running_generate_exits_130(tmp_path):
    """A real SIGTERM to ``rigidfold generate`` on a large grid once its run has started
    (whatever it is doing then: building, solving, analysing): exit 130, one line, and any
    summary.json written says "interrupted"."""
    import signal
    import time

    out = tmp_path / "run"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rigidfold",
            "generate",
            "--surface",
            "dome",
            "--pattern",
            "grid:30x30",
            "--quiet",
            "--no-report",
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not (out / ".rigidfold-run.lock").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)
    proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:  # do not leave the process and its pipes behind
        proc.kill()
        proc.communicate()
        raise
    assert proc.returncode == 130, err
    assert len(err.strip().splitlines()) == 1 and "interrupted" in err
    summary = out / "summary.json"
    assert json.loads(summary.read_text())["stop"] == "interrupted"
