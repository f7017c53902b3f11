"""Where the structure comes to rest when the drive lets go (quasi-static: no inertia).

Along its one-degree-of-freedom motion the released structure moves down its energy U(s):
towards flat where dU/ds > 0, towards the built end where dU/ds < 0. The *equilibria* are
the zeros of dU/ds inside the motion: stable where dU/ds turns from negative to positive (a
minimum of U), unstable at a maximum. The ends of the motion hold it too when U rises away
from them (flat when dU/ds(0) > 0, the built end when dU/ds(1) < 0; the motion beyond the
built design is not followed). Coulomb friction holds the structure wherever
``|dU/ds| <= D(s)`` (:mod:`rigidfold.drive.energy`).

:func:`released` gives, for the states grouped into intervals of s, where the structure goes
when released there: "released at 0.00-0.41 it falls back to flat; at 0.41-1.00 it comes to
rest at s = 0.73".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.drive.actuators import crossings


@dataclass(frozen=True)
class Equilibrium:
    """A state of rest of the released structure: ``s``, ``stable`` (a minimum of U),
    ``U_J`` the energy there, ``end``: ``"flat"`` or ``"built"`` at an end of the motion,
    else ``""``."""

    s: float
    stable: bool
    U_J: float
    end: str = ""

    def to_dict(self) -> dict:
        data: dict = {"s": self.s, "stable": self.stable, "U_J": self.U_J}
        if self.end:
            data["end"] = self.end
        return data


def equilibria(u: np.ndarray, slope: np.ndarray, s: np.ndarray) -> list[Equilibrium]:
    """The equilibria of U (``u`` (K,), ``slope`` (K,) dU/ds at ``s`` (K,)), in order of s
    (see the module's text)."""
    out = []
    if len(s) and slope[0] > 0:
        out.append(Equilibrium(float(s[0]), True, float(u[0]), "flat"))
    for at, k in crossings(slope, s):
        stable = slope[k] < 0  # and > 0 at k + 1: a minimum
        w = (at - s[k]) / (s[k + 1] - s[k])
        out.append(Equilibrium(at, bool(stable), float((1 - w) * u[k] + w * u[k + 1])))
    if len(s) and slope[-1] < 0:
        out.append(Equilibrium(float(s[-1]), True, float(u[-1]), "built"))
    return out


@dataclass(frozen=True)
class Release:
    """Released anywhere in ``[start, end]`` of s, the structure comes to rest at ``rest``
    (s); ``how``: ``"flat"`` (falls back to flat), ``"built"`` (goes on to the built end),
    ``"held"`` (friction holds it where it is released), ``"rest"`` (comes to rest at a
    stable state inside the motion)."""

    start: float
    end: float
    rest: float
    how: str

    def describe(self) -> str:
        where = f"{self.start:.2f}-{self.end:.2f}" if self.end > self.start else f"{self.start:.2f}"
        what = {
            "flat": "it falls back to flat",
            "built": "it goes on to the built end (s = 1)",
            "held": "friction holds it where it is",
            "rest": f"it comes to rest at s = {self.rest:.2f}",
        }[self.how]
        return f"released at {where} {what}"

    def to_dict(self) -> dict:
        return {"from_s": self.start, "to_s": self.end, "rest_s": self.rest, "how": self.how}


def released(slope: np.ndarray, friction: np.ndarray, s: np.ndarray) -> list[Release]:
    """Where the structure released at each state comes to rest (``slope`` (K,) dU/ds,
    ``friction`` (K,) D(s) >= 0, at ``s`` (K,)), the states grouped into intervals of the
    same end (see the module's text)."""
    n = len(s)
    if not n:
        return []
    down = slope > friction  # it moves towards flat
    up = slope < -friction  # towards the built end
    rest_down = np.empty(n, dtype=np.int64)
    for k in range(n):
        rest_down[k] = rest_down[k - 1] if down[k] and k > 0 else k
    rest_up = np.empty(n, dtype=np.int64)
    for k in range(n - 1, -1, -1):
        rest_up[k] = rest_up[k + 1] if up[k] and k < n - 1 else k
    rest = np.where(down, rest_down, np.where(up, rest_up, np.arange(n)))
    held = ~down & ~up
    out: list[Release] = []
    k = 0
    while k < n:
        j = k
        while j + 1 < n and held[j + 1] == held[k] and (held[k] or rest[j + 1] == rest[k]):
            j += 1
        r = int(rest[k])
        if held[k]:
            how, at = "held", float(s[k])
        else:
            how = "flat" if r == 0 else ("built" if r == n - 1 else "rest")
            at = float(s[r])
            if how == "rest":  # where the drive's balance crosses zero, between two states
                a, b = (r, r + 1) if down[k] else (r - 1, r)
                v = slope - friction if down[k] else slope + friction
                if v[a] != v[b]:
                    at = float(s[a] + (s[b] - s[a]) * v[a] / (v[a] - v[b]))
        out.append(Release(float(s[k]), float(s[j]), at, how))
        k = j + 1
    return out
