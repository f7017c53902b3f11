"""Every pair of thick solids over the whole folding motion: apart, or touching only at a hinge.

**Neighbours** (panels joined by a hinge) turn about the hinge's axis relative to each other,
so their relative position is the hinge's fold alone. Seen around the axis line, each solid
lies within a wedge at its surface (:attr:`rigidfold.fabricate.solids.Solids.fold_limit`),
so the two meet only along the axis exactly while the hinge's closing fold stays below
that limit. The check compares the fold at every frame with the limit: the *hinge margin*
(limit minus fold, radians). Between two frames the relative turn of two neighbours is
interpolated at a constant rate about their axis, so the fold there lies between the two
frames' and the margin over the whole motion is the smallest at the frames.

**Other pairs** must keep ``clearance`` (metres) at every point of the motion. At each frame,
a pair whose bounding spheres are more than ``clearance + thickness`` apart is apart by that
bound; closer pairs get their exact distance, the least over their convex pieces (GJK and
EPA of python-fcl, negative when they overlap: the depth). Between two frames the relative
motion of the pair (the second solid seen from the first) is interpolated at a constant
rate, a turn about a fixed axis by the angle ``theta`` while the second solid's centre moves
on a straight line by ``|dc|``: no point of the second solid moves more than
``eps = |dc| / 2 + 2 r sin(theta / 4)`` (``r``: its bounding radius) from where it is at the
nearer of the two frames. So the gap over the interval is at least ``min(d_0, d_1) - eps``
for gaps (or lower bounds) ``d_0``, ``d_1`` at its ends. Where that does not prove the
clearance, the interval is halved (its midpoint checked exactly), up to ``subdivisions``
times. The *bound* is the least proven gap over every pair and interval; the motion is
collision-free when it is at least ``clearance`` and every hinge margin is >= 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rigidfold.fabricate.motion import PanelMotion
from rigidfold.fabricate.solids import Solids
from rigidfold.runtime.interrupts import held_import


@dataclass(frozen=True)
class Meeting:
    """Where two solids come too close.

    panels : (a, b), a < b; fraction : the fraction folded where they first meet, the first
    frame (or midpoint) of the motion that is too close (0 flat, 1 the design);
    kind : ``"hinge"`` (neighbours past their fold limit: ``amount`` radians past it at
    worst) or ``"gap"`` (other solids closer than the clearance: ``amount`` the smallest gap,
    metres, 0 where they touch or overlap); worst : the fraction folded of that worst
    ``amount``; vertex : the vertex both panels have nearest to where they meet, or -1.
    """

    panels: tuple[int, int]
    fraction: float
    kind: str
    amount: float
    vertex: int = -1
    worst: float = math.nan

    def describe(self) -> str:
        a, b = self.panels
        at = f"at {100 * self.fraction:.0f}% folded"
        if self.kind == "hinge":
            return (
                f"panels {a} and {b} meet beyond their hinge {at} (folded "
                f"{math.degrees(self.amount):.2f} degrees past the bevels' limit)"
            )
        what = (
            "they touch or overlap"
            if self.amount <= 0
            else f"they come within {self.amount * 1e3:.1f} mm"
        )
        if not math.isnan(self.worst) and round(100 * self.worst) != round(100 * self.fraction):
            what += f" at {100 * self.worst:.0f}% folded"
        return f"panels {a} and {b} meet {at} (closer than the clearance: {what})"

    def to_dict(self) -> dict:
        return {
            "panels": list(self.panels),
            "fraction": self.fraction,
            "kind": self.kind,
            "amount": self.amount,
            "worst_fraction": self.worst,
            "vertex": self.vertex,
        }


@dataclass(frozen=True, eq=False)
class Clearance:
    """The check of every pair of solids over the motion.

    min_gap : smallest distance between solids that are not neighbours at a checked frame or
        midpoint, metres (inf when there is no such pair); gap_panels, gap_fraction : where.
    bound : smallest gap between them proven over the whole motion (see the module's text).
    hinge_margin : smallest (fold limit - closing fold) over hinges and frames, radians;
        hinge_panels, hinge_fraction : where.
    frames : frames of the motion checked; midpoints : intervals halved;
    distance_queries : exact distances between convex pieces computed.
    clearance : the gap required, metres.
    meetings : every pair that comes too close, the worst first (one entry per pair).
    """

    min_gap: float
    gap_panels: tuple[int, int]
    gap_fraction: float
    bound: float
    hinge_margin: float
    hinge_panels: tuple[int, int]
    hinge_fraction: float
    frames: int
    midpoints: int
    distance_queries: int
    clearance: float
    meetings: tuple[Meeting, ...] = field(default=())

    @property
    def collision_free(self) -> bool:
        return not self.meetings and self.bound >= self.clearance and self.hinge_margin >= 0

    def to_dict(self) -> dict:
        return {
            "collision_free": self.collision_free,
            "min_gap_m": self.min_gap,
            "min_gap_panels": list(self.gap_panels),
            "min_gap_fraction": self.gap_fraction,
            "proven_gap_m": self.bound,
            "required_gap_m": self.clearance,
            "hinge_margin_deg": math.degrees(self.hinge_margin),
            "hinge_margin_panels": list(self.hinge_panels),
            "hinge_margin_fraction": self.hinge_fraction,
            "frames_checked": self.frames,
            "midpoints_checked": self.midpoints,
            "distance_queries": self.distance_queries,
            "meetings": [m.to_dict() for m in self.meetings],
        }


class _Distances:
    """Exact distances between two solids (or some of their pieces) in a relative position,
    through python-fcl."""

    def __init__(self, solids: Solids) -> None:
        self.fcl = fcl = held_import("fcl")
        # unsigned: libccd's penetration depth (EPA) aborts the process on some touching
        # configurations (fcl throws std::logic_error through the binding)
        self.request = fcl.DistanceRequest(enable_nearest_points=True)
        self.objects = []
        self.of_panel: list[list[int]] = [[] for _ in range(solids.panels.n)]
        for i, piece in enumerate(solids.pieces):
            tris = piece.triangles
            faces = np.hstack([np.full((len(tris), 1), 3), tris]).ravel()
            shape = fcl.Convex(piece.vertices, len(tris), faces)
            self.objects.append(fcl.CollisionObject(shape, fcl.Transform()))
            self.of_panel[piece.panel].append(i)
        self.centres = np.asarray([piece.centre for piece in solids.pieces]).reshape(-1, 3)
        self.radii = np.asarray([piece.radius for piece in solids.pieces])
        self.identity = fcl.Transform()
        self.queries = 0
        self.cache: dict[_Pair, np.ndarray] = {}

    def gap(self, pair: _Pair, rot: np.ndarray, shift: np.ndarray) -> tuple[float, np.ndarray]:
        """(distance, point): the signed distance between the pieces of ``pair`` (solid a in
        the design, solid b moved by ``x -> rot @ x + shift``), and the nearest point on a."""
        fcl = self.fcl
        best, where = math.inf, np.zeros(3)
        moved = fcl.Transform(rot, shift)
        both = self.cache.get(pair)
        if both is None:
            both = self.cache[pair] = pair.pieces(self.of_panel)
        ia, ib = both.T
        diff = self.centres[ia] - self.centres[ib] @ rot.T - shift
        lower = np.sqrt(np.einsum("ij,ij->i", diff, diff)) - self.radii[ia] - self.radii[ib]
        for n in np.argsort(lower).tolist():
            if lower[n] >= best:
                break
            pa, pb = int(ia[n]), int(ib[n])
            oa, ob = self.objects[pa], self.objects[pb]
            oa.setTransform(self.identity)
            ob.setTransform(moved)
            result = fcl.DistanceResult()
            d = max(fcl.distance(oa, ob, self.request, result), 0.0)  # -1: they overlap
            self.queries += 1
            if d < best:
                best, where = d, np.asarray(result.nearest_points[0], dtype=np.float64)
        return best, where


@dataclass(frozen=True)
class _Pair:
    """Two solids whose pieces must keep the clearance: all of them (panels that are not
    neighbours), or, for neighbours, those that reach around their hinge's axis
    (``around_a`` of a against all of b, and the rest of a against ``around_b``)."""

    a: int
    b: int
    around_a: frozenset | None = None
    around_b: frozenset | None = None

    def pieces(self, of_panel: list[list[int]]) -> np.ndarray:
        """(n, 2) int: the pairs of pieces (indices into ``Solids.pieces``) to check."""
        pa, pb = of_panel[self.a], of_panel[self.b]
        if self.around_a is None or self.around_b is None:
            out = [(i, j) for i in pa for j in pb]
        else:
            out = [(i, j) for i in pa for j in pb if i in self.around_a or j in self.around_b]
        return np.asarray(out, dtype=np.int64).reshape(-1, 2)


def _near_pairs(solids: Solids, motion: PanelMotion, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(a (n,), b (n,)), a < b: the pairs of solids whose bounding spheres come within
    ``reach`` of each other over some interval of the motion, by the bound of
    :meth:`_GapCheck._prefilter` made the same for every pair (the largest radius and
    move), found at each frame with a k-d tree (``scipy.spatial.cKDTree.query_pairs``):
    about the solids times the frames times log the solids, never every pair. Every pair
    it leaves out is proven at least ``reach`` apart over the whole motion."""
    from scipy.spatial import cKDTree

    n, k = solids.panels.n, motion.n_frames
    if n < 2 or k == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    centres = np.einsum("kpij,pj->kpi", motion.rotations, solids.centres) + motion.translations
    r = float(solids.radii.max(initial=0.0))
    if k > 1:
        turn = np.linalg.norm(_turn(motion.rotations[:-1], motion.rotations[1:]), axis=-1)
        moved = np.linalg.norm(np.diff(centres, axis=0), axis=2)
        eps = _move_bound(moved, turn, solids.radii[None]).max(axis=1)  # (K - 1,)
        around = np.maximum(np.concatenate([eps, eps[-1:]]), np.concatenate([eps[:1], eps]))
    else:
        around = np.zeros(1)
    found = set()
    for i in range(k):
        tree = cKDTree(centres[i])
        found |= tree.query_pairs(2 * r + 2 * float(around[i]) + reach)
    if not found:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    pairs = np.array(sorted(found), dtype=np.int64)
    return pairs[:, 0], pairs[:, 1]


def _relative(motion: PanelMotion, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rot (K, n, 3, 3), shift (K, n, 3)): solid b seen from solid a (in a's design place) at
    every frame, for pairs a, b (n,)."""
    ra, rb = motion.rotations[:, a], motion.rotations[:, b]
    ta, tb = motion.translations[:, a], motion.translations[:, b]
    rot = np.einsum("knji,knjl->knil", ra, rb)
    shift = np.einsum("knji,knj->kni", ra, tb - ta)
    return rot, shift


def _turn(rot0: np.ndarray, rot1: np.ndarray) -> np.ndarray:
    """(..., 3) rotation vector of ``rot0^T rot1`` (..., 3, 3)."""
    from scipy.spatial.transform import Rotation

    rel = np.einsum("...ji,...jl->...il", rot0, rot1)
    flat = rel.reshape(-1, 3, 3)
    if not len(flat):
        return np.zeros((*rel.shape[:-2], 3))
    return Rotation.from_matrix(flat).as_rotvec().reshape(*rel.shape[:-2], 3)


def _rotation(vector: np.ndarray) -> np.ndarray:
    """(3, 3) rotation matrix of the rotation vector ``vector`` (3,) (Rodrigues' formula;
    what ``scipy.spatial.transform.Rotation.from_rotvec(...).as_matrix()`` gives, without
    its overhead for one small rotation)."""
    x, y, z = (float(v) for v in vector)
    angle = math.sqrt(x * x + y * y + z * z)
    if angle < 1e-8:  # second order: I + K + K^2 / 2
        k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
        return np.eye(3) + k + 0.5 * (k @ k)
    x, y, z = x / angle, y / angle, z / angle
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _move_bound(moved: np.ndarray, turn: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """How far a point of a solid of bounding ``radius`` moves from the nearer end of an
    interval in which its centre moves by ``moved`` on a line and it turns by ``turn``
    radians at a constant rate."""
    return moved / 2 + 2 * radius * np.sin(np.minimum(turn, math.pi) / 4)


def check_clearance(
    solids: Solids,
    motion: PanelMotion,
    *,
    clearance: float,
    subdivisions: int,
) -> Clearance:
    """Check every pair of ``solids`` over ``motion`` (see the module's text)."""
    hinge = _check_hinges(solids, motion)
    gaps = _GapCheck(solids, motion, clearance, subdivisions)
    meetings = {m.panels: m for m in gaps.meetings()}
    for m in hinge[3]:
        meetings[m.panels] = m  # past a hinge's limit: the graver
    ordered = sorted(
        meetings.values(),
        key=lambda m: (m.kind != "hinge", -m.amount if m.kind == "hinge" else m.amount),
    )
    return Clearance(
        min_gap=gaps.min_gap,
        gap_panels=gaps.min_panels,
        gap_fraction=gaps.min_fraction,
        bound=gaps.bound,
        hinge_margin=hinge[0],
        hinge_panels=hinge[1],
        hinge_fraction=hinge[2],
        frames=motion.n_frames,
        midpoints=gaps.midpoints,
        distance_queries=gaps.dist.queries,
        clearance=clearance,
        meetings=tuple(ordered),
    )


def _check_hinges(
    solids: Solids, motion: PanelMotion
) -> tuple[float, tuple[int, int], float, list[Meeting]]:
    """(smallest margin, its panels, its fraction, meetings) of the hinges: each hinge's fold
    limit minus its closing fold at every frame."""
    panels = solids.panels
    if not panels.n_hinges:
        return math.inf, (-1, -1), math.nan, []
    margin = solids.fold_limit[None, :] - motion.closing
    i, worst = (int(x) for x in np.unravel_index(int(np.argmin(margin)), margin.shape))
    a, b = sorted(int(x) for x in panels.hinge_panels[worst])
    least = (float(margin[i, worst]), (a, b), float(motion.fraction[i]))
    meetings: dict[tuple[int, int], Meeting] = {}
    for h in np.flatnonzero((margin < 0).any(axis=0)).tolist():
        first = int(np.flatnonzero(margin[:, h] < 0)[0])
        a, b = sorted(int(x) for x in panels.hinge_panels[h])
        past = float(-margin[:, h].min())
        at_worst = float(motion.fraction[int(np.argmin(margin[:, h]))])
        if (a, b) not in meetings or past > meetings[(a, b)].amount:
            meetings[(a, b)] = Meeting(
                (a, b), float(motion.fraction[first]), "hinge", past, worst=at_worst
            )
    return (*least, list(meetings.values()))


class _GapCheck:
    """The gaps between solids that are not neighbours, over the motion."""

    def __init__(
        self, solids: Solids, motion: PanelMotion, clearance: float, subdivisions: int
    ) -> None:
        self.solids, self.motion = solids, motion
        self.clearance, self.subdivisions = clearance, subdivisions
        self.dist = _Distances(solids)
        self.midpoints = 0
        # (gap, fraction, nearest point on the first solid in the design) of the smallest
        # exact distance below the clearance, per pair, and the least fraction folded of
        # such a distance (where the pair first meets)
        self.close: dict[tuple[int, int], tuple[float, float, np.ndarray]] = {}
        self.first: dict[tuple[int, int], float] = {}
        self.min_gap, self.min_panels, self.min_fraction = math.inf, (-1, -1), math.nan
        panels = solids.panels
        n = panels.n
        ia, ib = _near_pairs(solids, motion, clearance + solids.thickness)
        keys = ia * n + ib
        if len(panels.neighbours):
            a, b = np.sort(panels.neighbours, axis=1).T
            keys_joined = a.astype(np.int64) * n + b
        else:
            keys_joined = np.zeros(0, dtype=np.int64)
        self.left_out = len(ia) < n * (n - 1) // 2
        keep = ~np.isin(keys, keys_joined) & (solids.radii[ia] > 0) & (solids.radii[ib] > 0)
        pairs = [_Pair(int(a), int(b)) for a, b in zip(ia[keep], ib[keep], strict=True)]
        for h, (wrap_a, wrap_b) in enumerate(solids.hinge_limits[1]):
            if wrap_a or wrap_b:
                a, b = (int(x) for x in panels.hinge_panels[h])
                pairs.append(_Pair(a, b, wrap_a, wrap_b))
        self.pairs = pairs
        self.ia = np.asarray([q.a for q in pairs], dtype=np.int64)
        self.ib = np.asarray([q.b for q in pairs], dtype=np.int64)
        # the pairs never near (:func:`_near_pairs`) are at least this far apart
        self.bound = clearance + solids.thickness if self.left_out else math.inf
        if len(self.ia):
            self._run()

    def _exact(self, j: int, rot: np.ndarray, shift: np.ndarray, fraction: float) -> float:
        a, b = sorted((int(self.ia[j]), int(self.ib[j])))
        gap, point = self.dist.gap(self.pairs[j], rot, shift)
        if gap < self.min_gap:
            self.min_gap, self.min_panels, self.min_fraction = gap, (a, b), fraction
        if gap < self.clearance:
            self.first[(a, b)] = min(self.first.get((a, b), math.inf), fraction)
            if (a, b) not in self.close or gap < self.close[(a, b)][0]:
                self.close[(a, b)] = (gap, fraction, point)
        return gap

    def _prefilter(self) -> None:
        """Drop the pairs whose bounding spheres stay apart by more than the clearance over
        every interval, each solid's own motion bounded in the world (cheap: per panel, not
        per pair)."""
        solids, motion = self.solids, self.motion
        centres = np.einsum("kpij,pj->kpi", motion.rotations, solids.centres)
        centres += motion.translations
        ia, ib = self.ia, self.ib
        lower = np.linalg.norm(centres[:, ia] - centres[:, ib], axis=2)
        lower -= (solids.radii[ia] + solids.radii[ib])[None]
        if motion.n_frames > 1:
            turn = np.linalg.norm(_turn(motion.rotations[:-1], motion.rotations[1:]), axis=-1)
            moved = np.linalg.norm(np.diff(centres, axis=0), axis=2)
            eps = _move_bound(moved, turn, solids.radii[None])
            proven = np.minimum(lower[:-1], lower[1:]) - eps[:, ia] - eps[:, ib]
        else:
            proven = lower
        near = (proven < self.clearance + solids.thickness).any(axis=0)
        far = proven[:, ~near]
        self.bound = min(self.bound, float(far.min()) if far.size else math.inf)
        self.pairs = [q for q, keep in zip(self.pairs, near, strict=True) if keep]
        self.ia, self.ib = ia[near], ib[near]

    def _run(self) -> None:
        solids, motion = self.solids, self.motion
        frac = motion.fraction
        self._prefilter()
        ia, ib = self.ia, self.ib
        if not len(ia):
            return
        rot, shift = _relative(motion, ia, ib)
        self.centre_b = solids.centres[ib]
        cb = np.einsum("knij,nj->kni", rot, self.centre_b) + shift  # b's centre seen from a
        lower = np.linalg.norm(cb - solids.centres[ia][None], axis=2)
        lower -= (solids.radii[ia] + solids.radii[ib])[None]
        known = lower.copy()
        exact = np.zeros(lower.shape, dtype=bool)
        if motion.n_frames < 2:
            for j in np.flatnonzero(lower[0] < self.clearance + solids.thickness).tolist():
                known[0, j] = self._exact(j, rot[0, j], shift[0, j], float(frac[0]))
            self.bound = min(self.bound, float(known.min()))
            return
        turn_vec = _turn(rot[:-1], rot[1:])  # (K - 1, n, 3): b's turn seen from a
        turn = np.linalg.norm(turn_vec, axis=-1)
        moved = np.linalg.norm(np.diff(cb, axis=0), axis=2)
        radius = solids.radii[ib][None]
        eps = _move_bound(moved, turn, radius)
        # the most any point of b moves relative to a over a whole interval
        sweep = moved + 2 * radius * np.sin(np.minimum(turn, math.pi) / 2)
        # walk the frames: measure a pair only where the bound carried from its last
        # measurement (minus its moves since) and its spheres' gap both fall below what its
        # two intervals need
        need = self.clearance + np.maximum(np.vstack([eps, eps[-1:]]), np.vstack([eps[:1], eps]))
        carried = np.full(len(ia), -np.inf)
        for k in range(motion.n_frames):
            if k:
                carried -= sweep[k - 1]
            known[k] = np.maximum(lower[k], carried)
            for j in np.flatnonzero(known[k] < need[k]).tolist():
                known[k, j] = self._exact(j, rot[k, j], shift[k, j], float(frac[k]))
                exact[k, j] = True
                carried[j] = known[k, j]
        proven = np.minimum(known[:-1], known[1:]) - eps
        for k, j in zip(*np.nonzero(proven < self.clearance), strict=True):
            for m in (k, k + 1):
                if not exact[m, j]:
                    known[m, j] = self._exact(j, rot[m, j], shift[m, j], float(frac[m]))
                    exact[m, j] = True
            proven[k, j] = min(known[k, j], known[k + 1, j]) - eps[k, j]
            if proven[k, j] < self.clearance:
                proven[k, j] = self._halve(
                    j,
                    rot[k, j],
                    turn_vec[k, j],
                    (cb[k, j], cb[k + 1, j]),
                    (float(known[k, j]), float(known[k + 1, j])),
                    float(eps[k, j]),
                    (float(frac[k]), float(frac[k + 1])),
                    self.subdivisions,
                )
        self.bound = min(self.bound, float(proven.min()))

    def _halve(
        self,
        j: int,
        rot0: np.ndarray,
        step: np.ndarray,
        centres: tuple[np.ndarray, np.ndarray],
        ends: tuple[float, float],
        eps: float,
        fractions: tuple[float, float],
        depth: int,
    ) -> float:
        """The gap proven over one interval of pair j (b's rotation seen from a: ``rot0`` at
        its start, turned by the rotation vector ``step`` (3,) over it), halving it while
        the bound does not prove the clearance and both ends keep it (see the module's
        text). Each half turns by half the step about the same axis, so the turns are
        carried down, not measured again (a thin sheet halves thousands of intervals)."""
        proven = min(ends) - eps
        if proven >= self.clearance or depth <= 0 or min(ends) < self.clearance:
            return proven
        half_step = 0.5 * step
        rot = rot0 @ _rotation(half_step)
        c_mid = 0.5 * (centres[0] + centres[1])
        f_mid = 0.5 * (fractions[0] + fractions[1])
        mid = self._exact(j, rot, c_mid - rot @ self.centre_b[j], f_mid)
        self.midpoints += 1
        radius = self.solids.radii[self.ib[j]]
        half = float(
            _move_bound(
                np.asarray(np.linalg.norm(centres[1] - centres[0]) / 2),
                np.asarray(np.linalg.norm(step) / 2),
                radius,
            )
        )
        return min(
            self._halve(
                j,
                rot0,
                half_step,
                (centres[0], c_mid),
                (ends[0], mid),
                half,
                (fractions[0], f_mid),
                depth - 1,
            ),
            self._halve(
                j,
                rot,
                half_step,
                (c_mid, centres[1]),
                (mid, ends[1]),
                half,
                (f_mid, fractions[1]),
                depth - 1,
            ),
        )

    def meetings(self) -> list[Meeting]:
        """One :class:`Meeting` per pair closer than the clearance at a checked state."""
        out = []
        coords = self.solids.panels.pattern.coords
        for (a, b), (gap, fraction, point) in self.close.items():
            shared = self.solids.panels.shared_vertices(a, b)
            vertex = -1
            if len(shared):
                vertex = int(shared[np.argmin(np.linalg.norm(coords[shared] - point, axis=1))])
            out.append(Meeting((a, b), self.first[(a, b)], "gap", gap, vertex, fraction))
        return out
