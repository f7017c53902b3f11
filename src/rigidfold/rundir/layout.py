"""The run directory of ``rigidfold generate``: its files, its lock, and ``--overwrite``.

One running ``generate`` per directory (:func:`lock_run_dir`), and an earlier run's files
refused or, with ``--overwrite``, removed (:func:`earlier_run`, :func:`clear_earlier_run`):
exactly the files it recorded, never a file matched by a pattern, never an input.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from rigidfold.errors import RigidfoldError

TARGET_FILE = "target_surface.json"
"""The fitted spline of a mesh target (:meth:`rigidfold.surfaces.SplineSurface.grid`), which
summary.json names under ``target_surface`` so that the report can show the fit."""

REPORT_FILE = "report.html"
"""The run's report (:func:`rigidfold.pipeline.report.write_report`), its figures in
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

FIGURE_NAMES = (
    "development.png",
    "dof_and_F.png",
    "surface_fit.png",
    "fold_angles.png",
    "deformation.png",
)
"""Every figure the report may write in :data:`FIGURES_DIR`
(:func:`rigidfold.reporting.render_figures`): the only files there ``--overwrite`` removes."""

_RUN_SUBDIRS = ("solutions", FIGURES_DIR, FINAL_DIR, f"{FINAL_DIR}/thick", f"{FINAL_DIR}/structure")
"""Every directory a generation run makes, the deepest last."""

_STAGING = re.compile(rf"\.{FINAL_DIR}\.[0-9a-f]+\.tmp")
"""The directory the final design's exports are written to before they are moved into
:data:`FINAL_DIR` together (:meth:`rigidfold.pipeline.run._Run.export`): a killed run's
own, removed by ``--overwrite``."""

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


@dataclass(frozen=True)
class EarlierRun:
    """What an earlier run left in ``out`` that ``--overwrite`` removes: ``files``, the files
    it recorded (and their temporary files), each removed itself (a symbolic link is never
    followed); ``trees``, directories that are the run's own whole (a killed run's staging
    directory, a run directory that is a symbolic link: the link is removed); ``dirs``, the
    run's directories, removed when they are left empty."""

    out: Path
    files: tuple[Path, ...] = ()
    trees: tuple[Path, ...] = ()
    dirs: tuple[Path, ...] = ()

    def remove(self, keep: Iterable[Path] = ()) -> None:
        """Remove the earlier run's files but those in ``keep`` (written again, in place,
        by the new run), then its directories left empty. Raises ValueError naming a file
        that cannot be removed."""
        kept = {os.path.abspath(p) for p in keep}
        try:
            for path in self.trees:
                if path.is_symlink() or not path.is_dir():
                    path.unlink(missing_ok=True)
                else:
                    shutil.rmtree(path)
            for path in self.files:
                if os.path.abspath(path) not in kept:
                    path.unlink(missing_ok=True)
        except OSError as exc:
            raise RigidfoldError(
                f"cannot remove the earlier run's {exc.filename}: {exc.strerror}"
            ) from None
        for path in self.dirs:
            with contextlib.suppress(OSError):  # not empty: a file of the user's is there
                path.rmdir()


def earlier_run(
    out: str | Path,
    *,
    overwrite: bool,
    inputs: tuple[Path, ...] = (),
    names: tuple[str, ...] | None = None,
    dirs: tuple[str, ...] = (),
    others: tuple[str, ...] = (),
) -> EarlierRun:
    """Refuse an earlier run's files in ``out`` unless ``overwrite``; with it, what is to be
    removed (:class:`EarlierRun`), nothing removed yet.

    The one rule of ``--overwrite``: it removes exactly the files the earlier run wrote and
    recorded, never a file matched by a pattern, and every other file stays. ``names`` are
    the files the command writes and the earlier run recorded (paths relative to ``out``); by
    default a generation run's: :data:`RUN_FILES` and :data:`OLD_RUN_FILES`, the figures
    :data:`FIGURE_NAMES`, and what its summary.json lists (:func:`recorded_files`: the
    solutions and their diagrams, the exports, the thick panels' and the structure's
    files), its directories :data:`RUN_DIRS` as ``dirs``. ``others``: names that show an
    earlier run (refused without ``overwrite``) but that it did not record, which stay. A
    directory where the command writes a file is refused, with or without ``overwrite``
    (a file cannot be written there). The temporary files of the recorded names that a
    killed run left (``.report.html.<random>.tmp``: :func:`rigidfold.io.files.temp_files`)
    and its staging directory of the exports (``.final.<random>.tmp``) are its own too.
    Removing one of the run's ``inputs`` (e.g. an earlier solution used as the pattern) is
    refused. Raises ValueError naming what was found.
    """
    from rigidfold.io.files import temp_files

    out = Path(out)
    generate = names is None
    if names is None:
        dirs = (*RUN_DIRS, *dirs)
        names = (
            *RUN_FILES,
            *OLD_RUN_FILES,
            *(f"{FIGURES_DIR}/{n}" for n in FIGURE_NAMES),
            *recorded_files(out),
        )
    for n in names:
        if "/" not in n and (out / n).is_dir() and not (out / n).is_symlink():
            raise RigidfoldError(
                f"output directory '{out}' holds a directory '{n}' where this command writes "
                "a file (--overwrite replaces only files the command writes): move it, or use "
                "another --out"
            )
    shown = [n for n in (*names, *others, *dirs) if "/" not in n]
    found = [n for n in dict.fromkeys(shown) if _present(out / n)]
    if found and not overwrite:
        raise RigidfoldError(
            f"output directory '{out}' holds an earlier run ({', '.join(found)}): "
            "give --overwrite to replace it, or another --out"
        )
    if not overwrite or not found:
        return EarlierRun(out)
    subdirs = _RUN_SUBDIRS if generate else dirs
    linked: list[str] = []  # the run's directories that are links: removed, never followed
    for d in subdirs:
        if not any(d.startswith(f"{up}/") for up in linked) and (out / d).is_symlink():
            linked.append(d)
    trees = [out / d for d in linked]
    if generate:
        trees += [
            p
            for p in _entries(out)
            if _STAGING.fullmatch(p.name) and not p.is_symlink() and p.is_dir()
        ]
    files = [
        out / n
        for n in names
        if not any(n.startswith(f"{d}/") for d in linked) and (out / n).parent.is_dir()
    ]
    by_dir: dict[Path, list[str]] = {}
    for path in files:
        by_dir.setdefault(path.parent, []).append(path.name)
    files = [p for p in files if p.is_symlink() or (p.exists() and not p.is_dir())]
    for directory, members in by_dir.items():
        files += temp_files(directory, members)
    for path in [*files, *trees]:
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
    empty = [
        out / d
        for d in reversed(subdirs)
        if not any(d == up or d.startswith(f"{up}/") for up in linked) and (out / d).is_dir()
    ]
    return EarlierRun(out, tuple(files), tuple(trees), tuple(empty))


