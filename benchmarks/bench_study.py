"""Benchmark of study throughput: runs per minute per worker, and its scaling with workers.

Run with ``python benchmarks/bench_study.py [--surfaces 8] [--workers 1 2] [--repeat 3]``.

Each measurement runs a fresh study (Bezier seeds 0..N-1, pattern 1, criteria S-hat and S,
no Steps 8-9) into a temporary database with ``rigidfold.study.run_study``. Printed per
worker count, as medians over the repeats: the wall time, the part of it that starts the Dask
cluster, the throughput over the whole wall time and over the time after the start-up
(runs/min and runs/min/worker), and the speed-up over the first worker count, measured in
the same process. The runs are the same at every worker count (same seeds), so the work is
identical and only its distribution changes.

Two numbers say where a speed-up below the worker count goes: ``run time`` is the summed
time of the runs inside the workers (each run's own ``time_total``), which grows when two runs
at once slow each other down (shared cores, caches, memory bandwidth); ``busy`` is that sum
over ``workers x (wall - start-up)``, which falls when workers wait (the last runs of the
study, scheduling, the client writing the database).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

from rigidfold.study import STUDY_OPTIONS, Store, StudyConfig, plan, run_study


def measure(keys, config, workers: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        store = Store(Path(tmp) / "bench.sqlite", config.as_dict())
        result = run_study(keys, store, config, workers=workers)
        result["run_s"] = sum(r.time_total or 0.0 for r in store.runs())
        store.close()
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--surfaces", type=int, default=8)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    keys = plan(["1"], ["shat", "s"], args.surfaces)
    config = StudyConfig(STUDY_OPTIONS.replace(deform=False))
    base = None
    print(f"{len(keys)} runs per study, medians of {args.repeat} repeats", flush=True)
    for n in args.workers:
        results = [measure(keys, config, n) for _ in range(args.repeat)]
        wall = statistics.median(r["wall_s"] for r in results)
        startup = statistics.median(r["startup_s"] for r in results)
        rate = len(keys) / wall * 60
        steady = statistics.median(len(keys) / (r["wall_s"] - r["startup_s"]) * 60 for r in results)
        run_s = statistics.median(r["run_s"] for r in results)
        busy = statistics.median(r["run_s"] / (n * (r["wall_s"] - r["startup_s"])) for r in results)
        base = base or (rate, steady, run_s)
        print(
            f"workers {n:<3} wall {wall:6.1f} s (start-up {startup:4.1f} s)  "
            f"{rate:6.1f} runs/min  {rate / n:6.1f} runs/min/worker  "
            f"after start-up {steady:6.1f} runs/min  {steady / n:6.1f} runs/min/worker  "
            f"speed-up {rate / base[0]:4.2f}x ({steady / base[1]:4.2f}x after start-up)  "
            f"run time {run_s:6.1f} s ({run_s / base[2]:4.2f}x)  busy {busy:4.0%}",
            flush=True,
        )


if __name__ == "__main__":
    main()
