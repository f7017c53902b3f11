"""`rigidfold study` / `study-report` on damaged or foreign databases, two clients on one
database, a scheduler address that is not Dask, and a run whose Dask workers die (issue 17,
defects 5, 7, 8 and 10)."""

from __future__ import annotations

import os
import signal
import socket
import sqlite3
import subprocess
import sys
import threading
import time

import pytest

from conftest import main_code, run_cli
from rigidfold.study import STUDY_OPTIONS, Key, Store, StudyConfig

STUDY = ["--surfaces", "1", "--patterns", "1", "--criteria", "s", "--no-deform", "--quiet"]


def valid_database(path) -> None:
    """A study database of 60 runs of 5 attempts each, written by Store (no Dask)."""
    store = Store(path, StudyConfig().as_dict())
    attempt = {"fixed_added": [1, 2], "status": "converged", "locked": [], "outcome": "accepted"}
    for seed in range(60):
        run = {
            "stop": "target_reached",
            "status": "target DOF 1 reached",
            "n_lock": 1,
            "version": "v",
        }
        store.add(Key("bezier", seed, "1", "s"), run, [attempt | {"idx": i} for i in range(5)])
    store.close()


def zero_page(path, page: int) -> None:
    data = bytearray(path.read_bytes())
    data[page * 4096 : (page + 1) * 4096] = bytes(4096)
    path.write_bytes(bytes(data))


def by_sql(sql: str):
    def damage(path) -> None:
        con = sqlite3.connect(path)
        con.execute(sql)
        con.commit()
        con.close()

    return damage


DAMAGES = {
    "not sqlite": (lambda p: p.write_text("name,seed\nx,1\n" * 500), "damaged SQLite file"),
    "zeroed header": (lambda p: zero_page(p, 0), "damaged SQLite file"),
    "zeroed page": (lambda p: zero_page(p, 3), "damaged SQLite file"),
    "missing table": (by_sql("DROP TABLE attempts"), "no table 'attempts'"),
    "dropped column": (
        by_sql("ALTER TABLE runs DROP COLUMN n_lock"),
        "table 'runs' lacks column 'n_lock'",
    ),
    "text in a number": (by_sql("UPDATE runs SET n_lock = 'many'"), "runs.n_lock holds 'many'"),
    "corrupt config": (
        by_sql("UPDATE meta SET value = '{\"deform\": fa' WHERE key = 'config'"),
        "config is not a JSON object",
    ),
}


@pytest.mark.parametrize("kind", sorted(DAMAGES))
def test_damaged_databases_are_refused_in_one_line_untouched(tmp_path, kind):
    damage, needle = DAMAGES[kind]
    db = tmp_path / "d.sqlite"
    valid_database(db)
    damage(db)
    before = db.read_bytes()
    for args in (["study", *STUDY, "--db", str(db)], ["study-report", str(db)]):
        proc = run_cli(*args)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and needle in lines[0] and str(db) in lines[0], proc.stderr
        assert db.read_bytes() == before
        # no lock left; reading a WAL database leaves its (empty) -wal and -shm files
        assert {p.name for p in tmp_path.iterdir()} <= {"d.sqlite", "d.sqlite-wal", "d.sqlite-shm"}
        wal = tmp_path / "d.sqlite-wal"
        assert not wal.exists() or wal.stat().st_size == 0


def test_a_second_client_is_refused_and_a_dead_ones_lock_taken_over(tmp_path):
    db = tmp_path / "s.sqlite"
    config = StudyConfig(STUDY_OPTIONS.replace(deform=False)).as_dict()
    first = Store(db, config)
    with pytest.raises(ValueError, match=f"in use by another rigidfold study \\(pid {os.getpid()}"):
        Store(db, config)
    first.close()
    Store(db, config).close()  # released on close
    # a client in another process holds it: `study` is refused in one line, nothing written
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time\nfrom rigidfold.study import STUDY_OPTIONS, Store, StudyConfig\n"
            f"Store({str(db)!r}, StudyConfig(STUDY_OPTIONS.replace(deform=False)).as_dict())\n"
            "print('ready', flush=True)\ntime.sleep(300)",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "ready\n"
        before = db.read_bytes()
        proc = run_cli("study", *STUDY, "--db", str(db))
        assert proc.returncode == 2
        (line,) = proc.stderr.strip().splitlines()
        assert f"in use by another rigidfold study (pid {holder.pid} on" in line
        assert db.read_bytes() == before
        reader = Store(db, readonly=True)  # a report still reads it
        assert reader.done() == set()
        reader.close()
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        holder.stdout.close()
    assert (tmp_path / "s.sqlite.lock").exists()  # left by the killed client, taken over:
    store = Store(db, config)
    store.add(
        Key("bezier", 0, "1", "s"),
        {"stop": "zero_dof", "status": "DOF 0 reached", "version": "v"},
        [],
    )
    with pytest.raises(ValueError, match="already holds the run"):
        store.add(
            Key("bezier", 0, "1", "s"),
            {"stop": "zero_dof", "status": "DOF 0 reached", "version": "v"},
            [],
        )
    store.close()
    assert not (tmp_path / "s.sqlite.lock").exists()


