"""Benchmark of Step 9 (OpenSees large-deformation check) and of the folding motion.

Run with ``python benchmarks/bench_deform.py [--seeds 3] [--repeat 3]``.

For Bezier seeds 0..N-1, ``generate`` (pattern 1, S-hat, target DOF 1) gives a 1-DOF shape;
its large-deformation check (20 load steps, 20 mm tubes) and its folding motion (11 frames)
are timed, median over ``--repeat`` runs, and their figures printed next to the paper's
example (Section 6.3: mean |dl| 0.25 mm, mean |drho_fix| 0.018 deg, 37.0 s in Abaqus).
Target here: <= 10 s per pattern-1 shape.
"""

from __future__ import annotations

import argparse
import statistics
import time

from rigidfold.deform import deform, folding_motion
from rigidfold.develop import develop
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    deform_times = []
    for seed in range(args.seeds):
        run = generate(case_from_specs("bezier", "1", seed=seed), criterion="shat", seed=seed)
        shape = run.solutions[-1].result.pattern
        dev = develop(shape)
        times, mtimes = [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            result = deform(shape)
            times.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            motion = folding_motion(shape, dev.coords2d)
            mtimes.append(time.perf_counter() - t0)
        deform_times.append(statistics.median(times))
        print(
            f"seed {seed}: DOF {run.final_dof}, D {dev.D:.1e}, flips {dev.flipped}, "
            f"overlaps {dev.overlaps} | deform {result.status}, mean/max |dl| "
            f"{result.mean_dl_mm:.3f}/{result.max_dl_mm:.3f} mm, mean/max |drho_fix| "
            f"{result.mean_drho_fix_deg:.4f}/{result.max_drho_fix_deg:.4f} deg, median "
            f"{statistics.median(times):.2f} s | motion {motion.status}, max |dl|/l "
            f"{motion.max_length_error:.1e}, median {statistics.median(mtimes):.2f} s",
            flush=True,
        )
    print(
        f"deformation check, pattern 1, 1-DOF: median {statistics.median(deform_times):.2f} s "
        f"over {args.seeds} shapes   paper 37.0 s (Abaqus); target <= 10 s"
    )


if __name__ == "__main__":
    main()
