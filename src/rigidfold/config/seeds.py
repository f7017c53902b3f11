"""Seeds of Bezier surfaces and of generate's random draws."""

from __future__ import annotations

import numbers

from rigidfold.errors import RigidfoldError

SEED_LIMIT = 2**63
"""Seeds (of Bezier surfaces, of generate's random draws) are integers 0 <= seed <
SEED_LIMIT: a study stores them as SQLite's signed 64-bit integers."""

DEFAULT_SEED = 0
"""The seed of a Bezier surface and of generate's random draws (hinge stiffnesses, the
random criterion's order) when none is given."""


def check_seed(seed, what: str = "seed") -> int:
    """``seed`` as an int. Raises ValueError ``"<what> must be a non-negative integer below
    2**63, got <seed>"`` for anything else (a bool, a float, a negative or too large number)."""
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise RigidfoldError(f"{what} must be a non-negative integer below 2**63, got {seed!r}")
    value = int(seed)
    if not 0 <= value < SEED_LIMIT:
        raise RigidfoldError(f"{what} must be a non-negative integer below 2**63, got {value}")
    return value
