"""Benchmark of ``rigidfold report``: the HTML page and the figures of a generate run.

Run with ``python benchmarks/bench_report.py [--repeat 5] [--run DIR]``.

Without ``--run`` it first generates the 11 x 11 grid on the dome (criterion S, target DOF
1, Steps 8-9 on every solution) into a temporary directory, which takes minutes; ``--run DIR``
times an existing run instead. Then it writes the report ``--repeat`` times, each in a fresh
process (``python -m rigidfold.cli report DIR``: imports of matplotlib and plotly included,
as a user pays them), and prints the median wall time (and CPU time, which a busy machine
does not inflate) and the size of report.html.
Targets (issue 20): under 5 s and under 10 MB for an 11 x 11 run.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rigidfold.rundir import load_run


def generate_run(out: Path) -> None:
    args = ["generate", "--surface", "dome", "--pattern", "11", "--criterion", "s"]
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *args, "--quiet", "--out", str(out)],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    print(f"generated {out} in {time.perf_counter() - t0:.0f} s")


def _cpu() -> float:
    """CPU seconds of the finished child processes so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def bench(run: Path, repeat: int) -> None:
    times, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), _cpu()
        subprocess.run(
            [sys.executable, "-m", "rigidfold.cli", "report", str(run), "--json"],
            check=True,
            capture_output=True,
        )
        times.append(time.perf_counter() - t0)
        cpu.append(_cpu() - c0)
    summary = load_run(run).summary.to_dict()  # run files are read through rigidfold.rundir
    case = summary["case"]
    fields = [
        f"report of {case['pattern']} on {case['surface']['name']}: "
        f"{summary['n_solutions']} solutions, {summary['n_solves']} solves",
        f"median {statistics.median(times):.2f} s over {repeat} "
        f"(min {min(times):.2f} s, max {max(times):.2f} s), CPU {statistics.median(cpu):.2f} s",
        f"report.html {(run / 'report.html').stat().st_size / 1e6:.2f} MB",
        "target < 5 s, < 10 MB",
    ]
    print(" | ".join(fields))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--run", type=Path, help="an existing generate run to report on")
    args = parser.parse_args()
    if args.run is not None:
        bench(args.run, args.repeat)
        return
    with tempfile.TemporaryDirectory(prefix="rigidfold-bench-report-") as tmp:
        run = Path(tmp) / "run"
        generate_run(run)
        bench(run, args.repeat)


if __name__ == "__main__":
    main()
