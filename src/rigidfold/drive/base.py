"""Where the structure is held: the base panel, clamped in its built pose, and the ground.

With panel b as the base, the motion is expressed in b's frame: every state is moved
rigidly so that b stands where it is built (:meth:`rigidfold.drive.motion.DriveMotion.
in_base`), and gravity acts along -z of the built design. The height of a vertex is then
``(R_b e_z) . (x - t_b)`` (R_b, t_b: the base's rotation and translation at the state), so
the lowest point of every placement at every state costs one product of the states' vertices
with the bases' z axes.

``--base auto`` takes the panel of the smallest peak effort (the best crease that drives
the whole motion, else the best crease away from its dead points) among the placements
whose motion keeps every vertex above the ground (within ``Settings.drive.ground_tol``); the
smallest effort of all where no placement keeps clear of the ground.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.drive.motion import DriveMotion


def lowest_points(motion: DriveMotion, ground: float) -> np.ndarray:
    """(B, K) float64: the height above ``ground`` of the lowest vertex at each state with
    each panel as the base (negative: below the ground)."""
    pm = motion.motion
    up = pm.rotations[:, :, :, 2]  # (K, B, 3)
    coords = motion.coords  # (K, V, 3)
    offset = np.einsum("kbi,kbi->kb", up, pm.translations)
    low = np.empty((up.shape[1], len(coords)))
    for k in range(len(coords)):
        axes = np.ascontiguousarray(up[k].T)  # (3, B): a strided one takes NumPy's slow path
        low[:, k] = (coords[k] @ axes).min(axis=0) - offset[k]
    return low - ground


@dataclass(frozen=True)
class Below:
    """A vertex that passes below the ground: its deepest point, ``depth`` m under the
    ground at ``s``."""

    vertex: int
    depth: float
    s: float

    def to_dict(self) -> dict:
        return {"vertex": self.vertex, "depth_m": self.depth, "s": self.s}


def below_ground(
    motion: DriveMotion, base: int, ground: float, *, settings: Settings = DEFAULTS
) -> list[Below]:
    """Every vertex that passes more than ``ground_tol`` below ``ground`` with ``base``
    clamped, deepest first."""
    z = motion.in_base(base)[:, :, 2]  # (K, V)
    depth = ground - z
    worst = depth.max(axis=0)
    at = depth.argmax(axis=0)
    out = [
        Below(int(v), float(worst[v]), float(motion.s[at[v]]))
        for v in np.flatnonzero(worst > settings.drive.ground_tol)
    ]
    return sorted(out, key=lambda b: (-b.depth, b.vertex))


@dataclass(frozen=True)
class Placement:
    """One panel as the base: ``effort`` the peak torque of its best crease (N m; NaN: no
    crease in control), ``edge`` that crease, ``controls`` whether it drives the whole
    motion, ``clearance`` the lowest height above the ground over the motion (m; < 0:
    below), ``clear`` whether every vertex stays above it."""

    panel: int
    effort: float
    edge: int
    controls: bool
    clearance: float
    clear: bool

    def to_dict(self) -> dict:
        return {
            "panel": self.panel,
            "peak_Nm": None if not np.isfinite(self.effort) else self.effort,
            "edge": self.edge if self.edge >= 0 else None,
            "controls": self.controls,
            "clearance_m": self.clearance,
            "clear": self.clear,
        }


def rank_bases(
    powers: np.ndarray,
    rate: np.ndarray,
    ok: np.ndarray,
    still: np.ndarray,
    edges: np.ndarray,
    low: np.ndarray,
    *,
    settings: Settings = DEFAULTS,
    budget: int = 4_000_000,
) -> list[Placement]:
    """Every panel as the base, ranked: clear of the ground first, then by effort (lowest
    first). ``powers`` (B, K) the drive's power per unit of s of each placement, ``rate``
    (K, H) the hinges' rates, ``ok`` (K, H) their states in control and ``still`` (H,)
    those that do not move (:func:`rigidfold.drive.actuators.control`: the same for every
    base, the rates do not depend on it), ``edges`` (H,) the hinges' creases, ``low``
    (B, K) (:func:`lowest_points`). The effort of a crease is ``|P| / |rate|`` at its states
    in control: the creases that drive the whole motion where there are any, else all;
    the bases are taken a few at a time, ``budget`` numbers (bases x states x creases) at
    once."""
    whole = ok.all(axis=0) & ~still
    controls = bool(whole.any())
    use = np.flatnonzero(whole if controls else ~still)
    n_bases = len(powers)
    effort = np.full(n_bases, np.nan)
    best = np.full(n_bases, -1, dtype=np.int64)
    if len(use):
        with np.errstate(divide="ignore"):
            inverse = np.where(ok[:, use], 1.0 / np.abs(rate[:, use]), 0.0)  # (K, n)
        never = ~ok[:, use].any(axis=0)
        size = np.abs(powers)
        chunk = max(1, budget // max(inverse.size, 1))
        for lo in range(0, n_bases, chunk):
            hi = min(lo + chunk, n_bases)
            peak = (size[lo:hi, :, None] * inverse[None]).max(axis=1)  # (c, n)
            peak[:, never] = np.inf
            j = np.argmin(peak, axis=1)
            effort[lo:hi] = peak[np.arange(hi - lo), j]
            best[lo:hi] = use[j]
    effort[~np.isfinite(effort)] = np.nan
    clearance = low.min(axis=1)
    clear = clearance >= -settings.drive.ground_tol
    out = [
        Placement(
            panel=b,
            effort=float(effort[b]),
            edge=int(edges[best[b]]) if best[b] >= 0 else -1,
            controls=bool(controls and best[b] >= 0),
            clearance=float(clearance[b]),
            clear=bool(clear[b]),
        )
        for b in range(n_bases)
    ]
    return sorted(
        out,
        key=lambda p: (
            not p.clear,
            not np.isfinite(p.effort),
            p.effort if np.isfinite(p.effort) else 0.0,
            p.panel,
        ),
    )