def test_a_scheduler_that_is_not_dask_is_refused_within_the_timeout(tmp_path):
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    accepted: list[socket.socket] = []

    def accept() -> None:  # accepts and says nothing, as a foreign service would
        while True:
            try:
                accepted.append(server.accept()[0])
            except OSError:
                return

    threading.Thread(target=accept, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    t0 = time.perf_counter()
    try:
        proc = run_cli(
            "study", *STUDY, "--db", str(tmp_path / "c.sqlite"), "--scheduler", address,
            "--connect-timeout", "3", timeout=120,
        )  # fmt: skip
    finally:
        server.close()
        for conn in accepted:
            conn.close()
    assert time.perf_counter() - t0 < 60
    assert proc.returncode == 2
    (line,) = proc.stderr.strip().splitlines()
    assert f"cannot reach the Dask scheduler at {address!r} within 3 s" in line
    proc = run_cli("study", *STUDY, "--db", str(tmp_path / "c.sqlite"), "--connect-timeout", "0")
    assert proc.returncode == 2 and "--connect-timeout must be a finite number" in proc.stderr


def test_a_dask_scheduler_is_reached_through_the_handshake():
    from dask.distributed import LocalCluster

    from rigidfold.study.runner import connect

    with LocalCluster(
        n_workers=0,
        processes=False,
        protocol="tcp://",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # 8787 may be taken
    ) as cluster:
        client = connect(cluster.scheduler_address, 10)
        assert client.scheduler_info()["address"] == cluster.scheduler_address
        client.close()


# ------------------------------------------------------------ defect 7: a worker dies on a run
def test_a_run_whose_worker_dies_is_recorded_as_failed_and_the_others_go_on(
    tmp_path, monkeypatch, capsys
):
    """A real LocalCluster whose worker process ends (os._exit) when it runs seed 1: Dask gives
    up on that run (KilledWorker; here after the first death, by default after the fourth),
    the run is stored as failed with the reason, seed 0 is computed, the command is recorded,
    and the study exits 1 with one summary line; study-report lists the failed run.

    Two runs on two workers: each run has a worker of its own (Dask counts a death against
    every run its worker held, so a run queued behind seed 1 would be charged too)."""
    # distributed imported first: leaving the dask.config.set block below would drop its
    # configuration defaults if it were first imported inside (later clusters then fail)
    import dask
    import distributed  # noqa: F401

    from rigidfold.study import runner

    real_run_one = runner.run_one

    def dies_on_seed_1(key, config):  # pickled by value: the workers run this
        if key.seed == 1:
            os._exit(3)
        return real_run_one(key, config)

    monkeypatch.setattr(runner, "run_one", dies_on_seed_1)
    db = tmp_path / "s.sqlite"
    args = ["study", "--surfaces", "2", "--patterns", "1", "--criteria", "s", "--no-deform"]
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        code = main_code([*args, "--quiet", "--workers", "2", "--db", str(db)])
    out, err = capsys.readouterr()
    assert code == 1, err
    assert "2 runs done, 0 already in" in out
    assert "Traceback" not in err
    assert err.strip().splitlines() == [
        f"rigidfold: 1 of 2 runs failed and are recorded as errors in {db} (rigidfold "
        "study-report lists them): 1 x the Dask worker running it died 1 time (KilledWorker: "
        "killed, out of memory, or a crash in native code)"
    ]
    store = Store(db, readonly=True)
    runs = {r.seed: r for r in store.runs()}
    assert sorted(runs) == [0, 1]
    assert runs[0].status == "target DOF 1 reached" and runs[0].n_lock is not None
    assert runs[1].stop is None and runs[1].status == (
        "error: the Dask worker running it died 1 time (KilledWorker: killed, out of memory, "
        "or a crash in native code)"
    )
    assert runs[1].worker is not None and runs[1].worker.startswith("tcp://")
    assert runs[1].n_lock is None
    [invocation] = store.invocations()
    assert (invocation["ran"], invocation["outcome"]) == (2, "completed, 1 failed")
    store.close()

    # resumed: the failed run is not tried again, and nothing fails in this command
    monkeypatch.setattr(runner, "run_one", real_run_one)
    assert main_code([*args, "--quiet", "--db", str(db)]) == 0
    assert "0 runs done, 2 already in" in capsys.readouterr().out

    assert main_code(["study-report", str(db)]) == 0
    report = capsys.readouterr().out
    assert "### Runs that failed" in report
    assert (
        "| bezier | 1 | 1 | s | False | the Dask worker running it died 1 time (KilledWorker: "
        "killed, out of memory, or a crash in native code) |" in report
    )
    assert "| S | 1 |" in report  # Table 5 counts the one run that finished
    assert "| completed, 1 failed |" in report


def test_a_run_that_raises_unexpectedly_is_recorded_as_failed_and_the_others_go_on(
    tmp_path, monkeypatch, capsys
):
    """A defect in one run (an exception other than bad input) does not end the study in a
    traceback: the run is stored as failed with the exception's type and message, the other
    runs are computed, and the command exits 1 with one summary line."""
    from rigidfold.study import runner

    real_run_one = runner.run_one

    def fails_on_seed_1(key, config):  # pickled by value: the worker runs this
        if key.seed == 1:
            raise RuntimeError("singular matrix\nsecond line")
        return real_run_one(key, config)

    monkeypatch.setattr(runner, "run_one", fails_on_seed_1)
    db = tmp_path / "s.sqlite"
    args = ["study", "--surfaces", "2", "--patterns", "1", "--criteria", "s", "--no-deform"]
    code = main_code([*args, "--quiet", "--workers", "1", "--db", str(db)])
    out, err = capsys.readouterr()
    assert code == 1, err
    assert "2 runs done, 0 already in" in out and "Traceback" not in err
    message = (
        "unexpected RuntimeError: singular matrix (a defect: please report it with the run's key)"
    )
    assert err.strip().splitlines() == [
        f"rigidfold: 1 of 2 runs failed and are recorded as errors in {db} (rigidfold "
        f"study-report lists them): 1 x {message}"
    ]
    store = Store(db, readonly=True)
    runs = {r.seed: r for r in store.runs()}
    assert runs[0].status == "target DOF 1 reached"
    assert runs[1].status == "error: " + message
    store.close()


def _study_args(db) -> list[str]:
    return [
        "study", "--surfaces", "1", "--patterns", "1", "--criteria", "s", "--no-deform",
        "--quiet", "--db", str(db),
    ]  # fmt: skip


def test_workers_are_bounded_by_the_machine_before_the_database_is_made(
    tmp_path, monkeypatch, capsys
):
    """Issue 30, item 6: more local workers than CPUs (or than the open-file limit allows)
    are refused in one line naming the limit, by the library and the CLI, and no file made."""
    from rigidfold.study import runner, session

    db = tmp_path / "w.sqlite"
    monkeypatch.setattr(runner, "usable_cpus", lambda: 3)
    monkeypatch.setattr(runner, "open_file_limit", lambda: None)
    assert runner.max_workers() == (3, "the 3 CPUs this process may use")
    with pytest.raises(ValueError, match=r"^--workers 4 is more .* at most 3 local workers"):
        session.run_study_command([Key("bezier", 0, "1", "s")], db, StudyConfig(), workers=4)
    code = main_code([*_study_args(db), "--workers", "10000"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "--workers 10000 is more than this machine runs: at most 3" in err
    # the open-file limit: (1024 - 256) // 16 = 48 workers
    monkeypatch.setattr(runner, "usable_cpus", lambda: 1000)
    monkeypatch.setattr(runner, "open_file_limit", lambda: 1024)
    limit, reason = runner.max_workers()
    assert limit == 48 and "open-file limit of 1024" in reason
    with pytest.raises(ValueError, match="at most 48 local workers"):
        runner.check_workers(49)
    runner.check_workers(48)
    # the default is allowed on a one-CPU machine
    monkeypatch.setattr(runner, "usable_cpus", lambda: 1)
    runner.check_workers(session.STUDY_DEFAULTS.workers)
    assert list(tmp_path.iterdir()) == []


def test_the_real_limits_are_positive_and_used_by_run_study(tmp_path):
    from rigidfold.study import runner

    limit, _ = runner.max_workers()
    assert limit >= 2
    store = Store(tmp_path / "r.sqlite", StudyConfig().as_dict())
    try:
        with pytest.raises(ValueError, match=f"at most {limit} local workers"):
            runner.run_study([Key("bezier", 0, "1", "s")], store, StudyConfig(), workers=limit + 1)
        with pytest.raises(ValueError, match="--connect-timeout must be a finite"):
            runner.run_study(
                [Key("bezier", 0, "1", "s")], store, StudyConfig(), connect_timeout=float("inf")
            )
    finally:
        store.close()


@pytest.mark.parametrize("value", ["inf", "nan", "-1", "0", "1e400"])
def test_connect_timeout_must_be_finite_and_positive(tmp_path, capsys, value):
    """Issue 30, item 13: ``--connect-timeout inf`` is one line (exit 2), no database made."""
    db = tmp_path / "t.sqlite"
    code = main_code([*_study_args(db), f"--connect-timeout={value}"])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert err.startswith("rigidfold: error: --connect-timeout must be a finite number")
    assert err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["run#2.sqlite", "a?mode=rwc.sqlite", "p%41 q.sqlite", "x#"])
def test_a_database_named_with_uri_characters_resumes_without_stray_files(tmp_path, name):
    """Issue 30, item 7: the read-only connection (the check of an existing database, and
    reports) opens that very file, not the name cut at ``#`` or ``?`` nor ``%XX`` decoded."""
    db = tmp_path / name
    key = Key("bezier", 0, "1", "s")
    config = StudyConfig().as_dict()
    store = Store(db, config)
    store.add(
        key,
        {"stop": "target_reached", "status": "target DOF 1 reached", "n_lock": 2, "version": "t"},
        [],
    )
    store.close()
    store = Store(db, config)  # resumed: the existing file is checked read-only first
    assert store.done() == {key}
    store.close()
    report = Store(db, readonly=True)
    assert [r.n_lock for r in report.runs()] == [2]
    report.close()
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(n for n in (name, f"{name}-wal", f"{name}-shm") if n in left)
    assert name in left


def test_report_figures_of_patterns_with_directories_are_written(tmp_path, capsys):
    """Issue 30, item 8: a pattern given as ``sub/t.fold`` (or ``grid:3x3``) names a figure
    in DIR (a slug, unique), linked from results.md."""
    from rigidfold.study.markdown import figure_name
    from rigidfold.study.store import RUN_FIELDS

    db = tmp_path / "s.sqlite"
    store = Store(db, StudyConfig().as_dict())
    numbers = {
        f: 1 for f in RUN_FIELDS if f.startswith(("n_", "mean_f", "time_", "initial", "final"))
    }
    for i, pattern in enumerate(["sub/t.fold", "sub:t.fold", "grid:3x3", "../up.fold"]):
        for seed in range(2):
            store.add(
                Key("bezier", seed, pattern, "s"),
                numbers
                | {
                    "stop": "target_reached",
                    "status": "target DOF 1 reached",
                    "n_lock": seed + i,
                    "version": "t",
                },
                [],
            )
    store.close()
    out = tmp_path / "rep"
    code = main_code(["study-report", str(db), "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "n_lock_pattern_.._up.fold.png",
        "n_lock_pattern_grid_3x3.png",
        "n_lock_pattern_sub_t.fold.png",
        "n_lock_pattern_sub_t.fold_2.png",
        "results.md",
    ]
    text = (out / "results.md").read_text()
    for png in names[:-1]:
        assert f"]({png})" in text
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert figure_name("?#", set()) == "figure.png"


def test_one_lock_whatever_the_path_to_the_database(tmp_path):
    """Issue 47, item 7: the lock is named from the database file itself, so a symbolic link
    to it (or to its directory, or to a database yet to be made) takes the same lock."""
    config = StudyConfig(STUDY_OPTIONS.replace(deform=False)).as_dict()
    real_dir = tmp_path / "real"
    real_dir.mkdir()
    db = real_dir / "s.sqlite"
    link = tmp_path / "link.sqlite"
    link.symlink_to(db)  # dangling: the first study makes the database through it
    dir_link = tmp_path / "dir_link"
    dir_link.symlink_to(real_dir, target_is_directory=True)
    first = Store(link, config)
    assert db.is_file() and (real_dir / "s.sqlite.lock").exists()
    assert not (tmp_path / "link.sqlite.lock").exists()
    for other in (db, link, dir_link / "s.sqlite"):
        with pytest.raises(ValueError, match="in use by another rigidfold study"):
            Store(other, config)
    first.close()
    assert not (real_dir / "s.sqlite.lock").exists()
    second = Store(dir_link / "s.sqlite", config)  # released: taken through another path
    with pytest.raises(ValueError, match=f"'{link}' is in use by another rigidfold study"):
        Store(link, config)
    second.close()
