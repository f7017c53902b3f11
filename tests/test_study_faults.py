"""`rigidfold study` when its database cannot be written, and `study-report` on a database it
must not touch (issue 30, items 11 and 18): a full disk stops the study in one line with the
runs stored before kept; a report makes no -wal or -shm file and reads a database on a
read-only file system."""

from __future__ import annotations

import os
import shutil
import sqlite3
import subprocess
import sys

import pytest

from conftest import main_code, run_cli
from rigidfold.study import Key, Store, StoreWriteError, StudyConfig
from rigidfold.study.store import RUN_FIELDS

STUDY = ["study", "--patterns", "1", "--criteria", "s", "--no-deform", "--quiet"]


def fake_run(key, config):
    """A run computed in no time, whose 40 attempts take several database pages."""
    row = {f: 1 for f in RUN_FIELDS if f not in ("status", "stop", "version", "worker", "numerics")}
    from rigidfold.runtime.numerics import numeric_environment

    row |= {
        "stop": "target_reached",
        "status": "target DOF 1 reached",
        "version": "t",
        "numerics": numeric_environment().key,
    }
    attempt = {"fixed_added": list(range(100)), "status": "converged", "locked": list(range(100))}
    return key, row, [attempt | {"idx": i, "outcome": "accepted", "dof": 40 - i} for i in range(40)]


def test_a_full_disk_stops_the_study_in_one_line_and_keeps_the_runs(tmp_path, monkeypatch, capsys):
    """Issue 30, item 11: the second run's write fails as on a full disk (SQLite's own
    SQLITE_FULL: the database may not grow by a page); before, a sqlite3.OperationalError
    traceback. Now: exit 2, one line naming the database, the first run kept; the same
    command then resumes and completes."""
    from rigidfold.study import runner

    monkeypatch.setattr(runner, "run_one", fake_run)  # pickled by value: the worker runs it
    real_add = Store.add
    calls = []

    def add_on_a_full_disk(self, key, run, attempts):
        calls.append(key)
        if len(calls) == 2:  # the disk fills up: not one page more
            pages = self.db.execute("PRAGMA page_count").fetchone()[0]
            self.db.execute(f"PRAGMA max_page_count = {pages}")
        return real_add(self, key, run, attempts)

    monkeypatch.setattr(Store, "add", add_on_a_full_disk)
    db = tmp_path / "s.sqlite"
    args = [*STUDY, "--surfaces", "3", "--workers", "1", "--db", str(db)]
    code = main_code(args)
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err, err
    assert err.splitlines() == [
        f"rigidfold: error: cannot write to the study database {str(db)!r}: database or disk "
        "is full; the 1 run stored before is kept: free disk space, then run the same "
        "command to resume"
    ]
    store = Store(db, readonly=True)
    assert [r.seed for r in store.runs()] == [calls[0].seed]  # whole, with its attempts
    assert store.count_attempts() == 40
    store.close()
    assert not (tmp_path / "s.sqlite.lock").exists()  # released

    monkeypatch.setattr(Store, "add", real_add)  # space freed: the same command resumes
    assert main_code(args) == 0
    assert "2 runs done, 1 already in" in capsys.readouterr().out
    store = Store(db, readonly=True)
    assert len(store.runs()) == 3 and store.count_attempts() == 120
    outcomes = [r["outcome"] for r in store.invocations()]
    assert sorted(outcomes) == ["completed", "stopped: the database could not be written"]
    store.close()


def test_a_failed_write_is_rolled_back_whole(tmp_path):
    store = Store(tmp_path / "s.sqlite", StudyConfig().as_dict())
    _, run, attempts = fake_run(Key("bezier", 0, "1", "s"), {})
    store.add(Key("bezier", 0, "1", "s"), run, attempts)
    pages = store.db.execute("PRAGMA page_count").fetchone()[0]
    store.db.execute(f"PRAGMA max_page_count = {pages}")
    with pytest.raises(
        StoreWriteError, match="database or disk is full; the 1 run stored before is kept"
    ):
        store.add(Key("bezier", 1, "1", "s"), run, attempts)
    with pytest.raises(StoreWriteError, match="free disk space"):
        store.add_invocation(
            argv=["x" * 100_000],  # more than the free space of its pages
            **dict.fromkeys(("started", "scheduler", "outcome", "version"), "x"),
            **dict.fromkeys(("workers", "ran", "skipped", "total", "wall_s"), 1),
        )
    assert len(store.runs()) == 1 and store.count_attempts() == 40
    store.close()


