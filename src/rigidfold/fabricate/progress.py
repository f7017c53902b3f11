"""Progress of thick panels on stderr: one line as each step that can take long begins; and
the size limit of a design built thick.

Only for designs of at least ``Settings.fabricate.progress_panels`` panels (a step of a
smaller one takes a second or two, and its command prints nothing but its result).
"""

from __future__ import annotations

import sys
import time

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError

_START = time.monotonic()


def step(text: str, panels: int, *, settings: Settings = DEFAULTS) -> None:
    """Print ``fabricate: TEXT`` (with the seconds since the process started) on stderr
    when ``panels`` is at least ``settings.fabricate.progress_panels``."""
    if panels >= settings.fabricate.progress_panels:
        print(f"fabricate [{time.monotonic() - _START:.0f} s]: {text}", file=sys.stderr, flush=True)


def check_size(n_panels: int, *, settings: Settings = DEFAULTS) -> None:
    """ValueError (one line) for a design of more than
    ``settings.limits.max_fabricate_panels`` panels."""
    most = settings.limits.max_fabricate_panels
    if n_panels > most:
        raise RigidfoldError(
            f"a design of {n_panels} panels is too large to build thick (at most {most}: "
            "Settings.limits.max_fabricate_panels)"
        )
