"""Benchmark of ``rigidfold structure`` against the panel count (issue 39): wall time and
peak memory from about 100 to 3000 triangles, ``--supports auto`` and ``service``.

Run with ``python benchmarks/bench_structure_scale.py [--grids 8,12,17,25,33,40]
[--supports auto,service] [--modes 3] [--timeout 900] [--repeat 1] [--case dome]``.

Cases: ``grid:NxN`` spanning 3 m (every diagonal towards the centre,
:func:`rigidfold.patterns.grid`) lifted onto the dome (``case_from_specs("dome", "grid:NxN",
size="3x3")``; ``--case barrel`` and ``flat``: :func:`design`), every interior edge a free
hinge: 2 (N - 1)^2 triangles, grid:40x40 the issue's 3042. Each is written to a FOLD file
and checked by the command line (``rigidfold structure FILE --out DIR --supports S --modes
M --json``, self-weight of 18 mm plywood, L/250), one process per run, so that the
command's own pinned numerics (one BLAS thread) apply; its peak resident set is
``ru_maxrss`` of the children of a small wrapper process that runs only it. Printed per
run: triangles, supports, the exit code, wall time (median over ``--repeat``), peak memory
and the verdict (status, pins, largest displacement; the refusal's words for exit 2); the
issue's target is <= 90 s and <= 2.5 GB for grid:40x40 on the 2-core development machine.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from rigidfold.generate.specs import case_from_specs
from rigidfold.io import write_fold
from rigidfold.mesh import CreasePattern
from rigidfold.patterns.grids import grid

ROOF = "0.06*x*(12-x)/6 + 0.05*y*(8-y)"
"""The README roof's surface: ``--case barrel`` lifts the grid onto it over 12 m x 8 m."""


def design(case: str, n: int) -> CreasePattern:
    """``dome``: grid:NxN over 3 m x 3 m on the dome; ``barrel``: over 12 m x 8 m on the
    roof's shallow surface (nearly flat: a near-mechanism per inner vertex); ``flat``: the
    plane grid over 3 m x 3 m (a first-order motion per inner vertex)."""
    if case == "dome":
        return case_from_specs("dome", f"grid:{n}x{n}", size="3x3").pattern
    if case == "barrel":
        return case_from_specs("expr", f"grid:{n}x{n}", size="12x8", expr=ROOF).pattern
    xy, triangles = grid(n, n, 3.0, 3.0)
    return CreasePattern.from_faces(np.column_stack([xy, np.zeros(len(xy))]), triangles)


RIGIDFOLD = [sys.executable, "-m", "rigidfold"]


def measured(cmd: list[str], timeout: float) -> tuple[int, float, float, str]:
    """``cmd`` run under a small wrapper process that reports its child's peak RSS."""
    wrapper = (
        "import json, resource, subprocess, sys, time\n"
        "t0 = time.perf_counter()\n"
        "try:\n"
        "    p = subprocess.run(sys.argv[2:], capture_output=True, text=True,\n"
        "                       timeout=float(sys.argv[1]))\n"
        "    code, out, err = p.returncode, p.stdout, p.stderr[-2000:]\n"
        "except subprocess.TimeoutExpired:\n"  # run() has killed the command
        "    code, out, err = -9, '', 'timed out'\n"
        "wall = time.perf_counter() - t0\n"
        "peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024\n"
        "print(json.dumps([code, wall, peak, out, err]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", wrapper, str(timeout), *cmd], capture_output=True, text=True
    )
    code, wall, peak, out, err = json.loads(done.stdout)
    return code, wall, peak, out or err


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grids", default="8,12,17,25,33,40")
    parser.add_argument("--supports", default="auto,service")
    parser.add_argument("--modes", type=int, default=3)
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--case", choices=("dome", "barrel", "flat"), default="dome")
    args = parser.parse_args()
    grids = [int(g) for g in args.grids.split(",")]
    print("grid | triangles | supports | exit | wall s (median) | peak MB | verdict")
    with tempfile.TemporaryDirectory() as tmp:
        for n in grids:
            pattern = design(args.case, n)
            path = Path(tmp) / f"grid{n}.fold"
            write_fold(path, pattern)
            for supports in args.supports.split(","):
                out = Path(tmp) / f"out{n}{supports}"
                cmd = [
                    *RIGIDFOLD,
                    "structure",
                    str(path),
                    "--out",
                    str(out),
                    "--overwrite",
                    "--supports",
                    supports,
                    "--modes",
                    str(args.modes),
                    "--json",
                ]
                runs = [measured(cmd, args.timeout) for _ in range(args.repeat)]
                code, _, _, text = runs[-1]
                wall = statistics.median(r[1] for r in runs)
                peak = max(r[2] for r in runs)
                verdict = text.strip()[-200:]
                if code in (0, 1):
                    data = json.loads(text)
                    verdict = (
                        f"{data['status']}, {len(data['supports']['pinned'])} pins, largest "
                        f"displacement {data.get('max_displacement_m', 0) * 1e3:.3g} mm"
                    )
                print(
                    f"{n}x{n} | {pattern.n_faces} | {supports} | {code} | {wall:.1f} | "
                    f"{peak:.0f} | {verdict}",
                    flush=True,
                )
    print(f"({os.cpu_count()} CPUs; target: grid:40x40 <= 90 s and <= 2500 MB)")


if __name__ == "__main__":
    main()
