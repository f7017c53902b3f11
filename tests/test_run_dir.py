"""The lock of a generate run's directory and the files an earlier run leaves (issue 30,
items 17 and 18): a stale lock is taken over by one claimant only, and ``--overwrite``
removes the temporary files of a killed run."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import pytest

from conftest import main_code
from rigidfold.rundir import LOCK_NAME, clear_earlier_run, lock_run_dir
from rigidfold.rundir import layout as run_lock


def _dead_pid() -> int:
    """The id of a process that has ended."""
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    return int(proc.stdout)


def _race(out, claimants: int) -> list[str]:
    """``claimants`` threads call :func:`lock_run_dir` on ``out`` at once; what each got:
    "locked", or the error message."""
    start = threading.Barrier(claimants)
    got: list[str] = []

    def claim() -> None:
        start.wait()
        try:
            lock_run_dir(out)
            got.append("locked")
        except ValueError as exc:
            got.append(str(exc))

    threads = [threading.Thread(target=claim) for _ in range(claimants)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return got


def test_a_stale_lock_is_taken_over_by_one_claimant_only(tmp_path, monkeypatch):
    """Issue 30, item 17. Claimants that check the stale pid slowly (a busy machine) all find
    it dead; before, each removed the lock it found and made its own, so that every one of
    them "took over". Threads of one process contend like processes: each opens the lock
    itself (its own open file description, its own flock)."""
    real_alive = run_lock._alive

    def slow_alive(pid: int) -> bool:
        time.sleep(0.02)
        return real_alive(pid)

    monkeypatch.setattr(run_lock, "_alive", slow_alive)
    dead = _dead_pid()
    for trial in range(8):
        out = tmp_path / f"t{trial}"
        out.mkdir()
        (out / LOCK_NAME).write_text(f"{dead}\n")
        got = _race(out, 3)
        assert got.count("locked") == 1, got
        refused = [g for g in got if g != "locked"]
        assert all(f"in use by another rigidfold run (pid {os.getpid()})" in g for g in refused)
        assert (out / LOCK_NAME).read_text() == f"{os.getpid()}\n"
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


@pytest.mark.parametrize("content", ["", "garbage", "0", "-1", str(2**64), "\xff"])
def test_a_lock_without_a_live_pid_is_taken_over(tmp_path, content):
    """Empty (a claimant killed before it wrote), not a pid, or a pid that kill() would read
    as a process group (0, -1: "alive" for ever before) or that overflows it."""
    (tmp_path / LOCK_NAME).write_text(content)
    path = lock_run_dir(tmp_path)
    assert path.read_text() == f"{os.getpid()}\n"
    with pytest.raises(ValueError, match=f"in use by another rigidfold run \\(pid {os.getpid()}"):
        lock_run_dir(tmp_path)
    path.unlink()  # released: made again
    assert lock_run_dir(tmp_path).read_text() == f"{os.getpid()}\n"


def test_a_lock_that_is_a_link_is_refused_not_followed(tmp_path):
    target = tmp_path / "elsewhere"
    target.write_text("keep")
    out = tmp_path / "run"
    out.mkdir()
    (out / LOCK_NAME).symlink_to(target)
    with pytest.raises(ValueError, match="is a symbolic link, not a rigidfold lock"):
        lock_run_dir(out)
    assert target.read_text() == "keep"


# --------------------------------------------- item 18: temporary files of a killed run
LEFT = [".report.html.0123456789ab.tmp", ".summary.json.a1b2c3d4e5f6.tmp", ".log.json.ff.tmp"]
"""What a run killed while it wrote its files leaves (:func:`rigidfold.io.atomic_write`)."""
KEPT = [
    ".report.html.notes",  # not a temporary name
    "report.html.0123456789ab.tmp",  # no leading dot
    ".report.html.0123456789ab.tmpx",
    ".report.html.xyz.tmp",  # not hexadecimal
    ".notes.txt.0123456789ab.tmp",  # of a file that is not the run's
    ".r.0123456789ab.tmp",  # a short prefix of a run's name: not a cut name
]


def test_overwrite_removes_the_temporary_files_a_killed_run_left(tmp_path):
    """Issue 30, item 18: a SIGKILL while report.html (2 MB) was written left
    ``.report.html.<hex>.tmp``, which ``--overwrite`` kept for ever."""
    outside = tmp_path / "outside.txt"
    outside.write_text("keep")
    out = tmp_path / "run"
    out.mkdir()
    (out / "summary.json").write_text("{}")
    for name in [*LEFT, *KEPT]:
        (out / name).write_bytes(b"x" * 1000)
    (out / ".log.json.abcdefabcdef.tmp").symlink_to(outside)  # removed, not followed
    (out / ".report.html.abcdef012345.tmp").mkdir()  # a directory is nobody's temporary file
    with pytest.raises(ValueError, match=r"holds an earlier run \(summary\.json\)"):
        clear_earlier_run(out, overwrite=False)
    assert len(list(out.iterdir())) == 1 + len(LEFT) + len(KEPT) + 2
    clear_earlier_run(out, overwrite=True)
    assert sorted(p.name for p in out.iterdir()) == sorted([*KEPT, ".report.html.abcdef012345.tmp"])
    assert outside.read_text() == "keep"


def test_generate_overwrite_removes_them(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["generate", "--surface", "dome", "--pattern", "grid:3x3", "--no-deform", "--quiet"]
    assert main_code([*args, "--target-dof", "6", "--out", str(out)]) == 0
    for name in LEFT:
        (out / name).write_bytes(b"x" * 1000)
    assert main_code([*args, "--target-dof", "6", "--out", str(out), "--overwrite"]) == 0
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]
    assert (out / "report.html").is_file()


def test_the_report_figures_overwrite_removes_are_every_figure_the_report_draws():
    """--overwrite removes the report's figures by exact name (issue 47, item 4): the names
    in :data:`FIGURE_NAMES` are every one :func:`rigidfold.reporting.render_figures` writes."""
    import re
    from pathlib import Path

    import rigidfold.reporting.figures as figures
    from rigidfold.rundir.layout import FIGURE_NAMES

    drawn = re.findall(r'_figure\(plt, "([^"]+)"', Path(figures.__file__).read_text())
    assert drawn and sorted(drawn) == sorted(FIGURE_NAMES)
