"""`rigidfold study` / `study-report`: Dask runs, SQLite store, SIGKILL and resume, bad input."""

from __future__ import annotations

import dataclasses
import hashlib
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rigidfold.generate import Stop
from rigidfold.study import STUDY_OPTIONS, Key, Store, StudyConfig, plan, preset
from rigidfold.study.markdown import markdown, write_report
from rigidfold.study.tables import (
    FOLD_BINS,
    costs,
    criterion_summary,
    dof_steps,
    lock_causes,
    locked_fold_angles,
    locks_by_stage,
    paired_comparisons,
    tables_5_6,
)

STUDY = ["--surfaces", "3", "--patterns", "1", "--criteria", "shat,s", "--no-deform"]


def study_cmd(db, *extra: str) -> list[str]:
    return [sys.executable, "-m", "rigidfold.cli", "study", *STUDY, "--db", str(db), *extra]


def run(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(args, capture_output=True, text=True, check=False, timeout=600)


def n_runs(db) -> int:
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=5) as con:
            return con.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    except sqlite3.Error:
        return 0


def comparable(rows: list) -> list[dict]:
    """Rows (dicts, or stored runs) without the timings and the worker's name (which differ
    between runs)."""
    return [
        {
            k: v
            for k, v in (r if isinstance(r, dict) else dataclasses.asdict(r)).items()
            if not k.startswith("time") and k != "worker"
        }
        for r in rows
    ]


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    db = tmp_path_factory.mktemp("study") / "a.sqlite"
    proc = run(study_cmd(db, "--workers", "2", "--quiet"))
    assert proc.returncode == 0, proc.stderr
    assert "6 runs done" in proc.stdout
    return db


def test_study_stores_every_run_once(uninterrupted):
    store = Store(uninterrupted, readonly=True)
    runs = store.runs()
    assert len(runs) == 6
    assert {(r.seed, r.criterion) for r in runs} == {
        (s, c) for s in range(3) for c in ("shat", "s")
    }
    for r in runs:
        assert r.status == "target DOF 1 reached" and r.final_dof == 1
        assert r.stop is Stop.TARGET_REACHED
        assert r.n_reduce == 20 and r.n_solves >= 21
    # one attempts row per solve of (6)
    assert store.count_attempts() == sum(r.n_solves for r in runs)


def test_rerun_skips_finished_runs(uninterrupted):
    proc = run(study_cmd(uninterrupted, "--quiet"))
    assert proc.returncode == 0 and "0 runs done, 6 already" in proc.stdout
    assert n_runs(uninterrupted) == 6


