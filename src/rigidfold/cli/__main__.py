"""``python -m rigidfold.cli``: the command line, in this process as it is."""

import sys

from rigidfold.runtime.clock import mark_command
from rigidfold.runtime.interrupts import (
    EXIT_INTERRUPTED,
    command_ended,
    decided_exit,
    terminate_interrupts,
)

if __name__ == "__main__":
    terminate_interrupts()  # before the command line's modules load: SIGTERM then exits 130
    mark_command()  # a time limit counts from the process's start
    code = None
    try:
        from rigidfold.cli.commands import main

        code = main()
        command_ended()  # ended: a signal now changes nothing
    except KeyboardInterrupt:
        if code is None:
            code = decided_exit()  # the run had ended: the signal stops nothing
        if code is None:
            print("rigidfold: interrupted", file=sys.stderr)
            code = EXIT_INTERRUPTED
        command_ended()
    sys.exit(code)