def test_a_full_disk_before_the_study_names_the_lock_file(tmp_path, monkeypatch):
    """On a disk already full the lock file is made but its pid cannot be written: before,
    "cannot write the output: No space left on device" (as if stdout had failed)."""
    import errno

    from rigidfold.study import lock

    def full(fd, length):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(lock.os, "ftruncate", full)
    db = tmp_path / "s.sqlite"
    with pytest.raises(ValueError, match=r"cannot write its lock file .*: No space left on dev"):
        Store(db, StudyConfig().as_dict())
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------- item 18: reports leave the files alone
def study_database(path) -> None:
    """A finished study of 4 runs, closed (no -wal, no -shm, no lock left)."""
    store = Store(path, StudyConfig().as_dict())
    for seed in range(4):
        store.add(*fake_run(Key("bezier", seed, "1", "s"), {}))
    store.close()


def test_study_report_makes_no_wal_or_shm_file(tmp_path, capsys):
    """Issue 30, item 18: reading a WAL database made its -wal and -shm files, and left
    them."""
    db = tmp_path / "s.sqlite"
    study_database(db)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.sqlite"]
    before = db.read_bytes()
    assert main_code(["study-report", str(db)]) == 0
    assert "| S | 4 |" in capsys.readouterr().out
    assert main_code(["study-report", str(db), "--out", str(tmp_path / "rep")]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep", "s.sqlite"]
    assert db.read_bytes() == before
    # resuming checks the file read-only first, then writes it (its -wal while open)
    store = Store(db, StudyConfig().as_dict())
    assert len(store.done()) == 4
    store.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep", "s.sqlite"]


def test_a_report_while_a_study_writes_sees_its_runs(tmp_path):
    """With a writer's -wal holding runs not yet in the file, the report reads them there."""
    db = tmp_path / "s.sqlite"
    study_database(db)
    writer = Store(db, StudyConfig().as_dict())
    writer.add(*fake_run(Key("bezier", 9, "1", "s"), {}))
    assert (tmp_path / "s.sqlite-wal").stat().st_size > 0
    reader = Store(db, readonly=True)
    assert len(reader.runs()) == 5
    reader.close()
    writer.close()


def _read_only(directory, *args: str) -> subprocess.CompletedProcess:
    """``rigidfold ARGS`` with ``directory`` read-only: a read-only bind mount of it in a
    mount namespace of its own (root), else the directory's write permission removed."""
    command = [sys.executable, "-m", "rigidfold.cli", *args]
    if os.geteuid() != 0:
        directory.chmod(0o555)
        try:
            return run_cli(*args)
        finally:
            directory.chmod(0o755)
    if shutil.which("unshare") is None:
        pytest.skip("needs unshare to mount a directory read-only")
    d = str(directory)
    script = f'mount --bind "{d}" "{d}" && mount -o remount,bind,ro "{d}" && exec "$@"'
    proc = subprocess.run(
        ["unshare", "--mount", "--propagation", "private", "sh", "-c", script, "sh", *command],
        capture_output=True,
        text=True,
        check=False,
    )
    if "mount" in proc.stderr and proc.returncode != 0 and "rigidfold" not in proc.stderr:
        pytest.skip(f"cannot mount read-only here: {proc.stderr.strip()}")
    return proc


def test_a_database_on_a_read_only_file_system_is_reported_not_called_damaged(tmp_path):
    """Issue 30, item 18: `study-report` on a read-only mount said "damaged SQLite file:
    unable to open database file". It reads the database now; a study killed with runs in
    its -wal and no -shm beside it is named for what it is."""
    db = tmp_path / "s.sqlite"
    study_database(db)
    proc = _read_only(tmp_path, "study-report", str(db))
    assert proc.returncode == 0, proc.stderr
    assert "| S | 4 |" in proc.stdout
    proc = _read_only(tmp_path, *STUDY, "--surfaces", "4", "--db", str(db))
    assert proc.returncode == 2
    (line,) = proc.stderr.splitlines()
    assert "cannot create its lock file" in line and "damaged" not in line
    # runs only in the -wal of a killed study, its -shm gone
    con = sqlite3.connect(db)
    con.execute("PRAGMA wal_autocheckpoint = 0")
    con.execute("UPDATE runs SET n_lock = 7")
    con.commit()
    shutil.copy(db, tmp_path / "k.sqlite")
    shutil.copy(tmp_path / "s.sqlite-wal", tmp_path / "k.sqlite-wal")
    con.close()
    proc = _read_only(tmp_path, "study-report", str(tmp_path / "k.sqlite"))
    assert proc.returncode == 2
    (line,) = proc.stderr.splitlines()
    assert line == (
        f"rigidfold: error: {str(tmp_path / 'k.sqlite')!r}: cannot read its write-ahead log "
        "(k.sqlite-wal) in a read-only directory: SQLite needs to create k.sqlite-shm beside "
        "it; copy the database with its -wal file to a writable directory"
    )
    proc = run_cli("study-report", str(tmp_path / "k.sqlite"))  # writable again: read
    assert proc.returncode == 0 and "| S | 4 | 1.00 ± 0.00 | 7.00 ± 0.00 |" in proc.stdout
