"""Benchmark of the drive (issue 48): ``rigidfold.drive.deploy_design`` on the 722-panel
DOF-1 design of the fabrication benchmark (``benchmarks/bench_fabricate_scale.py``'s
waterbomb on the hyperbolic paraboloid).

Run with ``python benchmarks/bench_drive.py --fold FILE [--repeat 3] [--thickness 0.02]``,
FILE the design (``out/wb/solutions/step_NN_dof_01.fold`` of)::

    rigidfold generate --surface hp --pattern tests/data/origami_simulator/huffmanWaterbomb.svg \\
        --lookahead --no-deform --quiet --out out/wb

Without ``--fold`` that run is made first (not timed; minutes), into a temporary directory.
Then ``--repeat`` times in this process (median printed; the first call also pays the
imports, so at least 3 are advised): ``deploy_design`` with every option that costs (auto
base, auto cables, the OpenSees check of ``Settings.drive.check_states`` states), its steps
timed apart (:attr:`rigidfold.drive.DriveResult.seconds`): reading and the DOF, the motion
(the file's frames refined to 1 degree per state by continuation), **every crease and every
base ranked** (the masses and energy of every base, the lowest point of every placement at
every state, the best crease of each base; then the chosen base's creases, the pair where
needed and the cables; target <= 10 s), and **the OpenSees check** (target <= 60 s).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from rigidfold.drive import DriveOptions, deploy_design

COMMAND = [
    "generate",
    "--surface",
    "hp",
    "--pattern",
    "tests/data/origami_simulator/huffmanWaterbomb.svg",
    "--lookahead",
    "--no-deform",
    "--quiet",
]


def make_design(work: Path) -> Path:
    """Generate the waterbomb's DOF-1 design into ``work`` (the fabrication benchmark's)."""
    root = Path(__file__).resolve().parent.parent
    out = work / "wb"
    subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *COMMAND, "--out", str(out)], check=True, cwd=root
    )
    (design,) = sorted((out / "solutions").glob("*_dof_01.fold"))
    return design


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fold", type=Path, help="the DOF-1 design (default: generate it)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--thickness", type=float, default=0.02)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-drive-") as tmp:
        fold = args.fold if args.fold is not None else make_design(Path(tmp))
        options = DriveOptions(thickness=args.thickness, cables_auto=True)
        rows, result = [], None
        for k in range(args.repeat):
            result = deploy_design(fold, options, Path(tmp) / f"out{k}")
            rows.append(result.seconds)
        assert result is not None
        median = {key: statistics.median(r[key] for r in rows) for key in rows[0]}
        ranking = median["bases"] + median["drives"]
        pattern = result.pattern
        panels = len(result.bases)
        print(
            f"design {fold.name}: V {pattern.n_vertices}, {panels} panels, "
            f"{len(result.ranking)} hinges, {len(result.s)} states ({result.motion['source']})"
        )
        print(f"median of {args.repeat}:")
        print(f"  read and DOF                  {median['read']:7.2f} s")
        print(f"  motion (refined)              {median['motion']:7.2f} s")
        print(
            f"  every crease and base ranked  {ranking:7.2f} s  "
            f"(target <= 10 s: {'met' if ranking <= 10 else 'NOT met'}; bases "
            f"{median['bases']:.2f} s, drives {median['drives']:.2f} s)"
        )
        check = result.check
        print(
            f"  OpenSees check, {len(check.states)} states   {median['check']:7.2f} s  "
            f"(target <= 60 s: {'met' if median['check'] <= 60 else 'NOT met'}; "
            f"{check.status.value}: {check.message})"
        )
        print(f"  {result.status.value}: {result.summary_line()}")


if __name__ == "__main__":
    main()
