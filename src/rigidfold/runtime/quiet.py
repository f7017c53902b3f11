"""What OpenSees, CasADi and IPOPT print: hidden unless asked for.

OpenSeesPy writes its messages (``opserr``: warnings, ``printModel``) and CasADi writes
IPOPT's output and its own warnings through Python's ``sys.stdout`` and ``sys.stderr``.
:func:`native_quiet` drops what the thread that runs a solver writes to them while the
solver runs; what other threads write (a progress bar's refresh, Dask's logs) passes. It is
a context manager and a decorator, used around every OpenSees analysis and IPOPT solve;
it also keeps the interrupts that native code would swallow (:mod:`rigidfold.runtime.interrupts`).

The output is shown instead when the environment variable :data:`VERBOSE_ENV` is set to
anything but ``""`` or ``"0"`` (``rigidfold --verbose`` sets it for its own run, so the local
workers of a study started by that run show it too).

OpenSees also prints "Process 0 Terminating" while the process exits, after Python has
finished; ``rigidfold.cli`` closes standard error then (unless ``--verbose``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator
from typing import TextIO

from rigidfold.runtime.interrupts import kept_interrupts

VERBOSE_ENV = "RIGIDFOLD_VERBOSE"
"""Environment variable that shows what OpenSees, CasADi and IPOPT print."""


def native_output_shown() -> bool:
    """True when :data:`VERBOSE_ENV` asks for the solvers' output."""
    return os.environ.get(VERBOSE_ENV, "") not in ("", "0")


class _Filter:
    """A stand-in for ``sys.stdout`` or ``sys.stderr`` that drops the writes of the quiet
    threads and passes the others to the stream it replaced."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream

    def write(self, text: str) -> int:
        if threading.get_ident() in _QUIET:
            return len(text)
        return self.stream.write(text)

    def flush(self) -> None:
        self.stream.flush()

    def __getattr__(self, name: str):
        return getattr(self.stream, name)


_LOCK = threading.Lock()
_QUIET: dict[int, int] = {}  # thread id -> depth of native_quiet in that thread
_SAVED: list[tuple[TextIO, TextIO]] = []  # the streams replaced while a thread is quiet


def _enter() -> None:
    with _LOCK:
        if not _QUIET:
            sys.stdout.flush()
            sys.stderr.flush()
            _SAVED.append((sys.stdout, sys.stderr))
            sys.stdout, sys.stderr = _Filter(sys.stdout), _Filter(sys.stderr)
        me = threading.get_ident()
        _QUIET[me] = _QUIET.get(me, 0) + 1


def _leave() -> None:
    with _LOCK:
        me = threading.get_ident()
        _QUIET[me] -= 1
        if not _QUIET[me]:
            del _QUIET[me]
        if not _QUIET:
            sys.stdout, sys.stderr = _SAVED.pop()


@contextlib.contextmanager
def native_quiet() -> Iterator[None]:
    """Drop what this thread prints through ``sys.stdout`` and ``sys.stderr`` while the block
    runs (OpenSees's and CasADi's messages), unless :func:`native_output_shown`. Nested and
    concurrent uses (threads of a Dask worker) are safe: the streams are replaced once, while
    any thread is quiet. A Ctrl-C or SIGTERM that the native code swallows is raised when the
    block ends (:func:`rigidfold.runtime.interrupts.kept_interrupts`)."""
    with kept_interrupts():
        if native_output_shown():
            yield
            return
        _enter()
        try:
            yield
        finally:
            _leave()
