"""Benchmark of issue 39: ``rigidfold fabricate`` against the number of panels, with its
peak memory.

Run with ``python benchmarks/bench_fabricate_scale.py [--miura 10,16,23,27,40,55]
[--grid 12,17] [--fold FILE ...] [--thickness 0.02] [--repeat 1]``.

Designs, each written to a FOLD file first (not timed):

* ``miura N``: a Miura-ori of N x N parallelograms (:func:`rigidfold.patterns.miura.miura`,
  0.3 m cells, folded to a height of 0.09 m): N^2 panels, one DOF, deploys (its path is
  traced by ``fabricate``, the check runs over the whole motion);
* ``grid N``: an N x N vertex grid of triangles on a paraboloid (3 m x 3 m, each triangle
  a panel: 2 (N - 1)^2 panels), the curved grids of the issue (12: 242 triangles, 17: 512);
  it has many DOF and no motion from flat, so ``fabricate`` builds the solids and the cut
  sheets without a check;
* ``--fold FILE``: a design of one's own (e.g. the 722-panel waterbomb of the issue).

Each run is one ``fabricate_file`` (reading, the traced motion, solids, the check over the
motion, the thinner tries where the thickness fails, the cut sheets nested, every file
written) in a subprocess of its own: the median wall time of ``--repeat`` runs and the
largest peak resident set (``getrusage``) of them. The table is followed by the log-log
slope of the time against the panels over the Miura-ori sizes.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = """
import json, resource, sys, time
from rigidfold.fabricate import FabricateOptions
from rigidfold.pipeline.workflows import fabricate_file
t0 = time.perf_counter()
done = fabricate_file(sys.argv[1], sys.argv[2], FabricateOptions(thickness=float(sys.argv[3])))
print(json.dumps({
    "seconds": time.perf_counter() - t0,
    "panels": done.fabrication.panels.n,
    "status": done.fabrication.status.value,
    "frames": done.fabrication.motion.n_frames if done.fabrication.motion else 0,
    "sheets": done.sheets["sheets"],
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
}))
"""


def write_miura(n: int, path: Path) -> Path:
    from rigidfold.io import write_fold
    from rigidfold.patterns.miura import miura

    shape = miura(n, n, length=0.3, width=0.3, offset=0.12, height=0.09)
    return write_fold(path, shape, title=f"Miura-ori {n} x {n}")


def write_grid(n: int, path: Path) -> Path:
    import numpy as np

    from rigidfold.io import write_fold
    from rigidfold.mesh import CreasePattern
    from rigidfold.patterns.grids import grid

    xy, tri = grid(n, n, 3.0, 3.0)
    z = 0.15 * ((xy[:, 0] - 1.5) ** 2 + (xy[:, 1] - 1.5) ** 2)
    shape = CreasePattern.from_faces(np.column_stack([xy, z]), tri)
    return write_fold(path, shape, title=f"curved grid {n} x {n}")


def run(fold: Path, thickness: float, repeat: int, work: Path) -> dict:
    """``fabricate_file`` of ``fold`` in a fresh subprocess ``repeat`` times."""
    rows = []
    for k in range(repeat):
        out = work / f"{fold.stem}_{k}"
        t0 = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-c", CHILD, str(fold), str(out), str(thickness)],
            capture_output=True,
            text=True,
            check=True,
        )
        row = json.loads(done.stdout.strip().splitlines()[-1])
        row["wall"] = time.perf_counter() - t0
        rows.append(row)
    return rows[0] | {
        "seconds": statistics.median(r["seconds"] for r in rows),
        "wall": statistics.median(r["wall"] for r in rows),
        "peak_mb": max(r["peak_mb"] for r in rows),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--miura", default="10,16,23,27,40,55")
    parser.add_argument("--grid", default="12,17")
    parser.add_argument("--fold", nargs="*", default=[], metavar="FILE")
    parser.add_argument("--thickness", type=float, default=0.02)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    sizes = lambda text: [int(x) for x in text.split(",") if x]  # noqa: E731
    print(
        f"{'design':<22} {'panels':>6} {'frames':>6} {'status':<20} {'sheets':>6} "
        f"{'fabricate s':>11} {'process s':>9} {'peak MB':>8}"
    )
    miura_rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        designs = [
            (f"miura {n}", write_miura(n, work / f"miura_{n}.fold")) for n in sizes(args.miura)
        ]
        designs += [(f"grid {n}", write_grid(n, work / f"grid_{n}.fold")) for n in sizes(args.grid)]
        designs += [(Path(f).name, Path(f)) for f in args.fold]
        for name, fold in designs:
            row = run(fold, args.thickness, args.repeat, work)
            print(
                f"{name:<22} {row['panels']:>6} {row['frames']:>6} {row['status']:<20} "
                f"{row['sheets']:>6} {row['seconds']:>11.1f} {row['wall']:>9.1f} "
                f"{row['peak_mb']:>8.0f}",
                flush=True,
            )
            if name.startswith("miura"):
                miura_rows.append(row)
    if len(miura_rows) >= 2:
        a, b = miura_rows[0], miura_rows[-1]
        slope = math.log(b["seconds"] / a["seconds"]) / math.log(b["panels"] / a["panels"])
        print(f"log-log slope of the time against the panels (Miura-ori): {slope:.2f}")
    print(f"(this process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB)")


if __name__ == "__main__":
    main()
