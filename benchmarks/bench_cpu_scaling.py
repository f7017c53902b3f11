"""How well this machine's cores scale, whatever the program: a pure-Python loop run alone,
then two copies at once (median seconds of each, 3 repeats). Compare the ratio with the
study's speed-up from 1 to 2 workers (bench_study.py).

    python benchmarks/bench_cpu_scaling.py [--repeat 3] [--n 30000000]
"""

from __future__ import annotations

import argparse
import statistics
import time
from concurrent.futures import ProcessPoolExecutor


def spin(n: int) -> float:
    t = time.perf_counter()
    s = 0
    for i in range(n):
        s += i * i
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--n", type=int, default=30_000_000)
    args = ap.parse_args()
    alone, pair = [], []
    with ProcessPoolExecutor(2) as pool:
        for _ in range(args.repeat):
            alone.append(pool.submit(spin, args.n).result())
            pair += [f.result() for f in [pool.submit(spin, args.n) for _ in range(2)]]
    a, p = statistics.median(alone), statistics.median(pair)
    print(f"loop alone: median {a:.2f} s (range {min(alone):.2f}-{max(alone):.2f})")
    print(f"two at once: median {p:.2f} s each (range {min(pair):.2f}-{max(pair):.2f})")
    print(f"throughput with 2 processes: {2 * a / p:.2f}x")


if __name__ == "__main__":
    main()
