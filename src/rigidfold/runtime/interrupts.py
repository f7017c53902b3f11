"""Ctrl-C and SIGTERM are never lost in native code.

Python turns SIGINT into a KeyboardInterrupt raised in the main thread at the next Python
instruction. While IPOPT runs, that instruction is in one of rigidfold's callbacks (the
closed-form Hessian, the early stop): CasADi catches the exception there and IPOPT ends with
"NonIpopt_Exception_Thrown", a solve that merely failed, and generation went on as if the
shape were infeasible ("no developable polyhedron from the initial shape", exit 1).

:func:`kept_interrupts` notes every SIGINT (and SIGTERM, where :func:`terminate_interrupts`
made it an interrupt) received while its block runs, raises KeyboardInterrupt in the handler
as Python's own does (so a callback stops the solver at once), and raises it again when the
block ends, whatever the native code made of the first: the run stops as interrupted. It is
used around every IPOPT solve (:func:`rigidfold.runtime.quiet.native_quiet`). Outside the main
thread, or where the program installed handlers of its own, it does nothing.
"""

from __future__ import annotations

import contextlib
import importlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType, ModuleType

EXIT_INTERRUPTED = 130
"""The exit code of an interrupted command (128 + SIGINT), after SIGTERM too."""


_PENDING: list[int] = []
"""The signals :func:`_interrupt` raised outside every :func:`kept_interrupts` block and no
command has yet acted on (:func:`interrupt_handled`)."""


def _interrupt(signum: int, frame: FrameType | None) -> None:
    """The handler of SIGINT and SIGTERM set by :func:`terminate_interrupts`: noted, then
    raised as Ctrl-C."""
    _PENDING.append(signum)
    raise KeyboardInterrupt


def terminate_interrupts() -> None:
    """Make SIGTERM raise KeyboardInterrupt in the main thread, as Ctrl-C does, so that a
    run stopped by ``kill`` (or a batch system) ends like an interrupted one: its files
    written, its lock released, summary.json saying "interrupted", exit 130. Only while
    SIGTERM has its default action (a program's own handler is kept), and only from the main
    thread.

    Both signals are also noted: a library may swallow the KeyboardInterrupt (CasADi's
    module runs ``try: from numpy import pi ... except: pass`` while it is imported, so a
    SIGTERM landing there was lost and the run went on to its end, exit 0); the next
    :func:`kept_interrupts` block (every solve, the whole pipeline) raises it again."""
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _interrupt)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)


def interrupt_handled() -> None:
    """The command has acted on a KeyboardInterrupt (it stops, or the run had ended): a
    signal noted before it is not raised again."""
    _PENDING.clear()


_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_DECIDED: list[int] = []  # the exit code of a command whose run has ended (decide_exit)


def decide_exit(code: int) -> int:
    """The command's run has ended, every file of it written, and ``code`` is its exit
    code: an interrupt from here on stops nothing, and the command's entry points, catching
    it on the way out, exit with ``code`` (:func:`decided_exit`) rather than 130 beside a
    summary that says the run ended (a signal just after the held block that prints the
    verdict did so, once in the interrupt contract's runs). Returns ``code``."""
    _DECIDED[:] = [code]
    return code


def forget_exit() -> None:
    """No exit code is decided (a command run again in-process starts afresh)."""
    _DECIDED.clear()


def decided_exit() -> int | None:
    """The exit code :func:`decide_exit` decided for the command (None: none yet)."""
    return _DECIDED[0] if _DECIDED else None


