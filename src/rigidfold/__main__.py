"""``python -m rigidfold``: the command line, started with the pinned numerics."""

from rigidfold.cli.launch import main

if __name__ == "__main__":
    raise SystemExit(main())
