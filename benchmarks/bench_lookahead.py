"""Benchmark of the first-order look-ahead (issue 18): selection time and generation.

Run with ``make bench`` (or ``python benchmarks/bench_lookahead.py [--seeds 5] [--repeat 30]``).

* selection: on every accepted shape of one generation run (pattern 1, Bezier seed 1, S-hat,
  down to DOF 1; the 11 x 11 grid, dome, no symmetry, S, down to DOF 1), one Step 6 as
  ``generate`` makes it: the hinge stiffnesses, the scores (32)-(38) and the ranking, and the
  same plus the look-ahead's first candidate (:func:`rigidfold.selection.lookahead_order`,
  which forecasts the ranking 8 candidates at a time), and, for reference, the forecast of
  every candidate at once (:func:`rigidfold.selection.lock_forecast`, one (h, d) x (d, h)
  product). All are timed alternately in this process, on one BLAS thread as inside
  ``generate``; printed: the median over the shapes of each shape's median, the ratios to
  the selection without look-ahead, and the ratio of the sums over the shapes (the
  selection time of the run).
* generate: pattern 1, S-hat, Bezier seeds 0..N-1, without and with look-ahead: N_lock,
  N_reduce, solves of (6), candidates skipped, wall time, and the ratios of the totals.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rigidfold.config import one_blas_thread
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.stiffness import hinge_stiffness
from rigidfold.selection import lock_forecast, lookahead_order, rank_candidates, score_creases

MODES = ("off", "lookahead", "all candidates")


def select(mech, criterion: str, seed: int, mode: str) -> float:
    """Seconds of one selection on ``mech`` (Step 6 of ``generate``) in one of ``MODES``."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    K = hinge_stiffness(mech.frame.n_hinges, int(rng.integers(2**32)), mech.settings)
    ranked = rank_candidates(score_creases(mech, K=K), criterion, rng=rng)
    candidates = [g for g, _ in ranked]
    if mode == "lookahead":  # the first candidate to try, as generate asks for it
        next(lookahead_order(mech, candidates, settings=mech.settings))
    elif mode == "all candidates":
        lock_forecast(mech, candidates, settings=mech.settings)
    return time.perf_counter() - t0


def bench_selection(label: str, case, criterion: str, repeat: int) -> None:
    run = generate(case, criterion=criterion, seed=1)
    shapes = [s.mechanism for s in run.solutions if s.mechanism.dof > 1]
    medians: dict[str, list[float]] = {m: [] for m in MODES}
    with one_blas_thread():
        for mech in shapes:
            times: dict[str, list[float]] = {m: [] for m in MODES}
            for k in range(repeat):
                for mode in MODES:
                    times[mode].append(select(mech, criterion, k, mode))
            for mode in MODES:
                medians[mode].append(statistics.median(times[mode]))
    med = {m: statistics.median(medians[m]) for m in MODES}
    total = {m: sum(medians[m]) for m in MODES}
    print(
        f"{label}: {len(shapes)} shapes, DOF {shapes[0].dof}..{shapes[-1].dof}, "
        f"{len(shapes[0].hinges)}..{len(shapes[-1].hinges)} free creases"
    )
    for m in MODES:
        print(
            f"  {m:<15} median {med[m] * 1e3:7.3f} ms per selection (ratio "
            f"{med[m] / med['off']:.2f}), per run {total[m] * 1e3:7.2f} ms (ratio "
            f"{total[m] / total['off']:.2f})",
            flush=True,
        )


def bench_generate(seeds: int) -> None:
    totals = {}
    for lookahead in (False, True):
        rows = []
        for seed in range(seeds):
            t0 = time.perf_counter()
            run = generate(
                case_from_specs("bezier", "1", seed=seed),
                criterion="shat",
                seed=seed,
                lookahead=lookahead,
            )
            rows.append((run, time.perf_counter() - t0))
            s = run.to_dict()
            print(
                f"  look-ahead {'on ' if lookahead else 'off'} seed {seed}: {rows[-1][1]:6.2f} s, "
                f"N_reduce {s['n_reduce']}, N_lock {s['n_lock']}, N_exceed {s['n_exceed']}, "
                f"{s['n_solves']} solves, {s['n_skipped']} skipped",
                flush=True,
            )
        totals[lookahead] = (
            sum(r.n_lock for r, _ in rows),
            sum(len(r.attempts) for r, _ in rows),
            sum(t for _, t in rows),
        )
    (lock0, solves0, wall0), (lock1, solves1, wall1) = totals[False], totals[True]
    print(
        f"generate pattern 1 S-hat, seeds 0-{seeds - 1}: N_lock {lock0} -> {lock1}, solves "
        f"{solves0} -> {solves1}, wall {wall0:.2f} -> {wall1:.2f} s (ratio {wall1 / wall0:.2f})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=30)
    args = parser.parse_args()
    bench_selection(
        "pattern 1 (Bezier 1)", case_from_specs("bezier", "1", seed=1), "shat", args.repeat
    )
    bench_selection("11 x 11 (dome, asym)", case_from_specs("dome", "11"), "s", args.repeat)
    bench_generate(args.seeds)


if __name__ == "__main__":
    main()