def command_ended() -> None:
    """The command has ended and its exit code is decided: what is left is Python's exit,
    which no signal may change. Call it only where the process is the command (its entry
    point), from the main thread.

    * SIGINT and SIGTERM are ignored from here: Python's exit (freeing every module, a
      second or more on a loaded machine) puts the default handlers back early, and a signal
      then killed a process whose run had written every file (exit -15, not 0). A signal
      received just before is dropped with them.
    * CPython notes a KeyboardInterrupt that leaves code run by ``exec`` of a string (as
      dataclasses and named tuples are made, while a library is imported) as unhandled,
      however the program handles it after, and a process started with ``python -m`` then
      kills itself with SIGINT as it exits (exit -2 after rigidfold said "interrupted" and
      chose 130). Running ``exec`` once more clears that note (it is kept for the last
      ``exec`` only), so the exit code is the command's.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for s in _SIGNALS:
        try:
            signal.signal(s, signal.SIG_IGN)
        except KeyboardInterrupt:  # one received just before: its handler ran first
            signal.signal(s, signal.SIG_IGN)
    exec("pass")  # clears CPython's unhandled-KeyboardInterrupt note (see above)


_INTERRUPTING = (signal.default_int_handler, _interrupt)
_ACTIVE: list[list[int]] = []  # the signals the active outermost kept_interrupts noted


@contextlib.contextmanager
def kept_interrupts() -> Iterator[list[int]]:
    """Run the block with SIGINT (and SIGTERM where it interrupts) noted: a KeyboardInterrupt
    is raised in the handler as usual, and again when the block ends if native code swallowed
    the first (see the module's text); an exception that native code made of it (CasADi's
    overloads try the next one when a conversion is interrupted, and a symbolic result
    then fails as a TypeError) becomes the KeyboardInterrupt. The block is given the list
    of the signals received, for a long block to check between its steps. Nested uses share
    the outermost's handler and list, and raise again at their own end for a signal
    received while they ran. The outermost raises at once a signal noted before it that
    was not acted on (a library swallowed its KeyboardInterrupt: see
    :func:`terminate_interrupts`)."""
    if threading.current_thread() is not threading.main_thread():
        yield []
        return
    if _PENDING and not _ACTIVE:
        _PENDING.clear()
        raise KeyboardInterrupt  # one that a library swallowed before this block
    if _ACTIVE:
        shared = _ACTIVE[0]
        before = len(shared)
        try:
            yield shared
        except BaseException as exc:
            if len(shared) > before and not isinstance(exc, KeyboardInterrupt):
                raise KeyboardInterrupt from exc
            raise
        if len(shared) > before:
            raise KeyboardInterrupt
        return
    received: list[int] = []

    def note(signum: int, frame: FrameType | None) -> None:
        received.append(signum)
        raise KeyboardInterrupt

    note.rigidfold_handler = True  # type: ignore[attr-defined]
    saved = {s: signal.getsignal(s) for s in _SIGNALS}
    kept = [s for s, handler in saved.items() if handler in _INTERRUPTING]
    for s in kept:
        signal.signal(s, note)
    _ACTIVE.append(received)
    try:
        yield received
    except BaseException as exc:
        if received and not isinstance(exc, KeyboardInterrupt):
            raise KeyboardInterrupt from exc  # what the native code made of it
        raise
    finally:
        _ACTIVE.pop()
        for s in kept:
            signal.signal(s, saved[s])
    if received:
        raise KeyboardInterrupt


@contextlib.contextmanager
def held_interrupts(*, reraise: bool = True) -> Iterator[list[int]]:
    """Run the block with SIGINT (and SIGTERM where it interrupts) held: a signal received
    while it runs is noted, not raised, so that a few bookkeeping steps that must go
    together (renaming a set of files into place, the records of a solution and its file)
    are never torn. When the block ends, a KeyboardInterrupt is raised for a held signal
    (``reraise``; otherwise the caller reads the list the block is given, the signals
    received). Keep the block short: the interrupt waits for it. Inside another held block
    it changes nothing (the outer one notes the signal and decides). Outside the main
    thread, or where the program installed handlers of its own, it holds nothing."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread() or any(
        getattr(signal.getsignal(s), "rigidfold_held", False) for s in _SIGNALS
    ):
        yield received  # inside another held block: that one notes the signal
        return

    def note(signum: int, frame: FrameType | None) -> None:
        received.append(signum)

    note.rigidfold_handler = True  # type: ignore[attr-defined]
    note.rigidfold_held = True  # type: ignore[attr-defined]
    saved = {s: signal.getsignal(s) for s in _SIGNALS}
    held = [
        s
        for s, handler in saved.items()
        if handler in _INTERRUPTING or getattr(handler, "rigidfold_handler", False)
    ]
    for s in held:
        signal.signal(s, note)
    try:
        yield received
    finally:
        for s in held:
            signal.signal(s, saved[s])
    if received and reraise:
        raise KeyboardInterrupt


def held_import(name: str) -> ModuleType:
    """Import the module ``name`` with SIGINT and SIGTERM held (:func:`held_interrupts`), and
    raise the interrupt once it is imported. A native extension module interrupted while it
    initialises can crash the process: a SIGTERM landing in ``import trimesh`` (which imports
    manifold3d, whose initialisation ran the handler's KeyboardInterrupt) ended a run with a
    segmentation fault, its lock left and nothing said (twice in 76 runs signalled there on a
    loaded machine). Use it for every lazy import of a native library (trimesh, manifold3d,
    python-fcl, rhino3dm)."""
    with held_interrupts():
        return importlib.import_module(name)
