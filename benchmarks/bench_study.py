"""Benchmark of study throughput: runs per minute per worker, 1 and 2 local workers.

Run with ``python benchmarks/bench_study.py [--surfaces 4] [--workers 1 2]``.

Each measurement runs a fresh study (Bezier seeds 0..N-1, pattern 1, criteria S-hat and S,
no Steps 8-9) into a temporary database with ``rigidfold.study.run_study`` and reports the
wall time (including the start of the Dask cluster), the throughput and the speed-up over one
worker measured in the same process.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from rigidfold.study import Store, StudyConfig, plan, run_study


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--surfaces", type=int, default=4)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    keys = plan(["1"], ["shat", "s"], args.surfaces)
    config = StudyConfig(deform=False)
    base = None
    for n in args.workers:
        with tempfile.TemporaryDirectory() as tmp:
            store = Store(Path(tmp) / "bench.sqlite", config.as_dict())
            result = run_study(keys, store, config, workers=n)
            store.close()
        rate = result["ran"] / result["wall_s"] * 60
        base = base or rate
        print(
            f"workers {n:<3} runs {result['ran']:<4} wall {result['wall_s']:7.1f} s  "
            f"{rate:6.1f} runs/min  {rate / n:6.1f} runs/min/worker  speed-up {rate / base:4.2f}x",
            flush=True,
        )


if __name__ == "__main__":
    main()
