"""Entry point of the ``rigidfold`` command: pin the numerics, then run the command line.

Kept apart from :mod:`rigidfold.cli` so that the restart with the pinned numerics
(:func:`rigidfold.runtime.numerics.restart_pinned`) happens before NumPy, SciPy and CasADi load.
"""

from __future__ import annotations

import sys
import sysconfig
from collections.abc import Sequence
from pathlib import Path

from rigidfold.runtime.clock import mark_command
from rigidfold.runtime.interrupts import (
    EXIT_INTERRUPTED,
    command_ended,
    decided_exit,
    interrupt_handled,
    terminate_interrupts,
)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; Ctrl-C at any time, while the libraries load too, exits 130
    with one line ``rigidfold: interrupted``, not a traceback; SIGTERM too. Started as the
    ``rigidfold`` command (or ``python -m rigidfold``), the process first restarts itself
    with the pinned numerics; called from another program, it does not (restarting would
    run that program again from the top: ``python -m rigidfold.pinned python script.py``
    pins one). Started as the command, its exit code is the command's whatever signal
    comes once it has ended (:func:`rigidfold.runtime.interrupts.command_ended`)."""
    terminate_interrupts()
    entry = argv is None and _started_as_rigidfold()  # this process is the command
    code = None
    try:
        from rigidfold.runtime.numerics import restart_pinned

        if entry:
            restart_pinned()
            mark_command()  # a time limit counts from the process's start
        from rigidfold.cli.commands import main as cli_main

        code = cli_main(argv)
    except KeyboardInterrupt:
        if code is None:
            code = decided_exit()  # the run had ended: the signal stops nothing
        if code is None:
            print("rigidfold: interrupted", file=sys.stderr)
            code = EXIT_INTERRUPTED
    interrupt_handled()  # the command has ended: called again in-process, it starts afresh
    if entry:
        command_ended()  # a signal from now on changes nothing, the exit code included
    return code


def _started_as_rigidfold() -> bool:
    """Whether this process is the ``rigidfold`` command: its main module is rigidfold's
    (``python -m rigidfold``) or an installed script (the console script of the package,
    in the environment's scripts directory), not a program of the user's."""
    main = sys.modules.get("__main__")
    spec = getattr(main, "__spec__", None)
    if spec is not None and spec.name.split(".")[0] == "rigidfold":
        return True
    file = getattr(main, "__file__", None)
    if file is None:
        return False
    scripts = sysconfig.get_path("scripts")
    return Path(file).resolve().parent == Path(scripts).resolve()
