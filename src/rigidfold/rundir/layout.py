"""The run directory of ``rigidfold generate``: its files, its lock, and ``--overwrite``.

One running ``generate`` per directory (:func:`lock_run_dir`), and an earlier run's files
refused or, with ``--overwrite``, removed (:func:`clear_earlier_run`), never an input.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

from rigidfold.errors import RigidfoldError

TARGET_FILE = "target_surface.json"
"""The fitted spline of a mesh target (:meth:`rigidfold.surfaces.SplineSurface.grid`), which
summary.json names under ``target_surface`` so that the report can show the fit."""

REPORT_FILE = "report.html"
"""The run's report (:func:`rigidfold.pipeline.writer.write_report`), its figures in
:data:`FIGURES_DIR`."""

FIGURES_DIR = "figures"

FINAL_DIR = "final"
"""The final design's exports, its thick panels and its structure."""

RUN_FILES = ("summary.json", "log.jsonl", REPORT_FILE, TARGET_FILE)
"""The files a generation run writes at the top of its directory."""

OLD_RUN_FILES = ("log.json",)
"""Files that runs of earlier rigidfold versions wrote at the top of their directory: an
earlier run all the same (refused, or removed with ``--overwrite``)."""

RUN_DIRS = ("solutions", FIGURES_DIR, FINAL_DIR)
"""The directories a generation run writes (solution files, figures, exports)."""

_STEP = r"step_[0-9]+_dof_[0-9]+"
RUN_DIR_FILES = {
    "solutions": re.compile(rf"{_STEP}\.(?:fold|svg)"),
    "figures": re.compile(r"[A-Za-z0-9_]+\.png"),
    "final": re.compile(
        rf"{_STEP}(?:\.[a-z0-9.]+|_[a-z0-9_]+\.[a-z0-9]+)"
        rf"|thick|thick/{_STEP}_[a-z0-9_]+\.[a-z0-9]+"
        r"|structure|structure/structure\.(?:json|png)"
    ),
}
"""What a generation run writes in each of its directories (paths relative to it): the only
entries ``--overwrite`` removes with them; an entry of another name there is the user's, and
the directory is then refused, not removed. Temporary files of a killed run (``.NAME.<hex>.tmp``)
count as the run's."""

_TEMP = re.compile(r"(?:.*/)?\.[^/]*\.[0-9a-f]+\.tmp")


LOCK_NAME = ".rigidfold-run.lock"
"""The file that marks a directory as in use by a running ``generate`` (it holds the pid)."""


def lock_run_dir(out: Path) -> Path:
    """Claim ``out`` for one run: :data:`LOCK_NAME` in it holding this process's id. Returns
    the lock's path; ValueError when another live run holds it.

    The lock file is opened (created when absent; a symbolic link is refused, never
    followed) and decided on under an exclusive ``flock`` of it, which every claimant takes
    before it reads the pid: a live pid refuses; a lock that is empty, unreadable, or left
    by a process that no longer runs is taken over in place (this pid written over it). So
    of two processes taking over one stale lock, one gets it and the other finds it held,
    and a lock being created is never taken for a stale one. A lock released (removed) while
    it was waited for is made again.
    """
    import fcntl

    path = out / LOCK_NAME
    for _ in range(100):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            if path.is_symlink():
                raise RigidfoldError(
                    f"cannot lock output directory '{out}': its {LOCK_NAME} is a symbolic "
                    "link, not a rigidfold lock; remove it"
                ) from None
            raise RigidfoldError(f"cannot lock output directory '{out}': {exc.strerror}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)  # held only while deciding; closing drops it
            try:
                same = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # released (and maybe made again) while we waited: start over
                continue
            pid = _lock_owner(fd)
            if pid is not None and _alive(pid):
                raise RigidfoldError(
                    f"output directory '{out}' is in use by another rigidfold run (pid {pid}); "
                    "wait for it to end, or use another --out"
                )
            os.ftruncate(fd, 0)  # new, or stale: its run is gone
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            return path
        except OSError as exc:
            raise RigidfoldError(f"cannot lock output directory '{out}': {exc.strerror}") from None
        finally:
            os.close(fd)
    raise RigidfoldError(f"cannot lock output directory '{out}': its lock keeps coming back")


def _lock_owner(fd: int) -> int | None:
    """The pid written in the open lock file ``fd``, None when there is none: empty, not a
    number, or not a possible pid (0 or less names a process group in ``kill``)."""
    try:
        pid = int(os.pread(fd, 64, 0).decode("ascii").strip())
    except (OSError, ValueError):  # UnicodeDecodeError is a ValueError
        return None
    return pid if pid > 0 else None


def _alive(pid: int) -> bool:
    """Whether a process with this id runs (on this machine)."""
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):  # OverflowError: no pid is that large
        return False
    except PermissionError:
        return True
    return True


