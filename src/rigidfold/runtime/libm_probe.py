"""The part of the numerics canary that libm alone computes, runnable on its own:
``python -I -S libm_probe.py`` prints :func:`digest`, with nothing but the standard library
(no NumPy, not rigidfold), so that :mod:`rigidfold.runtime.numerics` can start a process with the
pinned libm and compare what it computes with this process's (whether this process's libm
is pinned is measured, not inferred from its environment)."""

from __future__ import annotations

import hashlib
import math
import struct


def canary_inputs(n: int = 4096) -> tuple[list[float], list[float]]:
    """Fixed inputs (no RNG of NumPy's: it must not depend on its version either): numbers
    in [-10, 10) and in [0, 1)."""
    xs, ps = [], []
    state = 0x2545F4914F6CDD1D
    for _ in range(n):
        state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        u = (state >> 11) / float(1 << 53)
        xs.append(20.0 * u - 10.0)
        ps.append((state >> 20) / float(1 << 44))
    return xs, ps


def update(h, xs: list[float], ps: list[float]) -> None:
    """Feed ``h`` the results of libm (through Python's ``math``, as CasADi's expressions use
    it) on the canary inputs: those of sin, cos, exp, atan, acos, log, atan2 and pow."""
    pairs = list(zip(xs, xs[1:] + xs[:1], strict=True))
    for f, data in (
        (math.sin, xs),
        (math.cos, xs),
        (math.exp, xs),
        (math.atan, xs),
        (math.acos, ps),
        (math.log, ps),
    ):
        h.update(struct.pack(f"{len(data)}d", *map(f, data)))
    h.update(struct.pack(f"{len(pairs)}d", *(math.atan2(a, b) for a, b in pairs)))
    h.update(struct.pack(f"{len(xs)}d", *(math.pow(p, x) for p, x in zip(ps, xs, strict=True))))


def digest() -> str:
    """Hash of libm's results on the canary inputs."""
    h = hashlib.sha256()
    update(h, *canary_inputs())
    return h.hexdigest()[:16]


if __name__ == "__main__":
    print(digest())
