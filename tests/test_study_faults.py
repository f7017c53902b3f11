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
from rigidfold.study import Key, Store, StudyConfig
from rigidfold.study.store import RUN_FIELDS

STUDY = ["study", "--patterns", "1", "--criteria", "s", "--no-deform", "--quiet"]


def fake_run(key, config):
    """A run computed in no time, whose 40 attempts take several database pages."""
    row = {f: 1 for f in RUN_FIELDS if f not in ("status", "version", "worker", "numerics")}
    from rigidfold.numerics import numeric_environment

    row |= {"status": "target DOF 1 reached", "version": "t", "numerics": numeric_environment().key}
    attempt = {"fixed_added": list(range(100)), "status": "converged", "locked": list(range(100))}
    return key, row, [attempt | {"idx": i, "outcome": "accepted", "dof": 40 - i} for i in range(40)]


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
