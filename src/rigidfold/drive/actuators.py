"""The drives of a motion: every hinge as the single drive, pairs of hinges, cables.

By virtual work (quasi-static, the base clamped), a drive whose own coordinate q turns at
``dq/ds`` along the motion does the work the structure needs: its effort is
``P(s) / (dq/ds)`` with P the power per unit of s (:meth:`rigidfold.drive.energy.Energy.
power`: ``dU/ds`` plus the friction's dissipation).

* **A crease** e as the drive: q its fold angle, the torque ``tau_e = P / (drho_e/ds)``
  (N m, > 0 turning it towards valley). Where ``drho_e/ds`` vanishes (a *dead point*: the
  crease stops turning while others still move) the torque is unbounded and the drive loses
  control; a dead point is a state where the rate is below ``Settings.drive.dead_fraction``
  of its largest over the motion, or where it changes sign (:func:`control`). The peak is
  the largest |tau| away from dead points; the creases are ranked by it (lowest first).
* **The sign changes** of tau away from dead points are those of P: there the load turns
  from resisting the motion to driving it, and the motion runs away unless braked. The
  *brake zones* are where P < 0 deploying (and where ``dU/ds - D > 0`` folding back).
* **A pair** (a, b): the torques of least norm that do the work, ``tau = P g / |g|^2`` with
  ``g = (drho_a/ds, drho_b/ds)``: dead only where both creases stop at once. Searched where
  the best single crease has a dead point, among the ``Settings.drive.pair_candidates``
  best creases.
* **A cable** between vertices v, w, of length l: the tension ``T = -P / (dl/ds)`` (its
  work ``T (-dl)``), which must stay positive: a cable only pulls. Where T would be
  negative it would have to push (said, as zones of s); dead where dl/ds vanishes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigidfold.config import DEFAULTS, Settings


def control(
    rate: np.ndarray, *, reference: float | None = None, settings: Settings = DEFAULTS
) -> tuple[np.ndarray, np.ndarray]:
    """(ok (K, N) bool, still (N,) bool) of drives whose coordinates change at ``rate``
    (K, N) per unit of s: ``still`` a drive whose largest |rate| is below
    ``still_fraction`` of ``reference`` (default: the largest of all), which drives
    nothing; ``ok`` the states where a drive is in control: |rate| at least
    ``dead_fraction`` of its largest, and no sign change of the rate to the next or from
    the previous state."""
    mag = np.abs(rate)
    big = mag.max(axis=0, initial=0.0)
    top = float(big.max(initial=0.0)) if reference is None else float(reference)
    still = big <= settings.drive.still_fraction * top
    ok = (mag >= settings.drive.dead_fraction * big) & ~still
    flip = np.sign(rate[1:]) * np.sign(rate[:-1]) < 0
    ok[1:] &= ~flip
    ok[:-1] &= ~flip
    return ok, still


def crossings(values: np.ndarray, s: np.ndarray) -> list[tuple[float, int]]:
    """(s, k) of each sign change of ``values`` (K,) between states k and k + 1, s by
    linear interpolation, in order."""
    v = np.asarray(values, dtype=np.float64)
    out = []
    for k in np.flatnonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0).tolist():
        a, b = v[k], v[k + 1]
        out.append((float(s[k] + (s[k + 1] - s[k]) * a / (a - b)), k))
    return out


def zero_crossings(values: np.ndarray, s: np.ndarray, where: np.ndarray | None = None) -> list:
    """The s (sorted) where ``values`` (K,) changes sign between two states, by linear
    interpolation; only between states both ``where`` (K,) bool when given."""
    return [at for at, k in crossings(values, s) if where is None or (where[k] and where[k + 1])]


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) state of each run of True in ``mask`` (K,)."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def zones(values: np.ndarray, s: np.ndarray, negative: bool = True) -> list[tuple[float, float]]:
    """The intervals of s where ``values`` (K,) is negative (``negative``) or positive, their
    ends interpolated to the sign changes (0 and 1: the motion's ends)."""
    v = np.asarray(values, dtype=np.float64)
    mask = v < 0 if negative else v > 0
    out = []
    for a, b in runs(mask):
        lo = float(s[a]) if a == 0 else _cross(v, s, a - 1)
        hi = float(s[b]) if b == len(v) - 1 else _cross(v, s, b)
        out.append((lo, hi))
    return out


def _cross(v: np.ndarray, s: np.ndarray, k: int) -> float:
    a, b = v[k], v[k + 1]
    if a == b:
        return float(s[k])
    return float(s[k] + (s[k + 1] - s[k]) * a / (a - b))


def dead_points(ok: np.ndarray, rate: np.ndarray, s: np.ndarray) -> list[float]:
    """The s of each dead point of one drive: each run of states out of control (``ok``
    (K,) False, not ``still``), at the rate's sign change within it where there is one, else
    where |rate| (K,) is least."""
    out = []
    for a, b in runs(~ok):
        lo, hi = max(a - 1, 0), min(b + 1, len(s) - 1)
        zero = zero_crossings(rate[lo : hi + 1], s[lo : hi + 1])
        if zero:
            out.append(zero[0])
        else:
            out.append(float(s[a + int(np.argmin(np.abs(rate[a : b + 1])))]))
    return out


def peaks(effort: np.ndarray, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(peak (N,), at (N,) int): the largest |effort| (K, N) of each drive over its states
    in control (``ok`` (K, N)); NaN and -1 for a drive never in control."""
    masked = np.where(ok, np.abs(effort), -1.0)
    at = np.argmax(masked, axis=0)
    peak = masked[at, np.arange(masked.shape[1])]
    never = peak < 0
    return np.where(never, np.nan, peak), np.where(never, -1, at)


@dataclass(frozen=True)
class Actuator:
    """One drive and its effort along the motion.

    kind : ``"crease"``, ``"pair"`` or ``"cable"``; ids : the crease's edge (one), the
    pair's two edges, or the cable's two vertices.
    effort : (K,) torque (N m; a pair (2, K)) or tension (N) at each state, deploying.
    coordinate : (K,) the fold angle (radians; a pair (2, K)) or the cable's length (m).
    peak : the largest |effort| in control (NaN: never in control); peak_s its s.
    dead : the s of its dead points; sign_changes : where its effort changes sign in
    control; push : the zones of s where a cable would have to push.
    """

    kind: str
    ids: tuple[int, ...]
    effort: np.ndarray = field(repr=False)
    coordinate: np.ndarray = field(repr=False)
    peak: float
    peak_s: float
    dead: tuple[float, ...]
    sign_changes: tuple[float, ...]
    push: tuple[tuple[float, float], ...] = ()
    still: bool = False

    @property
    def controls(self) -> bool:
        """It drives the whole motion: no dead point, never still, a cable never pushes."""
        return not self.still and not self.dead and not self.push and np.isfinite(self.peak)

    @property
    def name(self) -> str:
        """``crease 217``, ``pair 12+40``, ``cable 4-77``."""
        sep = {"crease": "", "pair": "+", "cable": "-"}[self.kind]
        return f"{self.kind} {sep.join(str(i) for i in self.ids)}"

    def to_dict(self) -> dict:
        unit = "peak_N" if self.kind == "cable" else "peak_Nm"
        key = "vertices" if self.kind == "cable" else "edges"
        data: dict = {
            "kind": self.kind,
            key: list(self.ids),
            unit: None if not np.isfinite(self.peak) else float(self.peak),
            "peak_s": None if not np.isfinite(self.peak) else self.peak_s,
            "dead_points": list(self.dead),
            "sign_changes": list(self.sign_changes),
            "controls": self.controls,
        }
        if self.kind == "cable":
            data["push_zones"] = [list(z) for z in self.push]
        if self.still:
            data["still"] = True
        return data


def crease_drives(
    rate: np.ndarray,
    fold: np.ndarray,
    power: np.ndarray,
    s: np.ndarray,
    edges: np.ndarray,
    *,
    settings: Settings = DEFAULTS,
) -> list[Actuator]:
    """Every hinge as the single drive (``rate`` (K, H) and ``fold`` (K, H) its fold angle's
    rate and value, ``power`` (K,) P, ``edges`` (H,) its crease), ranked by peak, lowest
    first (those never in control last)."""
    ok, still = control(rate, settings=settings)
    with np.errstate(divide="ignore", invalid="ignore"):
        torque = power[:, None] / rate
    peak, at = peaks(torque, ok)
    changes = zero_crossings(power, s)
    out = []
    for h in range(rate.shape[1]):
        dead = () if still[h] else tuple(dead_points(ok[:, h], rate[:, h], s))
        inside = tuple(c for c in changes if _in_control(c, s, ok[:, h]))
        out.append(
            Actuator(
                "crease",
                (int(edges[h]),),
                torque[:, h],
                fold[:, h],
                float(peak[h]),
                float(s[at[h]]) if at[h] >= 0 else float("nan"),
                dead,
                inside,
                still=bool(still[h]),
            )
        )
    return sorted(out, key=_rank_key)


def _rank_key(a: Actuator) -> tuple:
    return (not np.isfinite(a.peak), a.peak if np.isfinite(a.peak) else 0.0, a.ids)


def _in_control(at: float, s: np.ndarray, ok: np.ndarray) -> bool:
    k = int(np.clip(np.searchsorted(s, at) - 1, 0, len(s) - 2))
    return bool(ok[k] and ok[k + 1])


def best_pair(
    ranking: list[Actuator],
    rate: np.ndarray,
    fold: np.ndarray,
    edges: np.ndarray,
    power: np.ndarray,
    s: np.ndarray,
    *,
    settings: Settings = DEFAULTS,
) -> Actuator | None:
    """The pair of creases of the smallest peak that drives the whole motion (no state where
    both stop), among the ``pair_candidates`` best of ``ranking`` (those not still), with
    the torques of least norm (see the module's text); ``rate`` and ``fold`` (K, H) the
    hinges' rates and fold angles, ``edges`` (H,) their creases. None when no pair does."""
    index = {int(e): h for h, e in enumerate(edges.tolist())}
    chosen = [index[a.ids[0]] for a in ranking if not a.still and a.ids[0] in index]
    chosen = chosen[: settings.drive.pair_candidates]
    if len(chosen) < 2:
        return None
    i, j = np.triu_indices(len(chosen), 1)
    a, b = np.asarray(chosen)[i], np.asarray(chosen)[j]
    ra, rb = rate[:, a], rate[:, b]  # (K, n)
    g = np.sqrt(ra**2 + rb**2)
    big = g.max(axis=0)
    ok = g >= settings.drive.dead_fraction * big
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = power[:, None] * ra / g**2
        tb = power[:, None] * rb / g**2
    effort = np.maximum(np.abs(ta), np.abs(tb))
    whole = ok.all(axis=0)
    if not whole.any():
        return None
    peak, at = peaks(effort, ok)
    peak = np.where(whole, peak, np.inf)
    p = int(np.argmin(peak))
    changes = tuple(zero_crossings(power, s))
    return Actuator(
        "pair",
        (int(edges[a[p]]), int(edges[b[p]])),
        np.vstack([ta[:, p], tb[:, p]]),
        np.vstack([fold[:, a[p]], fold[:, b[p]]]),
        float(peak[p]),
        float(s[at[p]]),
        (),
        changes,
    )


def cable_lengths(coords: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(K, n) the distance between the vertices of each of ``pairs`` (n, 2) at each state of
    ``coords`` (K, V, 3)."""
    if not len(pairs):
        return np.zeros((len(coords), 0))
    return np.linalg.norm(coords[:, pairs[:, 1]] - coords[:, pairs[:, 0]], axis=-1)


def cable_drives(
    lengths: np.ndarray,
    pairs: np.ndarray,
    power: np.ndarray,
    s: np.ndarray,
    *,
    reference: float | None = None,
    settings: Settings = DEFAULTS,
) -> list[Actuator]:
    """The cables between ``pairs`` (n, 2) of vertices, of ``lengths`` (K, n) along the
    motion, with their tension ``-P / (dl/ds)`` (see the module's text), in the order given;
    ``reference``: the largest |dl/ds| a cable that does not move is measured against
    (default: these cables' largest)."""
    from rigidfold.drive.energy import derivative

    if not len(pairs):
        return []
    rate = derivative(lengths.T, s).T
    if reference is None:
        reference = float(np.abs(rate).max(initial=0.0)) if rate.size else 0.0
    ok, still = control(rate, reference=reference, settings=settings)
    with np.errstate(divide="ignore", invalid="ignore"):
        tension = -power[:, None] / rate
    peak, at = peaks(np.where(tension > 0, tension, 0.0), ok)
    out = []
    for c in range(len(pairs)):
        pushes = np.where(ok[:, c], tension[:, c], 1.0)
        push = tuple(zones(pushes, s, negative=True)) if not still[c] else ()
        dead = () if still[c] else tuple(dead_points(ok[:, c], rate[:, c], s))
        inside = tuple(x for x in zero_crossings(tension[:, c], s, ok[:, c]))
        out.append(
            Actuator(
                "cable",
                (int(pairs[c, 0]), int(pairs[c, 1])),
                tension[:, c],
                lengths[:, c],
                float(peak[c]),
                float(s[at[c]]) if at[c] >= 0 else float("nan"),
                dead,
                inside,
                push,
                still=bool(still[c]),
            )
        )
    return out


def auto_cable_pairs(
    pattern, panel_vertices: tuple[np.ndarray, ...], settings: Settings
) -> np.ndarray:
    """(n, 2) int: the pairs of boundary vertices ``--cables auto`` tries: every pair of at
    most ``auto_cable_vertices`` of them (spread evenly along the boundary), but pairs on
    one panel (``panel_vertices``: the vertices of each; their distance never changes)."""
    import scipy.sparse as sp

    loop = np.asarray(pattern.boundary_vertices, dtype=np.int64)
    most = settings.drive.auto_cable_vertices
    if len(loop) > most:
        loop = loop[np.linspace(0, len(loop) - 1, most).round().astype(np.int64)]
    i, j = np.triu_indices(len(loop), 1)
    pairs = np.column_stack([loop[i], loop[j]])
    rows = np.concatenate(panel_vertices) if panel_vertices else np.zeros(0, dtype=np.int64)
    cols = np.repeat(np.arange(len(panel_vertices)), [len(v) for v in panel_vertices])
    incidence = sp.csr_matrix(
        (np.ones(len(rows)), (rows, cols)), shape=(pattern.n_vertices, len(panel_vertices))
    )
    shared = np.asarray(incidence[pairs[:, 0]].multiply(incidence[pairs[:, 1]]).sum(axis=1))
    return pairs[shared.ravel() == 0]


def best_cables(
    coords: np.ndarray,
    pairs: np.ndarray,
    power: np.ndarray,
    s: np.ndarray,
    count: int,
    *,
    settings: Settings = DEFAULTS,
    budget: int = 2_000_000,
) -> list[Actuator]:
    """The ``count`` best cables among ``pairs`` (n, 2) of vertices of the states ``coords``
    (K, V, 3): those that drive the whole motion (never push, no dead point) by their peak
    tension, then the others by peak. The pairs are taken a few at a time (``budget``
    numbers, pairs x states, at once), only the best kept."""
    if not len(pairs) or count <= 0:
        return []
    lengths = cable_lengths(coords, pairs)
    from rigidfold.drive.energy import derivative

    reference = float(np.abs(derivative(lengths.T, s)).max(initial=0.0))
    step = max(1, budget // max(len(s), 1))
    good: list[Actuator] = []
    rest: list[Actuator] = []
    for lo in range(0, len(pairs), step):
        some = cable_drives(
            lengths[:, lo : lo + step],
            pairs[lo : lo + step],
            power,
            s,
            reference=reference,
            settings=settings,
        )
        good = sorted(good + [c for c in some if c.controls], key=_rank_key)[:count]
        rest = sorted(rest + [c for c in some if not c.controls and not c.still], key=_rank_key)
        rest = rest[:count]
    return (good + rest)[:count]
