"""Entry point of the ``rigidfold`` command: pin the numerics, then run the command line.

Kept apart from :mod:`rigidfold.cli` so that the restart with the pinned numerics
(:func:`rigidfold.numerics.restart_pinned`) happens before NumPy, SciPy and CasADi load.
"""

from __future__ import annotations

from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    from rigidfold.numerics import restart_pinned

    if argv is None:  # the process's own command line: it can be started again
        restart_pinned()
    from rigidfold.cli import main as cli_main

    return cli_main(argv)
