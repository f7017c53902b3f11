"""Output files: the output directory, atomic writes and JSON data.

Every file rigidfold writes goes through :func:`atomic_write`: the content goes to a new,
uniquely named temporary file beside the target, is flushed to disk and then renamed onto
the target, so an interrupted run never leaves a half-written file and a reader never sees
one. A file that grows as a run goes (a run's attempt log) is appended to instead, a line
at a time (:func:`append_json_line`): a crash can tear only its last line.
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import re
import secrets
import stat
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.runtime.interrupts import held_interrupts

_TEMP_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)


def prepare_output_dir(path: str | os.PathLike, *, within: str | os.PathLike | None = None) -> Path:
    """Create the output directory and check it is writable, before any computation.

    The check creates and removes a new, uniquely named file in it. ``within``: ``path`` is
    a directory of that one (a run's ``figures/``, ``final/``), and no directory from
    ``within`` down to ``path`` may be a symbolic link, so nothing is written through a
    link to another place (the user's own output directory, ``within``, may be one).

    Raises ValueError ``"cannot write to output directory 'PATH': reason"``, and
    ``"'DIR' is a symbolic link ..."`` for a linked directory below ``within``.
    """
    out = Path(path)
    if within is not None:
        _refuse_linked_dirs(Path(within), out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        with held_interrupts():  # an interrupt here leaves no probe behind
            fd, probe = _create_temp(out, ".rigidfold-write-test")
            os.close(fd)
            probe.unlink()
    except OSError as exc:
        raise RigidfoldError(f"cannot write to output directory '{out}': {_reason(exc)}") from None
    return out


def _refuse_linked_dirs(root: Path, path: Path) -> None:
    """ValueError when a directory of ``path`` below ``root`` is a symbolic link (or
    ``path`` is not below ``root``)."""
    try:
        parts = path.relative_to(root).parts
    except ValueError:
        raise RigidfoldError(f"'{path}' is not a directory of '{root}'") from None
    here = root
    for part in parts:
        here = here / part
        if here.is_symlink():
            raise RigidfoldError(
                f"'{here}' is a symbolic link (to '{os.readlink(here)}'): rigidfold writes no "
                "file through a linked directory; remove the link"
            )


def inside_dir(root: str | os.PathLike, path: str | os.PathLike) -> Path:
    """``path`` (a file or directory under the directory ``root``, which need not exist) as a
    Path, when it stays inside ``root`` with every symbolic link followed (``root``'s own
    links included: a run directory may be reached through a link). A reader of a run's
    files passes each through it, so that no link leads it out of the run.

    Raises ValueError ``"'PATH' leads to 'REAL', outside the directory 'ROOT' ..."``.
    """
    path = Path(path)
    base = Path(os.path.realpath(root))
    real = Path(os.path.realpath(path))
    if real != base and base not in real.parents:
        raise RigidfoldError(
            f"'{path}' leads to '{real}', outside the directory '{root}': rigidfold reads no "
            "file of a run through a symbolic link out of its directory"
        )
    return path


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
"""The eight bytes every PNG file starts with."""


def read_png(path: str | os.PathLike) -> bytes:
    """The bytes of the PNG image ``path``, checked to start with the PNG signature (a
    report embeds no other file as an image).

    Raises ValueError ``"'PATH' is not a PNG image ..."`` or ``"cannot read 'PATH': ..."``.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise RigidfoldError(f"cannot read '{path}': {_reason(exc)}") from None
    if not data.startswith(PNG_SIGNATURE):
        raise RigidfoldError(
            f"'{path}' is not a PNG image (it starts with {data[:8]!r}, not the PNG signature)"
        )
    return data


def refuse_replacing_inputs(
    inputs: Iterable[str | os.PathLike], outputs: Iterable[str | os.PathLike]
) -> None:
    """Refuse, before anything is written, a command whose output would replace its input.

    ``outputs`` are the files a command would write, ``inputs`` the files it reads. Two paths
    are the same file when :func:`os.path.samefile` says so (symbolic and hard links
    included), or, when one of them does not exist, when their resolved paths are equal.

    Raises ValueError ``"the output 'OUT' would replace the input file 'IN'; choose another
    output directory"`` for the first output that is an input.
    """
    given = [Path(p) for p in inputs]
    for output in outputs:
        for path in given:
            if _same_file(Path(output), path):
                raise RigidfoldError(
                    f"the output '{output}' would replace the input file '{path}'; choose "
                    "another output directory"
                )


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (see :func:`refuse_replacing_inputs`)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (or cannot be looked at)
        pass
    try:
        return a.resolve() == b.resolve()
    except (OSError, RuntimeError):  # a loop of symbolic links names no file
        return False


def text_bytes(text: str) -> bytes:
    """``text`` as UTF-8 for a file's contents. A file name whose bytes are not UTF-8 reaches
    Python as lone surrogates (``surrogateescape``); inside a document (a title, a label)
    each such character becomes U+FFFD, so the document stays valid UTF-8 (the name on disk
    keeps its bytes)."""
    try:
        return text.encode("utf-8")
    except UnicodeEncodeError:  # rare: only then is the text looked at again
        return os.fsencode(text).decode("utf-8", "replace").encode("utf-8")


def atomic_write(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write ``data`` (str: as UTF-8) to ``path`` atomically; returns ``path`` as a Path.

    A new temporary file is created beside ``path`` (exclusive creation, not following
    symbolic links), written, flushed and synced to disk, then renamed onto ``path``. On any
    error the temporary file is removed and ``path`` is left as it was.

    Raises ValueError ``"cannot write 'PATH': reason"`` when the file cannot be written, and
    for data that is neither str nor bytes.
    """
    path = Path(path)
    if isinstance(data, str):
        data = text_bytes(data)
    elif not isinstance(data, bytes):
        raise RigidfoldError(
            f"cannot write '{path}': data must be str or bytes, got {type(data).__name__}"
        )
    tmp = None
    try:
        with held_interrupts():  # the file and the note of it go together
            fd, tmp = _create_temp(path.parent, path.name)
        with os.fdopen(fd, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        if tmp is not None:
            with contextlib.suppress(OSError):
                tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise RigidfoldError(f"cannot write '{path}': {_reason(exc)}") from None
        raise
    return path


def write_together(files: list[tuple[Path, str | bytes]]) -> list[Path]:
    """Write every ``(path, data)`` of ``files`` so that they appear together: each to a new
    temporary file beside its path (as :func:`atomic_write`: exclusive, no symbolic link
    followed, synced), and only when all of them are written are they renamed onto their
    paths. On an error while writing (a full disk) every temporary file is removed and no
    path is touched: ValueError ``"cannot write the N files of 'DIR' (reason): none
    written"``. A rename that fails after some succeeded (rare: renames take no space)
    raises ValueError naming the files that are missing. Returns the paths, in order."""
    staged: list[tuple[Path, Path]] = []
    try:
        for path, data in files:
            path = Path(path)
            raw = text_bytes(data) if isinstance(data, str) else data
            with held_interrupts():  # the file and the note of it go together
                fd, tmp = _create_temp(path.parent, path.name)
                staged.append((tmp, path))
            with os.fdopen(fd, "wb") as file:
                file.write(raw)
                file.flush()
                os.fsync(file.fileno())
    except BaseException as exc:
        for tmp, _ in staged:
            with contextlib.suppress(OSError):
                tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            where = Path(files[0][0]).parent if files else Path(".")
            raise RigidfoldError(
                f"cannot write the {len(files)} files of '{where}' ({_reason(exc)}): none written"
            ) from None
        raise
    done: list[Path] = []
    for k, (tmp, path) in enumerate(staged):
        try:
            os.replace(tmp, path)
        except OSError as exc:
            for left, _ in staged[k:]:
                with contextlib.suppress(OSError):
                    left.unlink(missing_ok=True)
            missing = ", ".join(p.name for _, p in staged[k:])
            raise RigidfoldError(
                f"cannot write '{path}' ({_reason(exc)}): {len(done)} of {len(staged)} files "
                f"written, missing: {missing}"
            ) from None
        done.append(path)
    return done


def write_json(path: str | os.PathLike, data, *, indent: int | None = 2) -> Path:
    """Write ``jsonable(data)`` as strict JSON text atomically (see :func:`atomic_write`).

    Raises ValueError for an unwritable file or data that is not JSON data.
    """
    path = Path(path)
    clean = jsonable(data, where=f"the JSON data of '{path}'")
    return atomic_write(path, json.dumps(clean, indent=indent, allow_nan=False) + "\n")


_APPEND_FLAGS = (
    os.O_WRONLY | os.O_APPEND | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
)


def append_json_line(path: str | os.PathLike, data, *, create: bool = False) -> Path:
    """Append ``jsonable(data)`` to ``path`` as one line of JSON text (JSON Lines), flushed
    and synced to disk before it returns; returns ``path`` as a Path.

    The line goes in one write to the end of the file (``O_APPEND``), so earlier lines are
    never touched and a crash can leave at most the last line torn (a reader skips a last
    line that does not parse). ``create``: the file is new, created exclusively (an
    existing file or symbolic link of that name is an error); otherwise it must exist. A
    symbolic link is never followed, and anything but a regular file is refused.

    Raises ValueError ``"cannot write 'PATH': reason"`` when the line cannot be appended, and
    for data that is not JSON data.
    """
    path = Path(path)
    clean = jsonable(data, where=f"the JSON data of '{path}'")
    line = (json.dumps(clean, allow_nan=False, separators=(",", ":")) + "\n").encode("utf-8")
    flags = _APPEND_FLAGS | (os.O_CREAT | os.O_EXCL if create else 0)
    try:
        fd = os.open(path, flags, 0o666)
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise RigidfoldError(f"cannot write '{path}': not a regular file")
            view = memoryview(line)
            try:
                while view:
                    view = view[os.write(fd, view) :]
            finally:  # a Ctrl-C between two writes of one line: the line is ended first
                while view:
                    view = view[os.write(fd, view) :]
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as exc:
        raise RigidfoldError(f"cannot write '{path}': {_reason(exc)}") from None
    return path


def parse_json(text: str | bytes, *, max_depth: int = DEFAULTS.limits.max_json_depth):
    """The JSON data of ``text``, nested at most ``max_depth`` levels
    (``Settings.limits.max_json_depth``).

    Raises json.JSONDecodeError for text that is not JSON, and ValueError ``"nested deeper
    than N levels"`` for a deeper document (one nested too deep for Python's parser included).
    """
    try:
        value = json.loads(text)
    except RecursionError:
        raise RigidfoldError(_too_deep(max_depth)) from None
    check_json_depth(value, max_depth=max_depth)
    return value


def check_json_depth(value, *, max_depth: int = DEFAULTS.limits.max_json_depth) -> None:
    """ValueError ``"nested deeper than N levels"`` when lists, tuples and dicts nest in
    ``value`` deeper than ``max_depth``; measured without recursion, so any depth is safe."""
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children = list(item.values())
        elif isinstance(item, list | tuple):
            children = list(item)
        else:
            continue
        if depth > max_depth:
            raise RigidfoldError(_too_deep(max_depth))
        stack.extend((child, depth + 1) for child in children)


def _too_deep(max_depth: int) -> str:
    return f"nested deeper than {max_depth} levels (Settings.limits.max_json_depth)"


def jsonable(value, *, where: str = "the value"):
    """``value`` as plain JSON data (what ``json.dumps(..., allow_nan=False)`` accepts).

    * NumPy arrays and scalars become Python lists and numbers (``tolist()``), then as below;
    * non-finite floats (NaN, +-inf) become None (JSON ``null``);
    * tuples become lists; dicts get ``str(key)`` keys (keys are not checked otherwise);
    * str, int, bool, None and finite floats stay as they are (subclasses such as
      :class:`rigidfold.outcomes.Outcome` members included).

    Raises ValueError ``"<where> holds a <type>, which is not JSON data"`` for anything else
    (sets, arbitrary objects), and ``"<where> is nested deeper than N levels"`` for lists and
    dicts nested deeper than ``Settings.limits.max_json_depth``.
    """
    try:
        check_json_depth(value)
    except ValueError as exc:
        raise RigidfoldError(f"{where} is {exc}") from None
    return _clean(value, where)


def _clean(value, where: str):
    """:func:`jsonable` of data whose depth is checked."""
    if isinstance(value, np.ndarray | np.generic):
        return _clean(value.tolist(), where)
    if isinstance(value, dict):
        return {str(k): _clean(v, where) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v, where) for v in value]
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, str | bool | int):
        return value
    raise RigidfoldError(f"{where} holds a {type(value).__name__}, which is not JSON data")


def _create_temp(directory: Path, stem: str) -> tuple[int, Path]:
    """A new file ``.<stem>.<random>.tmp`` in ``directory``: (open descriptor, path).

    Created exclusively (an existing file or symbolic link of that name is an error, then a
    new name is tried) with the permissions the umask allows, like any new file.
    """
    for _ in range(100):
        tmp = directory / f".{_cut(stem, _TEMP_STEM_BYTES)}.{secrets.token_hex(6)}.tmp"
        try:
            return os.open(tmp, _TEMP_FLAGS, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary file name in {directory}")


_TEMP_STEM_BYTES = 200
"""Most bytes of a file's name kept in its temporary name: with the dot, the random part and
``.tmp`` (18 bytes) it stays within the 255 bytes of a name on Linux and macOS."""


def _cut(name: str, limit: int) -> str:
    """The longest start of ``name`` that is at most ``limit`` bytes in the file system's
    encoding, cut between characters (a CJK character is 3 bytes in UTF-8)."""
    size = 0
    for k, ch in enumerate(name):
        size += len(os.fsencode(ch))
        if size > limit:
            return name[:k]
    return name


def temp_files(directory: Path, names: Iterable[str]) -> list[Path]:
    """The temporary files that :func:`atomic_write` left in ``directory`` for the files
    ``names`` (``.<name>.<random>.tmp``, the name maybe cut: a process killed between
    creating one and renaming it onto its target leaves it), sorted. A symbolic link of
    such a name counts too (to be removed, never followed), a directory does not; ``[]``
    when ``directory`` cannot be listed."""
    names = [n for n in names if n]
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return []
    found = []
    for entry in entries:
        match = _TEMP_NAME.fullmatch(entry.name)
        if (
            match
            and any(_cut_from(match["stem"], n) for n in names)
            and not entry.is_dir(follow_symlinks=False)
        ):
            found.append(Path(directory) / entry.name)
    return sorted(found)


_TEMP_NAME = re.compile(r"\.(?P<stem>.+)\.[0-9a-f]+\.tmp", re.DOTALL)
"""A name made by :func:`_create_temp`."""


def _cut_from(stem: str, name: str) -> bool:
    """Whether a temporary file's ``stem`` is ``name``, or ``name`` cut to
    ``_TEMP_STEM_BYTES`` (:func:`_cut`)."""
    return stem == name or stem == _cut(name, _TEMP_STEM_BYTES)


_CAUSES = {
    errno.ENOSPC: "the disk is full",
    errno.EDQUOT: "the disk quota is reached",
    errno.EFBIG: "the file size limit is reached (ulimit -f)",
}
"""What a write that failed for want of room means, said with the system's words."""


def _reason(exc: OSError) -> str:
    """Why a file could not be written: the system's words, and for want of room its cause
    (a full disk, the quota, the file size limit)."""
    words = str(exc.strerror or exc)
    cause = _CAUSES.get(exc.errno) if exc.errno is not None else None
    return words if cause is None else f"{words}: {cause}"
