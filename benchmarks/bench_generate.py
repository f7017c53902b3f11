"""Benchmark of the mechanism analysis, the scoring and a full generation (Steps 2-7).

Run with ``make bench`` (or ``python benchmarks/bench_generate.py [--seeds 5]``).

* analysis + scoring: median over 30 repetitions on the optimised initial shape of pattern 1
  (Bezier seed 0) and of the 11 x 11 grid (dome, no symmetry), on one BLAS thread as inside
  ``generate``. Paper: 0.0113 s and 0.882 s for "selecting the crease lines to be fixed".
* generate: pattern 1, S-hat, target DOF 1, no deformation check, median over Bezier seeds
  0..N-1; paper: 2367 s for one such run including Abaqus checks and its development
  diagrams (72.4 s per solve of (6)).
"""

from __future__ import annotations

import argparse
import statistics
import time

from rigidfold.config import one_blas_thread
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.selection import rank_candidates, score_creases


def bench_analysis(label: str, case, paper: float, repeat: int = 30) -> None:
    shape = case.problem().solve().pattern
    times, analysis_only = [], []
    with one_blas_thread():  # as inside generate
        for k in range(repeat):
            fresh = shape.with_coords(shape.coords)  # no cached geometry
            t0 = time.perf_counter()
            mech = analyze(fresh)
            t1 = time.perf_counter()
            rank_candidates(score_creases(mech, seed=k), "shat")
            times.append(time.perf_counter() - t0)
            analysis_only.append(t1 - t0)
    print(
        f"{label:<22} DOF {mech.dof:<3} analysis {statistics.median(analysis_only) * 1e3:6.2f} ms"
        f"  analysis+scoring {statistics.median(times) * 1e3:6.2f} ms   paper {paper * 1e3:g} ms"
    )


def bench_generate(seeds: int) -> None:
    walls, solves = [], []
    for seed in range(seeds):
        t0 = time.perf_counter()
        run = generate(case_from_specs("bezier", "1", seed=seed), criterion="shat", seed=seed)
        walls.append(time.perf_counter() - t0)
        solves.append(len(run.attempts))
        s = run.to_dict()
        print(
            f"  seed {seed}: {walls[-1]:6.2f} s, DOF {s['initial_dof']} -> {s['final_dof']}, "
            f"{s['n_solves']} solves, N_lock {s['n_lock']}, N_exceed {s['n_exceed']}",
            flush=True,
        )
    print(
        f"generate pattern 1 S-hat: median {statistics.median(walls):.2f} s over {seeds} seeds "
        f"(median {statistics.median(solves)} solves)   paper 2367 s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args()
    bench_analysis("pattern 1 (Bezier 0)", case_from_specs("bezier", "1", seed=0), 0.0113)
    bench_analysis("11 x 11 (dome, asym)", case_from_specs("dome", "11"), 0.882)
    bench_generate(args.seeds)


if __name__ == "__main__":
    main()
