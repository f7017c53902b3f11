"""Where a generation chain stops deploying (issue 40): for every solution of a run
directory, its DOF, the largest fold angle of a free crease, and whether its folding path
(the mechanism's own at DOF 1, the Gauss-Newton path above) reaches the flat state.

Run with ``python benchmarks/chain_deploys.py DIR [--min-dof N] [--max-dof N]`` on the
directory of a ``rigidfold generate`` run. Each line: the solution file, its DOF, the path's
status and steps, the smallest folding measure it reached (of the design's), the largest and
the mean |fold angle| of the free creases, and the seconds of the trace.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a generate run's directory")
    parser.add_argument("--min-dof", type=int, default=0)
    parser.add_argument("--max-dof", type=int, default=10**9)
    args = parser.parse_args()

    from rigidfold.exports import read_design
    from rigidfold.mechanism import analyze
    from rigidfold.mechanism.path import trace_path

    for path in sorted((args.run / "solutions").glob("*.fold")):
        pattern = read_design(path).pattern
        dof = analyze(pattern, settings=pattern.settings).dof
        if not args.min_dof <= dof <= args.max_dof:
            continue
        t0 = time.perf_counter()
        traced = trace_path(pattern, dof=dof, settings=pattern.settings)
        seconds = time.perf_counter() - t0
        free = ~pattern.fixed & ~pattern.is_boundary_edge
        folds = np.degrees(np.abs(pattern.fold_angles[free]))
        print(
            f"{path.name}  DOF {dof:3d}  {traced.status.value:12s} {traced.steps:4d} steps  "
            f"min m {traced.measure.min():.3g}  largest fold {folds.max():5.1f} deg  "
            f"mean {folds.mean():5.1f} deg  {seconds:.1f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