def test_sigkill_mid_study_then_resume_gives_the_same_tables(uninterrupted, tmp_path):
    db = tmp_path / "killed.sqlite"
    proc = subprocess.Popen(
        study_cmd(db, "--workers", "2", "--quiet"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # its own process group: client and Dask workers
    )
    deadline = time.monotonic() + 300
    while n_runs(db) < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
    assert proc.poll() is None, "the study finished before it could be killed"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    killed_at = n_runs(db)
    assert 2 <= killed_at < 6
    resumed = run(study_cmd(db, "--workers", "2", "--quiet"))
    assert resumed.returncode == 0, resumed.stderr
    assert f"{6 - killed_at} runs done, {killed_at} already" in resumed.stdout
    a, b = Store(uninterrupted, readonly=True), Store(db, readonly=True)
    assert comparable(b.runs()) == comparable(a.runs())
    assert b.count_attempts() == a.count_attempts()
    assert comparable(tables_5_6(b)) == comparable(tables_5_6(a))


def test_report_tables_and_figures(uninterrupted, tmp_path):
    store = Store(uninterrupted, readonly=True)
    rows = tables_5_6(store)
    assert [(r["pattern"], r["criterion"], r["n"]) for r in rows] == [
        ("1", "s", 3),
        ("1", "shat", 3),
    ]
    assert rows[1]["paper"] == (20.00, 0.06, 0.01, 1.38e-9)
    text = markdown(store)
    assert "Table 5" in text and "| S-hat | 3 | 20.00 ± 0.00 |" in text
    path = write_report(store, tmp_path / "report")
    assert path.read_text().startswith("# rigidfold study report")
    png = tmp_path / "report" / "n_lock_pattern_1.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_report_pairs_costs_and_commands(uninterrupted):
    store = Store(uninterrupted, readonly=True)
    runs = {(r.criterion, r.seed): r.n_lock for r in store.runs("bezier")}
    (pair,) = paired_comparisons(store)  # only S-hat and S ran
    d = [runs[("shat", k)] - runs[("s", k)] for k in range(3)]
    assert (pair["a"], pair["b"], pair["n"]) == ("shat", "s", 3)
    assert pair["mean_diff"] == pytest.approx(sum(d) / 3)
    assert pair["less"] + pair["equal"] + pair["more"] == 3
    assert pair["less"] == sum(x < 0 for x in d) and 0 <= pair["p_value"] <= 1
    cost = {c["criterion"]: c for c in costs(store)}
    n_attempts = store.count_attempts()
    assert sum(c["solves_per_run"] * c["runs"] for c in cost.values()) == n_attempts
    assert all(c["iterations_per_solve"] > 0 and c["total_cpu_s"] > 0 for c in cost.values())
    (inv,) = [r for r in store.invocations() if r["ran"] == 6]  # the fixture's command
    assert inv["argv"][:2] == ["rigidfold", "study"] and inv["workers"] == 2
    assert (inv["skipped"], inv["total"], inv["outcome"]) == (0, 6, "completed")
    text = markdown(store)
    assert "### Ordering of N_lock" in text and "| 1 | S-hat - S | 3 |" in text
    assert "### Cost" in text and "`rigidfold study --surfaces 3" in text


def test_plan_and_store_units(tmp_path):
    keys = plan(["1", "2"], ["shat"], 2, first_seed=5)
    assert [(k.seed, k.pattern) for k in keys] == [(5, "1"), (5, "2"), (6, "1"), (6, "2")]
    twist = str(Path(__file__).parent / "data" / "fold_examples" / "squaretwist.fold")
    assert [k.pattern for k in plan(["grid:5x4", twist], ["s"], 1)] == ["grid:5x4", twist]
    with pytest.raises(ValueError, match="a grid pattern is grid:NXxNY"):
        plan(["grid:5"], ["s"], 1)
    store = Store(tmp_path / "u.sqlite", StudyConfig().as_dict())
    key = Key("bezier", 5, "1", "shat")
    store.add(key, {"stop": "zero_dof", "status": "DOF 0 reached", "version": "v"}, [])
    assert store.done() == {key}
    with pytest.raises(ValueError, match="already holds the run"):
        store.add(
            key, {"stop": "zero_dof", "status": "DOF 0 reached", "version": "v"}, []
        )  # never counted twice
    assert len(store.runs()) == 1


def test_presets_can_be_combined_longest_runs_first():
    keys = preset("dome,hp")
    assert {(k.study, k.symmetric) for k in keys} == {
        (s, m) for s in ("dome", "hp") for m in (True, False)
    }
    assert [k.symmetric for k in keys] == [False, False, True, True]
    assert preset("hp") == sorted(preset("hp"), key=lambda k: k.symmetric)


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--criteria", "shat,best"], "unknown criterion 'best'"),
        (["--patterns", "7"], "unknown pattern '7'"),
        (["--preset", "moon"], "unknown preset 'moon'"),
        (["--preset", "dome,moon"], "unknown preset 'moon'"),
        (["--surfaces", "0"], "--surfaces must be >= 1"),
        (["--workers", "0"], "--workers must be >= 1"),
    ],
)
def test_bad_input_is_one_line_and_touches_nothing(tmp_path, extra, needle):
    db = tmp_path / "x.sqlite"
    proc = run([sys.executable, "-m", "rigidfold.cli", "study", "--db", str(db), *extra])
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and needle in proc.stderr
    assert not db.exists()


def test_other_configuration_is_refused_untouched(uninterrupted):
    digest = hashlib.sha256(uninterrupted.read_bytes()).hexdigest()
    proc = run(
        [
            sys.executable,
            "-m",
            "rigidfold.cli",
            "study",
            "--surfaces",
            "3",
            "--patterns",
            "1",
            "--db",
            str(uninterrupted),
        ]  # Steps 8-9 on: another configuration
    )
    assert proc.returncode == 2 and "another configuration" in proc.stderr
    assert hashlib.sha256(uninterrupted.read_bytes()).hexdigest() == digest
    other_hessian = [*STUDY, "--hessian", "casadi", "--db", str(uninterrupted)]
    proc = run([sys.executable, "-m", "rigidfold.cli", "study", *other_hessian])
    assert proc.returncode == 2 and "settings.ipopt_hessian" in proc.stderr
    assert hashlib.sha256(uninterrupted.read_bytes()).hexdigest() == digest


