"""The time budget of a run with a time limit: when each part must end.

A run given ``--time-limit T`` ends by T + 2 graces (a grace is max(
``Settings.generation.time_limit_grace_min``, ``time_limit_grace`` x T): T + max(10 s, 5 %
of T) with the defaults). After the search come parts that take their own time whatever
the search did: naming the final design (the path traces of the chain's bisection), the
final design's folding path and motion, its DOF margin (a dense SVD of the constraints), its
checks, its exports and the report. The first two have deadlines; the others cannot be cut
without losing what a run is for, so the search leaves them a *reserve*, estimated from the
pattern's size::

    reserve = min(time_limit_reserve_share x T,
                  time_limit_reserve + time_limit_reserve_per_vertex x V)

measured on patterns of 49 to 684 vertices (docs/broad_set.md, "Session 23": 4 s after the
search on the demo, 17 s on a 684-vertex drawn pattern). The search then stops
``max(0, reserve - grace / 2)`` before T, naming the final design ends a grace after the
search, the final design's path a grace and a half after it, and the reserve follows.
"""

from __future__ import annotations

from dataclasses import dataclass

from rigidfold.config import Settings


@dataclass(frozen=True)
class TimeBudget:
    """When each part of a run with a time limit ends, as times of ``time.monotonic()``.

    search : the search stops (no solve or candidate trace goes past it);
    naming : naming the final design ends (the traces of the chain's bisection);
    path : the final design's folding path and motion end (a trace it cuts is ``cut``);
    end : the run should have ended (T + 2 graces);
    reserve : seconds kept for what follows the path (the margin, checks, exports, report);
    grace : seconds of one grace.
    """

    search: float
    naming: float
    path: float
    end: float
    reserve: float
    grace: float


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
    search = started + limit - max(0.0, reserve - grace / 2)
    return TimeBudget(
        search=search,
        naming=search + grace,
        path=search + 1.5 * grace,
        end=started + limit + 2 * grace,
        reserve=reserve,
        grace=grace,
    )