def clear_earlier_run(
    out: str | Path,
    *,
    overwrite: bool,
    inputs: tuple[Path, ...] = (),
    names: tuple[str, ...] | None = None,
    dirs: tuple[str, ...] = (),
) -> Path:
    """Refuse, or with ``overwrite`` remove at once, the files of an earlier run in ``out``
    (:func:`earlier_run`, whose rule it follows). Returns ``out`` as a Path."""
    earlier_run(out, overwrite=overwrite, inputs=inputs, names=names, dirs=dirs).remove()
    return Path(out)


def recorded_files(out: Path) -> list[str]:
    """The files in its directories that the generation run in ``out`` recorded in its
    summary.json (paths relative to ``out``): its solutions and the SVG of each, its
    exports, its target surface, the files of its thick panels and of its structure. Only
    a name of the form the run writes there counts (``solutions/NAME.fold``,
    ``final/NAME``, ``final/thick/NAME``, ``final/structure/NAME``); ``[]`` when summary.json
    cannot be read (not JSON, a symbolic link, not a file). Its order: as listed."""
    from rigidfold.io.files import parse_json

    try:
        fd = os.open(out / "summary.json", os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        with os.fdopen(fd, "rb") as file:
            data = parse_json(file.read())
    except (OSError, ValueError):
        return []
    if not isinstance(data, dict):
        return []

    def listed(value) -> list:
        return value if isinstance(value, list) else []

    names = [*listed(data.get("solutions")), *listed(data.get("exports"))]
    names.append(data.get("target_surface"))
    for record in listed(data.get("per_solution")):
        for stage in ("fabrication", "structure"):
            part = record.get(stage) if isinstance(record, dict) else None
            files = part.get("files") if isinstance(part, dict) else None
            names += listed(files)
    out_names: list[str] = []
    for name in names:
        if not isinstance(name, str) or not _RECORDED.fullmatch(name):
            continue
        out_names.append(name)
        if name.startswith("solutions/"):
            out_names.append(name[: -len(".fold")] + ".svg")
    return list(dict.fromkeys(out_names))


_NAME = r"(?!\.\.?(?:/|$))[^/\x00]+"
_RECORDED = re.compile(
    rf"solutions/{_NAME}\.fold|{FINAL_DIR}/(?:thick/|structure/)?{_NAME}|{TARGET_FILE}"
)
"""A file a generation run records, in the form it writes (see :func:`recorded_files`)."""


def _present(path: Path) -> bool:
    return path.is_symlink() or path.exists()


def _entries(directory: Path) -> list[Path]:
    try:
        return [Path(e.path) for e in os.scandir(directory)]
    except OSError:
        return []


SOLUTIONS_DIR = "solutions"
"""Where a generation run writes its solutions' FOLD files (:func:`solution_file`)."""


def solution_file(step: int, dof: int) -> Path:
    """The FOLD file of the solution at ``step`` with ``dof``, relative to the run's
    directory: ``solutions/step_XX_dof_YY.fold`` (its development diagram as ``.svg``
    beside it)."""
    return Path(SOLUTIONS_DIR) / f"step_{step:02d}_dof_{dof:02d}.fold"