def test_unwritable_database_and_missing_report(tmp_path):
    proc = run(
        [sys.executable, "-m", "rigidfold.cli", "study", "--db", str(tmp_path / "no" / "x.db")]
    )
    assert proc.returncode == 2 and "no such directory" in proc.stderr
    proc = run([sys.executable, "-m", "rigidfold.cli", "study-report", str(tmp_path / "n.db")])
    assert proc.returncode == 2 and "no study database" in proc.stderr


def test_progress_prints_plain_lines_when_stderr_is_not_a_terminal(capsys):
    from rigidfold.cli.progress import StudyProgress

    bar = StudyProgress(enabled=True, log_every=3600.0)
    bar.plain = True  # as under pytest's captured stderr, a log file or nohup
    rows = [
        {"status": "target DOF 1 reached"},
        {"status": "error: ValueError: x", "error": "ValueError: x"},
        {},
    ]
    for finished, row in enumerate(rows, start=4):  # 3 runs were already in the database
        bar.update(bool(row.get("error")), finished, 6)
    lines = capsys.readouterr().err.splitlines()
    # the first run prints, the second is within log_every, the last run always prints
    assert len(lines) == 2
    assert lines[0].startswith("study 4/6  failures 0")
    assert lines[1].startswith("study 6/6  failures 1")
    assert "runs/min" in lines[1] and "ETA" in lines[1]


def test_report_of_several_databases(uninterrupted, tmp_path):
    import shutil

    other = tmp_path / "b.sqlite"
    shutil.copy(uninterrupted, other)
    stores = [Store(uninterrupted, readonly=True), Store(other, readonly=True)]
    path = write_report(stores, tmp_path / "both")
    text = path.read_text()
    assert f"## {uninterrupted.name}" in text and "## b.sqlite" in text
    assert text.count("### Crease pattern 1 (paper's Table 5)") == 2
    assert "Steps 8-9 off" in text
    for stem in (uninterrupted.stem, "b"):
        png = tmp_path / "both" / f"{stem}_n_lock_pattern_1.png"
        assert png.is_file() and f"]({png.name})" in text


def _without_setting(config: dict, name: str) -> dict:
    """A study configuration as a rigidfold without setting ``name`` wrote it."""
    settings = {k: v for k, v in config["settings"].items() if k != name}
    return {**config, "settings": settings}


def test_settings_added_later_at_their_default_are_compatible():
    from rigidfold.config import DEFAULTS
    from rigidfold.study.store import config_differences

    current = StudyConfig().as_dict()
    older = _without_setting(current, "path_step")  # written before it existed
    assert config_differences(older, current) == []
    changed = StudyConfig(settings=DEFAULTS.with_(path_step=0.5)).as_dict()
    assert config_differences(older, changed) == ["settings.path_step"]
    assert config_differences(current, older) == ["settings.path_step"]  # one removed
    deform = StudyConfig(STUDY_OPTIONS.replace(deform=True)).as_dict()
    assert config_differences(current, deform) == ["deform"]
    tighter = StudyConfig(settings=DEFAULTS.with_(f_tol=1e-9)).as_dict()
    assert config_differences(current, tighter) == ["settings.f_tol"]


def test_locks_by_stage_adds_up_to_n_lock(uninterrupted):
    store = Store(uninterrupted, readonly=True)
    stages = {r["criterion"]: r for r in locks_by_stage(store)}
    for row in tables_5_6(store):
        st = stages[row["criterion"]]
        assert st["runs"] == row["n"] == 3
        assert sum(st["per_stage"]) == pytest.approx(row["n_lock"])
    assert "### Where the locks happen" in markdown(store)


def test_dof_steps_add_up_to_the_dof_reduced(uninterrupted):
    """Every accepted fix is one step; the signed steps sum to the DOF reduced per run."""
    store = Store(uninterrupted, readonly=True)
    steps = {r["criterion"]: r for r in dof_steps(store)}
    for row in tables_5_6(store):
        st = steps[row["criterion"]]
        assert st["runs"] == row["n"] == 3
        runs = [r for r in store.runs("bezier") if r.criterion == row["criterion"]]
        accepted_fixes = np.mean([r.n_solutions - 1 for r in runs])
        assert sum(st["per_kind"].values()) == pytest.approx(accepted_fixes)
        assert st["per_kind"]["-1"] >= 0
    assert "### How fixing a crease changes the DOF" in markdown(store)


def test_readonly_store_takes_no_configuration(uninterrupted, tmp_path):
    with pytest.raises(ValueError, match="no configuration"):
        Store(uninterrupted, StudyConfig().as_dict(), readonly=True)
    with pytest.raises(ValueError, match="no study database"):
        Store(tmp_path / "none.sqlite", readonly=True)
    assert not (tmp_path / "none.sqlite").exists()


