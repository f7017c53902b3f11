"""The time budget of a run with a time limit: when each part must end.

A run given ``--time-limit T`` ends by T + 2 graces (a grace is max(
``Settings.generation.time_limit_grace_min``, ``time_limit_grace`` x T): T + max(10 s, 5 %
of T) with the defaults). After the search come parts that take their own time whatever
the search did: naming the final design (the path traces that search the chain), the
final design's folding path and motion, its DOF margin (a dense SVD of the constraints), its
checks, its exports and the report. The first two have deadlines; the others cannot be cut
without losing what a run is for, so the search leaves them a *reserve*, estimated from the
pattern's size::

    reserve = min(time_limit_reserve_share x T,
                  time_limit_reserve + time_limit_reserve_per_vertex x V) x load

measured on patterns of 49 to 684 vertices on an idle machine (docs/broad_set.md, "Session
23": 4 s after the search on the demo, 17 s on a 684-vertex drawn pattern). ``load`` is the
ratio of the wall time to the process's CPU time since the budget was made (1 on an idle
machine, 2 where another program takes half the core; at most
``time_limit_load_max``): the parts after the search take that much longer too. The search
then stops ``max(0, reserve - grace / 2)`` before T, naming the final design ends a grace
after the search, the final design's path a grace and a half after it, and the reserve
follows. The first solve alone ends half a grace after T whatever the reserve: without it
there is no design.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from rigidfold.config import Settings


@dataclass(frozen=True)
class TimeBudget:
    """When each part of a run with a time limit ends, as times of ``time.monotonic()``
    (the module's text); each is read when it is needed, with the machine's load then.

    started : the time T counts from; limit : T (seconds); reserve : the seconds kept for
    what follows the final design's path on an idle machine; grace : seconds of one grace;
    load_max : the most the load may stretch the reserve.
    """

    started: float
    limit: float
    reserve: float
    grace: float
    load_max: float
    _wall0: float = field(default_factory=lambda: time.monotonic(), repr=False)
    _cpu0: float = field(default_factory=lambda: time.process_time(), repr=False)

    def load(self) -> float:
        """Wall time over this process's CPU time since the budget was made, in [1,
        ``load_max``] (1 until a second of wall time has passed)."""
        wall = time.monotonic() - self._wall0
        cpu = time.process_time() - self._cpu0
        if wall < 1.0 or cpu <= 0.0:
            return 1.0
        return min(max(wall / cpu, 1.0), self.load_max)

    @property
    def search(self) -> float:
        """The search stops here: no solve or candidate trace goes past it."""
        kept = min(self.reserve * self.load(), self.limit / 2)
        return self.started + self.limit - max(0.0, kept - self.grace / 2)

    @property
    def first_solve(self) -> float:
        """The first solve ends here, half a grace after T, whatever the reserve: without it
        the run has no design, and a run without one has no final stages to keep time for
        (its summary and report take a few seconds)."""
        return self.started + self.limit + self.grace / 2

    @property
    def naming(self) -> float:
        """Naming the final design ends here (the traces that search the chain)."""
        return self.search + self.grace

    @property
    def path(self) -> float:
        """The final design's folding path and motion end here (a trace it cuts is
        ``cut``)."""
        return self.search + 1.5 * self.grace

    @property
    def end(self) -> float:
        """The run should have ended here: T + 2 graces."""
        return self.started + self.limit + 2 * self.grace


def time_budget(
    started: float, limit: float | None, n_vertices: int, settings: Settings
) -> TimeBudget | None:
    """The :class:`TimeBudget` of a run started at ``started`` (``time.monotonic()``) with the
    time limit ``limit`` (seconds; None: no limit, no budget) on a pattern of ``n_vertices``
    vertices (the module's text)."""
    if limit is None:
        return None
    g = settings.generation
    grace = max(g.time_limit_grace_min, g.time_limit_grace * limit)
    reserve = min(
        g.time_limit_reserve_share * limit,
        g.time_limit_reserve + g.time_limit_reserve_per_vertex * n_vertices,
    )
    return TimeBudget(started, limit, reserve, grace, g.time_limit_load_max)
