"""Benchmark of Step 8: the development diagram, problem (13).

Run with ``python benchmarks/bench_develop.py [--repeat 5]``.

Median wall time of :func:`rigidfold.develop.develop` (model build + IPOPT + flip and overlap
counts) on the optimised shape of pattern 1 (Bezier seed 1) and on the optimised 11 x 11
grid (dome, no symmetry). Paper: 3.31 s (pattern 1) and 20.3 s (11 x 11, asymmetric) per
solution of (13). Target here: 11 x 11 <= 0.5 s.
"""

from __future__ import annotations

import argparse
import statistics
import time

from rigidfold.develop import develop
from rigidfold.generate.specs import case_from_specs


def bench(label: str, case, paper: float, repeat: int) -> None:
    shape = case.problem().solve().pattern
    times = []
    for _ in range(repeat):
        fresh = shape.with_coords(shape.coords)  # no cached geometry
        t0 = time.perf_counter()
        dev = develop(fresh)
        times.append(time.perf_counter() - t0)
    print(
        f"{label:<22} V {shape.n_vertices:<4} F {shape.n_faces:<4} "
        f"median {statistics.median(times):7.3f} s  D {dev.D:9.3g}  "
        f"max |dl|/l {dev.max_length_error:9.3g}  flips {dev.flipped}  "
        f"overlaps {dev.overlaps}  iter {dev.iterations:<3} {dev.status:<9} paper {paper:g} s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    bench("pattern 1 (Bezier 1)", case_from_specs("bezier", "1", seed=1), 3.31, args.repeat)
    bench("11 x 11 (dome, asym)", case_from_specs("dome", "11"), 20.3, args.repeat)


if __name__ == "__main__":
    main()
