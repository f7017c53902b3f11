"""Why and at what cost rigidfold runs its linear algebra on one BLAS thread.

Run with ``make bench`` (or ``python benchmarks/blas_threads.py [--seeds 3] [--repeat 3]``).

* path: the first solve of problem (6) for the symmetric HP (Step 3, no crease fixed) with
  one and with two BLAS threads, and with CasADi's Hessian, as rigidfold did before
  ``rigidfold.config.one_blas_thread``. F is zero on a family of developable shapes, so the
  solver stops at different shapes; printed: F, IPOPT iterations and the largest vertex
  coordinate difference from the one-thread, closed-form solve.
* time: ``generate`` (pattern 2, criterion S, Bezier seeds 0..N-1) on one BLAS thread
  against the machine's default thread count, in one process, interleaved, medians of
  ``--repeat``; the ratio is default / one thread.
* overhead: one ``threadpoolctl.threadpool_limits`` call, which only the outermost
  ``one_blas_thread`` makes.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import time

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

from rigidfold.config import DEFAULTS
from rigidfold.config import blas as config
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs


@contextlib.contextmanager
def caller_threads(n: int | None):
    """Run rigidfold with ``n`` BLAS threads (None: the default), bypassing one_blas_thread."""
    config._BLAS.depth = 1  # one_blas_thread now counts as nested and leaves the limit alone
    try:
        with threadpool_limits(limits=n, user_api="blas"):
            yield
    finally:
        config._BLAS.depth = 0


def first_solve(threads: int, hessian: str) -> tuple[np.ndarray, float, int]:
    settings = DEFAULTS.with_(ipopt_hessian=hessian)
    with caller_threads(threads):
        case = case_from_specs("hp", "11", symmetric=True, settings=settings)
        result = case.problem().solve()
    return result.coords, result.F, result.iterations


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    if args.seeds < 1 or args.repeat < 1:
        parser.error(f"--seeds and --repeat must be >= 1, got {args.seeds} and {args.repeat}")
    default = max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
    print(f"default BLAS threads here: {default}")

    reference, _, _ = first_solve(1, "closed-form")
    for threads, hessian in ((1, "closed-form"), (2, "closed-form"), (1, "casadi")):
        coords, F, iterations = first_solve(threads, hessian)
        diff = np.abs(coords - reference).max()
        print(
            f"HP symmetric, first solve, {threads} thread(s), {hessian:<11}  F {F:.1e}  "
            f"{iterations:3d} iterations  max |coordinate - 1-thread closed-form| {diff:.3f} m"
        )

    cases = [case_from_specs("bezier", "2", seed=s) for s in range(args.seeds)]
    times: dict[str, list[float]] = {"one thread": [], "default threads": []}
    for _ in range(args.repeat):
        for mode, threads in (("one thread", 1), ("default threads", None)):
            with caller_threads(threads):
                t0 = time.perf_counter()
                for seed, case in enumerate(cases):
                    generate(case, criterion="s", seed=seed)
                times[mode].append(time.perf_counter() - t0)
    one, dflt = (statistics.median(times[m]) for m in ("one thread", "default threads"))
    print(
        f"generate pattern 2, S, seeds 0-{args.seeds - 1}: one thread {one:.2f} s, "
        f"default threads {dflt:.2f} s (medians of {args.repeat}), ratio {dflt / one:.2f}"
    )

    n = 200
    t0 = time.perf_counter()
    for _ in range(n):
        with threadpool_limits(limits=1, user_api="blas"):
            pass
    print(f"threadpool_limits: {(time.perf_counter() - t0) / n * 1e3:.2f} ms per call")


if __name__ == "__main__":
    main()
