"""How long this process has run: a time limit counts from the command's start.

A user who gives ``rigidfold generate --time-limit T`` measures the command, from the moment
it was started: the Python start-up, the libraries' imports (about 2-5 s: SciPy, CasADi),
the restart with the pinned numerics (:func:`rigidfold.runtime.numerics.restart_pinned`,
an ``exec`` that keeps the process) and building the case all count. :func:`process_age`
gives those seconds, so that the command line hands the search what is left of T.
"""

from __future__ import annotations

import os
import time


def process_age() -> float:
    """Seconds since this process was started (its fork; an ``exec`` keeps the time), from
    ``/proc/self/stat`` and the boot-time clock on Linux; 0.0 where they cannot be read
    (another system): then a time limit counts from the call of the library instead."""
    try:
        with open("/proc/self/stat", "rb") as f:
            stat = f.read().decode("ascii", "replace")
        # the fields after the command name, which is in parentheses and may hold spaces
        fields = stat[stat.rindex(")") + 2 :].split()
        ticks = int(fields[19])  # field 22 of proc(5): starttime, clock ticks after boot
        started = ticks / os.sysconf("SC_CLK_TCK")
        now = time.clock_gettime(time.CLOCK_BOOTTIME)
    except (OSError, ValueError, IndexError, AttributeError):
        return 0.0
    return max(0.0, now - started)


_command_started: float | None = None
"""The time of ``time.monotonic()`` at which this process, the ``rigidfold`` command, was
started (:func:`mark_command`); None where the command line is called from a program."""


def mark_command() -> None:
    """Note that this process is the ``rigidfold`` command (``python -m rigidfold``,
    ``python -m rigidfold.cli``, the installed script), started :func:`process_age` seconds
    ago: its time limit counts from then (:func:`command_started`)."""
    global _command_started
    _command_started = time.monotonic() - process_age()


def command_started() -> float | None:
    """When this process, the ``rigidfold`` command, was started (of ``time.monotonic()``);
    None when the command line runs inside another program (a test, a script calling
    ``rigidfold.cli.commands.main``): its limit then counts from the run's start."""
    return _command_started
