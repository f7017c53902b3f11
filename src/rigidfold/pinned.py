"""``python -m rigidfold.pinned``: this machine's numeric environment, or a command run with
the pinned numerics of :mod:`rigidfold.runtime.numerics`.

::

    python -m rigidfold.pinned                  # the environment as JSON
    python -m rigidfold.pinned dask worker tcp://host:8786   # a study worker, pinned
    python -m rigidfold.pinned python script.py # a script whose designs match the CLI's
"""

from __future__ import annotations

import json
import os
import shutil
import sys

from rigidfold.runtime.numerics import (
    RESTARTED_ENV,
    numeric_environment,
    pinned_environ,
    restart_pinned,
)

EXIT_NOT_FOUND = 127  # as a shell reports a command it cannot find
EXIT_CANNOT_RUN = 126  # as a shell reports one it found but cannot run


USAGE = """usage: python -m rigidfold.pinned [-h] [COMMAND [ARG ...]]

Without a command: print this machine's numeric environment as JSON (the process restarted
with the pinned numerics of rigidfold.runtime.numerics first). With one: run COMMAND with those
numerics (its environment pinned), e.g. a study worker or a script whose designs match
the command line's:

  python -m rigidfold.pinned
  python -m rigidfold.pinned dask worker tcp://host:8786
  python -m rigidfold.pinned python script.py

Exit code: the command's; 127 when it is not found, 126 when it cannot be run."""


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] in ("-h", "--help"):  # an option of this module, not a command
        print(USAGE)
        return 0
    if args:
        program = shutil.which(args[0])
        if program is None:
            print(f"rigidfold.pinned: no command {args[0]!r}", file=sys.stderr)
            return EXIT_NOT_FOUND
        env = pinned_environ(os.environ)
        env[RESTARTED_ENV] = "1"
        try:
            os.execve(program, args, env)
        except OSError as exc:  # not a program: a script without #!, a directory, ...
            reason = exc.strerror or str(exc)
            print(f"rigidfold.pinned: cannot run {args[0]!r}: {reason}", file=sys.stderr)
            return EXIT_CANNOT_RUN
    restart_pinned()
    print(json.dumps(numeric_environment().to_dict(), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
