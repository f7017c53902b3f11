"""Supports chosen for serviceability (``--supports service``).

``auto`` pins the fewest candidate vertices that make the design first-order rigid
(:func:`rigidfold.structure.supports.auto_supports`). Rigid is not stiff: a nearly flat
design on free hinges rests on the bending of its panels between a few pins, and deflects
metres where a roof may deflect centimetres (``docs/structure.md``). ``service`` starts from
``auto``'s set and, while the largest displacement exceeds the limit, pins the candidate
vertex that moves most (ties to the lower index, displacements compared to six
significant digits so that round-off cannot choose), one at a time, with a linear analysis
after each. Once the limit is met, each added pin is taken away again, in the order they
were added, where the rest still meet it, until every pin left has been tried against the
final set: without any one of them the limit is missed. The set is small, not necessarily
the smallest.
A search that pins every candidate, or ``Settings.structure.service_max_pins`` of them,
without meeting the limit says so: pins alone cannot carry the load within the limit
(stiffer hinges, thicker panels, or supports elsewhere can).

The search uses the linear analysis without natural frequencies; the set found is then
checked as asked (``--nonlinear``, ``--modes``).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mesh import CreasePattern
from rigidfold.structure.check import StructureCheck, StructureStatus
from rigidfold.structure.supports import (
    Rigidity,
    SupportGrowth,
    Supports,
    check_supports,
    support_modes,
)

Analyse = Callable[[Rigidity, float | None], StructureCheck]
"""The linear structure check of the design on the supports of a :class:`Rigidity`, with
hinges of the given stiffness (N m/rad per m; None: the design's own)."""


def vertex_displacements(check: StructureCheck) -> np.ndarray:
    """(V,) the largest displacement magnitude of the shell nodes at each vertex of the
    pattern, m (0 where it has none, or without a response)."""
    V = check.pattern.n_vertices
    out = np.zeros(V)
    if check.response is None or check.mesh is None:
        return out
    nodes = check.mesh.node_vertex >= 0
    np.maximum.at(out, check.mesh.node_vertex[nodes], check.magnitudes[nodes])
    return out


def _most_moved(check: StructureCheck, free: np.ndarray) -> int:
    """The vertex of ``free`` that moves most: displacements rounded to six significant
    digits of the largest, ties to the lowest index."""
    disp = vertex_displacements(check)[free]
    scale = float(disp.max(initial=0.0))
    if scale <= 0:
        return int(free[0])
    rounded = np.round(disp / scale, 6)
    return int(free[int(np.flatnonzero(rounded == rounded.max())[0])])


def grow_supports(
    pattern: CreasePattern,
    first: Rigidity,
    candidates: np.ndarray,
    analyse: Analyse,
    settings: Settings = DEFAULTS,
) -> tuple[StructureCheck, SupportGrowth]:
    """The linear check of the supports grown from ``first`` (see the module's text) and
    how they grew. ``candidates`` : (c,) int64 the vertices that may be pinned."""
    sup = first.supports
    rigid = np.asarray(sup.pinned, dtype=np.int64)
    trail: list[tuple[str, int, int, float, float]] = []
    modes = support_modes(sup.held(pattern), settings)  # one design: its free motions once

    def run(pins: list[int], step: str, vertex: int) -> StructureCheck:
        rigidity = (
            first
            if len(pins) == len(rigid)
            else check_supports(
                pattern,
                Supports(np.array(sorted(pins), np.int64), sup.clamped, sup.actuated),
                settings,
                modes,
            )
        )
        check = analyse(rigidity, None)
        trail.append((step, vertex, len(pins), check.max_displacement, check.allowed_displacement))
        return check

    pins = rigid.tolist()
    added: list[int] = []
    check = run(pins, "rigid", -1)
    pool = np.setdiff1d(np.asarray(candidates, dtype=np.int64), sup.clamped)
    while check.status is StructureStatus.DEFLECTION and len(added) < (
        settings.structure.service_max_pins
    ):
        free = np.setdiff1d(pool, pins)
        if not len(free):
            break
        v = _most_moved(check, free)
        pins.append(v)
        added.append(v)
        check = run(pins, "add", v)
    kept: set[int] = set()  # tried without, against the current set: needed
    while check.passed and (todo := [v for v in added if v not in kept]):
        for v in todo:
            trial = [p for p in pins if p != v]
            fewer = run(trial, "drop", v)
            if fewer.passed:
                pins, check = trial, fewer
                added.remove(v)
                kept.clear()  # a smaller set: the kept pins are tried again
            else:
                kept.add(v)
                _, vertex, n, largest, allowed = trail[-1]
                trail[-1] = ("keep", vertex, n, largest, allowed)
    searched = check.status is StructureStatus.DEFLECTION
    growth = SupportGrowth(
        rigid=rigid,
        added=np.array(added, dtype=np.int64),
        trail=tuple(trail),
        candidates=len(pool),
        passed=check.passed,
        hinge_hint=hinge_hint(check, analyse, settings) if searched else None,
        searched_hinges=searched,
    )
    return check, growth


def hinge_hint(
    check: StructureCheck, analyse: Analyse, settings: Settings = DEFAULTS
) -> tuple[float, float] | None:
    """(hinge stiffness N m/rad per m, its largest displacement m): about the least uniform
    stiffness of the free creases' hinges that meets the deflection limit on the supports of
    ``check`` (which misses it), two significant digits rounded up; None when even
    ``Settings.structure.hint_hinge_stiffness`` does not (or the design's own is that
    already). A bisection in log scale, ``hint_iterations`` steps, one linear analysis
    each, assuming stiffer hinges deflect less."""
    top = settings.structure.hint_hinge_stiffness
    own = check.hinge_stiffness
    if own >= top or not analyse(check.rigidity, top).passed:
        return None
    low, high = max(own, top * 1e-6), top
    if own < low and analyse(check.rigidity, low).passed:
        high = low
    else:
        for _ in range(settings.structure.hint_iterations):
            mid = math.sqrt(low * high)
            if analyse(check.rigidity, mid).passed:
                high = mid
            else:
                low = mid
    digit = 10.0 ** (math.floor(math.log10(high)) - 1)
    rounded = min(math.ceil(high / digit - 1e-9) * digit, top)
    named = analyse(check.rigidity, rounded)
    if not named.passed:  # not monotone after all: name the stiffness bisected to
        rounded, named = high, analyse(check.rigidity, high)
    return rounded, named.max_displacement
