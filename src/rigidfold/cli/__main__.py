"""``python -m rigidfold.cli``: the command line, in this process as it is."""

import sys

from rigidfold.cli.commands import main
from rigidfold.runtime.interrupts import terminate_interrupts

if __name__ == "__main__":
    terminate_interrupts()
    sys.exit(main())