def clear_earlier_run(
    out: str | Path,
    *,
    overwrite: bool,
    inputs: tuple[Path, ...] = (),
    names: tuple[str, ...] | None = None,
    dirs: tuple[str, ...] = (),
) -> Path:
    """Refuse, or with ``overwrite`` remove, the files of an earlier run in ``out``.

    The one rule of ``--overwrite``: it replaces only what the command writes. ``names`` are
    the files the command writes (a generation run's by default, :data:`RUN_FILES` and the
    file of earlier versions :data:`OLD_RUN_FILES`, with its directories :data:`RUN_DIRS`
    as ``dirs``); only they count and are removed, other
    files in ``out`` stay. A directory where the command writes a file is never removed:
    it is refused, with or without ``overwrite`` (a file cannot be written there). Only the
    command's own directories, ``dirs``, are removed whole. With ``overwrite`` the
    temporary files of those names that a killed run left (``.report.html.<random>.tmp``:
    :func:`rigidfold.io.files.temp_files`) are removed too. A symbolic link among them is
    removed itself, never followed. Removing one of the run's ``inputs`` (e.g. an earlier
    solution used as the pattern) is refused. Returns ``out`` as a Path. Raises ValueError
    naming what was found.
    """
    from rigidfold.io.files import temp_files

    if names is None:
        names, dirs = (*RUN_FILES, *OLD_RUN_FILES), (*RUN_DIRS, *dirs)
    out = Path(out)
    for n in names:
        if n not in dirs and (out / n).is_dir() and not (out / n).is_symlink():
            raise RigidfoldError(
                f"output directory '{out}' holds a directory '{n}' where this command writes "
                "a file (--overwrite replaces only files the command writes): move it, or use "
                "another --out"
            )
    every = (*names, *(d for d in dirs if d not in names))
    found = [out / n for n in every if (out / n).is_symlink() or (out / n).exists()]
    if found and not overwrite:
        raise RigidfoldError(
            f"output directory '{out}' holds an earlier run ({', '.join(p.name for p in found)}): "
            "give --overwrite to replace it, or another --out"
        )
    if overwrite:
        found += temp_files(out, every)
    if not found:
        return out
    for path in found:
        for given in inputs:
            doomed = (
                given.absolute() == path.absolute()
                if path.is_symlink()
                else (
                    path.resolve() == given.resolve() or path.resolve() in given.resolve().parents
                )
            )
            if doomed:
                raise RigidfoldError(
                    f"--overwrite would remove the input file '{given}' with the earlier run's "
                    f"{path.name}: copy it out of '{out}' first, or use another --out"
                )
    for path in found:
        pattern = RUN_DIR_FILES.get(path.name)
        if pattern is not None and path.is_dir() and not path.is_symlink():
            foreign = _foreign(path, pattern)
            if foreign is not None:
                raise RigidfoldError(
                    f"output directory '{out}' holds '{path.name}/{foreign}', which rigidfold "
                    f"did not write, in the run's {path.name}/ (--overwrite replaces only what "
                    "the command writes): move it, or use another --out"
                )
    try:
        for path in found:
            if path.name in dirs and path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            elif not path.is_dir() or path.is_symlink():
                path.unlink(missing_ok=True)
    except OSError as exc:
        raise RigidfoldError(
            f"cannot remove the earlier run's {exc.filename}: {exc.strerror}"
        ) from None
    return out


def _foreign(directory: Path, pattern: re.Pattern) -> str | None:
    """The first entry below ``directory`` (its path relative to it) that is not one a run
    writes there (``pattern``, or a temporary file), None when there is none; a symbolic
    link is an entry itself, never followed."""
    for root, subdirs, files in os.walk(directory):
        here = Path(root).relative_to(directory)
        for name in sorted(subdirs) + sorted(files):
            rel = (here / name).as_posix()
            if not (pattern.fullmatch(rel) or _TEMP.fullmatch(rel)):
                return rel
    return None
