"""Entry point of the ``rigidfold`` command: pin the numerics, then run the command line.

Kept apart from :mod:`rigidfold.cli` so that the restart with the pinned numerics
(:func:`rigidfold.numerics.restart_pinned`) happens before NumPy, SciPy and CasADi load.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from rigidfold.interrupts import EXIT_INTERRUPTED, terminate_interrupts


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; Ctrl-C at any time, while the libraries load too, exits 130
    with one line ``rigidfold: interrupted``, not a traceback; SIGTERM too."""
    terminate_interrupts()
    try:
        from rigidfold.numerics import restart_pinned

        if argv is None:  # the process's own command line: it can be started again
            restart_pinned()
        from rigidfold.cli import main as cli_main

        return cli_main(argv)
    except KeyboardInterrupt:
        print("rigidfold: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