def test_locked_fold_angles_and_lock_causes(uninterrupted):
    """Every lock of the study logs its creases' fold angles and its cause; without look-ahead
    the forecast at the shape before predicted the demo's locks (nearly flat creases)."""
    store = Store(uninterrupted, readonly=True)
    n_lock = {r["criterion"]: r["n_lock"] * r["n"] for r in tables_5_6(store)}
    angles = {r["criterion"]: r for r in locked_fold_angles(store)}
    causes = {r["criterion"]: r for r in lock_causes(store)}
    assert n_lock["shat"] >= 1  # seed 1, the demo, locks
    for crit, locks in n_lock.items():
        if not locks:
            continue
        assert angles[crit]["locks"] == causes[crit]["locks"] == locks
        assert sum(angles[crit]["bins"]) == angles[crit]["creases"] >= locks
        assert len(angles[crit]["bins"]) == len(FOLD_BINS) + 1
        assert causes[crit]["causes"]["unknown"] == 0
    assert causes["shat"]["causes"]["predicted"] >= 1
    assert angles["shat"]["median_deg"] < 1.0
    summary = {r["criterion"]: r for r in criterion_summary(store)}
    assert summary["shat"]["n_lock"] == pytest.approx(n_lock["shat"] / 3)
    assert summary["shat"]["skipped_per_run"] == 0 and summary["shat"]["selection_s"] > 0
    text = markdown(store)
    for head in ("Summary per criterion", "Fold angles of the locked creases", "Why the locks"):
        assert f"### {head}" in text
    assert "look-ahead off" in text


def test_lookahead_study_has_its_own_database(uninterrupted, tmp_path):
    digest = hashlib.sha256(uninterrupted.read_bytes()).hexdigest()
    proc = run(study_cmd(uninterrupted, "--lookahead"))
    assert proc.returncode == 2 and "differs in: lookahead" in proc.stderr
    assert hashlib.sha256(uninterrupted.read_bytes()).hexdigest() == digest
    db = tmp_path / "lookahead.sqlite"
    one = ["--surfaces", "1", "--first-seed", "1", "--patterns", "1", "--criteria", "shat"]
    args = ["rigidfold.cli", "study", *one, "--no-deform", "--lookahead", "--workers", "1"]
    proc = run([sys.executable, "-m", *args, "--quiet", "--db", str(db)])
    assert proc.returncode == 0, proc.stderr
    store = Store(db, readonly=True)
    assert store.config()["lookahead"] is True
    (row,) = criterion_summary(store)
    assert row["n_lock"] == 0 and row["n_reduce"] == 20 and row["skipped_per_run"] >= 3
    assert row["groups_per_run"] == 0  # no candidate failed: no group was needed
    assert "look-ahead on" in markdown(store)


def test_report_figures_never_follow_a_link(uninterrupted, tmp_path):
    outside = tmp_path / "outside.png"
    outside.write_bytes(b"keep")
    out = tmp_path / "rep"
    out.mkdir()
    (out / "n_lock_pattern_1.png").symlink_to(outside)
    write_report(Store(uninterrupted, readonly=True), out)
    assert outside.read_bytes() == b"keep"
    png = out / "n_lock_pattern_1.png"
    assert not png.is_symlink() and png.read_bytes().startswith(b"\x89PNG")


def test_generate_progress_shows_the_last_step_and_an_eta(capsys):
    from types import SimpleNamespace

    from rigidfold.cli.progress import GenerateProgress

    bar = GenerateProgress(enabled=True, target=1, log_every=3600.0)
    bar.plain = True
    run = SimpleNamespace(initial_dof=11, n_reduce=0, lowest_dof=11, n_lock=0, n_exceed=0, n_path=0)
    step = SimpleNamespace(solve_time=0.25, analysis_time=0.125, path_time=0.5)
    bar.update(run, step)  # the first line prints
    run.n_reduce, run.lowest_dof, run.n_lock = 4, 7, 1
    bar.update(run, step)  # within log_every: silent
    done, total, text = bar.describe(run, 120.0)
    assert (done, total) == (4, 10)
    assert "ETA 3.0 min" in text  # 6 DOF to go at 0.5 min each
    run.n_reduce, run.lowest_dof = 10, 1
    bar.update(run, step)  # the last line always prints
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("generate 0/10  DOF 11  lock 0  exceed 0  path 0")
    assert "ETA ?" in lines[0]
    assert lines[1].startswith("generate 10/10  DOF 1  lock 1")
    assert "last step: solve 0.25 s, analysis 0.12 s, path 0.50 s" in lines[1]
