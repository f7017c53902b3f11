"""The final design of a run that ends short of its target or is stopped: the lowest-DOF
solution whose folding path reaches the flat state (Step 9's check, made while the run
generates; docs/deployability.md).

A run that ends short of its target otherwise (no candidate left, none that deploys)
probes its chain from the end back in doubling steps, then bisects, instead of tracing
every path from the last back (about 2 log2(d) traces for a design d solutions above the
last); a run ended by its time limit bisects the whole chain from its middle, so that the
limit is not overrun (about log2(K) traces of K solutions, within a grace of seconds, which
the few-DOF paths at the chain's end can spend alone); an interrupted run traces nothing and
names the best design known to deploy.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from rigidfold.config import Settings
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.records import Generation, Solution
from rigidfold.mechanism.path import trace_path


def deployable_final(
    run: Generation,
    options: GenerateOptions,
    settings: Settings,
    *,
    bisect: bool,
    deadline: float | None = None,
) -> None:
    """With the deployability check, a run that ends short of its target names as its final
    design the lowest-DOF solution whose folding path reaches the flat state; none: the last
    solution.

    The paths not yet traced are probed from the chain's end back at 1, 2, 4, ... solutions
    above the last, down to the latest solution known to deploy, until one deploys; the gap
    between it and the probe below it is then bisected: about 2 log2(d) traces for a design
    d solutions above the last, not d. A run stopped by its time limit (``bisect``) bisects
    the chain between the latest solution known to deploy and its end instead, from the
    middle: about log2(K) traces of its K solutions, so that the limit is not overrun (the
    few-DOF paths at the chain's end can take longer than the grace: on a 21 x 21 grid on
    the HP the probes from the end named no design that deploys, the bisection one of DOF
    20; docs/deployability.md, session 33). Either names a solution whose own path deploys
    and none of whose probed successors' does. Where the chain's paths deploy down to some
    DOF and none below (as on the drawn patterns measured, docs/deployability.md), that is
    the lowest-DOF solution that deploys, as a scan of every path from the last back finds
    it.

    ``deadline`` (of ``time.monotonic()``: the run's time limit and its grace): every trace
    ends there (a trace it cuts counts as not deploying and is not kept), and none starts
    after it; their seconds are ``Generation.final_path_time`` (``time_s.path``).
    """
    if not options.deploy_check:
        return

    def deploys(solution: Solution) -> bool:
        verdict, seconds = traced_deploys(solution, options, settings, deadline)
        run.final_path_time += seconds
        return bool(verdict)

    chain = run.solutions
    known = [i for i, s in enumerate(chain) if known_to_deploy(s)]
    lo = lowest_deploying(chain, known[-1] if known else -1, deploys, gallop=not bisect)
    if lo >= 0:
        run.final_step = chain[lo].step


def lowest_deploying(
    chain: list[Solution], lo: int, deploys: Callable[[Solution], bool], *, gallop: bool
) -> int:
    """The index of a solution of ``chain`` whose path reaches the flat state (``deploys``)
    and whose next probed solution's does not, at or above ``lo`` (a solution that deploys;
    -1: none), or ``lo``. With ``gallop``, the solutions above ``lo`` are probed from the
    chain's end back at 1, 2, 4, ... solutions above the last, until one deploys, and the
    gap between it and the probe below it bisected: about 2 log2(d) traces for a solution
    d above the last, all of them of the chain's last, fewest-DOF shapes. Without, the
    chain between ``lo`` and its end is bisected from its middle: about log2 of its
    length in traces."""
    hi, back = len(chain), 1
    while gallop and len(chain) - back > lo:
        probe = len(chain) - back
        if deploys(chain[probe]):
            lo = probe
            break
        hi, back = probe, 2 * back
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if deploys(chain[mid]) else (lo, mid)
    return lo


def traced_deploys(
    solution: Solution, options: GenerateOptions, settings: Settings, deadline: float | None
) -> tuple[bool | None, float]:
    """Whether the solution's folding path reaches the flat state: its path's verdict where
    it was traced, else traced now (to ``deadline``, of ``time.monotonic()``) and kept
    (``Solution.path``). None where the deadline cut the trace or had passed (nothing
    kept). Returns the verdict and the seconds of the trace (0.0: none)."""
    if solution.path is not None:
        return bool(solution.path.deploys), 0.0
    if deadline is not None and time.monotonic() > deadline:
        return None, 0.0
    t0 = time.perf_counter()
    path = trace_path(
        solution.result.pattern,
        dof=solution.mechanism.dof,
        support_face=options.support_face,
        settings=settings,
        deadline=deadline,
    )
    seconds = time.perf_counter() - t0
    if path.cut:
        return None, seconds
    solution.path = path
    return bool(path.deploys), seconds


def best_so_far(run: Generation) -> None:
    """Name the final design of a run that stops before its end (interrupted): the
    lowest-DOF solution whose folding path is known to reach the flat state (of two at one
    DOF, the later); where none is known, ``final_step`` stays None (the last solution),
    which the verdict does not name as a design (:func:`known_to_deploy`). No path is
    traced."""
    known = [s for s in run.solutions if known_to_deploy(s)]
    if known:
        run.final_step = min(known, key=lambda s: (s.mechanism.dof, -s.step)).step


def known_to_deploy(solution: Solution) -> bool:
    """Whether the solution's folding path was traced and reached the flat state (the
    deployability check of Step 5)."""
    return solution.path is not None and bool(solution.path.deploys)
