"""`rigidfold study` / `study-report` on damaged or foreign databases, two clients on one
database, and a scheduler address that is not Dask (issue 17, defects 5, 8 and 10)."""

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

from conftest import run_cli
from rigidfold.study import Key, Store, StudyConfig

STUDY = ["--surfaces", "1", "--patterns", "1", "--criteria", "s", "--no-deform", "--quiet"]


def valid_database(path) -> None:
    """A study database of 60 runs of 5 attempts each, written by Store (no Dask)."""
    store = Store(path, StudyConfig().as_dict())
    attempt = {"fixed_added": [1, 2], "status": "converged", "locked": [], "outcome": "accepted"}
    for seed in range(60):
        run = {"status": "target DOF 1 reached", "n_lock": 1, "version": "v"}
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
    config = StudyConfig(deform=False).as_dict()
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
            "import sys, time\nfrom rigidfold.study import Store, StudyConfig\n"
            f"Store({str(db)!r}, StudyConfig(deform=False).as_dict())\n"
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
    store.add(Key("bezier", 0, "1", "s"), {"status": "x", "version": "v"}, [])
    with pytest.raises(ValueError, match="already holds the run"):
        store.add(Key("bezier", 0, "1", "s"), {"status": "x", "version": "v"}, [])
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
    assert proc.returncode == 2 and "--connect-timeout must be > 0" in proc.stderr


def test_a_dask_scheduler_is_reached_through_the_handshake():
    from dask.distributed import LocalCluster

    from rigidfold.study.runner import connect

    with LocalCluster(
        n_workers=0, processes=False, protocol="tcp://", dashboard_address=":0"
    ) as cluster:
        client = connect(cluster.scheduler_address, 10)
        assert client.scheduler_info()["address"] == cluster.scheduler_address
        client.close()
