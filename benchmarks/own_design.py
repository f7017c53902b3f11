"""The figures of issue 16's checks: the dome as an OBJ mesh against the built-in dome, and the
check of a finished ``generate`` run (every solution accepted, no lock, the plan's span).

    python benchmarks/own_design.py                 # the OBJ dome (121 x 121 vertices)
    python benchmarks/own_design.py --run DIR       # and a generate run, e.g. the 12 m x 8 m roof:
        rigidfold generate --pattern grid:15x9 --size 12x8 --surface expr \\
            --expr "0.06*x*(12-x)/6 + 0.05*y*(8-y)" --quiet --out DIR
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from rigidfold.generate.specs import case_from_specs
from rigidfold.pipeline.workflows import analyze_file
from rigidfold.surfaces import Dome, sample_mesh


def obj_dome(n: int) -> None:
    """optimize --pattern 11 on the dome given as an n x n OBJ mesh, beside the built-in dome."""
    import trimesh

    dome = Dome()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "dome.obj"
        trimesh.Trimesh(*sample_mesh(dome, n), process=False).export(path)
        case = case_from_specs(f"mesh:{path}", "11")
    mesh = case.problem().solve()
    built_in = case_from_specs("dome", "11").problem().solve()
    xyz = mesh.pattern.coords
    x, y = np.meshgrid(np.linspace(0, 3, 601), np.linspace(0, 3, 601))
    print(f"OBJ dome, {n} x {n} vertices, optimize --pattern 11:")
    print(f"  {mesh.status.value}: F = {mesh.F:.3g}, {mesh.iterations} iterations")
    print(f"  built-in dome: F = {built_in.F:.3g}, {built_in.iterations} iterations")
    off_dome = np.abs(xyz[:, 2] - dome.height(xyz[:, 0], xyz[:, 1])).max()
    fit_vs_dome = np.abs(case.surface.height(x, y) - dome.height(x, y)).max()
    print(f"  max |z - analytic dome| = {off_dome:.3g} m")
    print(f"  fit error against the mesh = {case.surface.fit_error:.3g} m")
    print(f"  max |fit - analytic dome| (601 x 601) = {fit_vs_dome:.3g} m")


def check_run(directory: Path) -> None:
    """Every solution of a generate run: F, locked creases, DOF, and the final plan's span."""
    files = sorted((directory / "solutions").glob("*.fold"))
    if not files:
        raise SystemExit(f"{directory}: no solutions/*.fold")
    analyses = [analyze_file(f) for f in files]
    worst = max(a.data.metadata["F"] for a in analyses)
    locks = sum(len(a.mechanism.locked_creases) for a in analyses)
    span = np.ptp(analyses[-1].data.pattern.coords[:, :2], axis=0)
    print(f"{directory}: {len(files)} solutions, max F = {worst:.3g}, {locks} locked creases,")
    print(f"  final DOF {analyses[-1].mechanism.dof}, plan span {span[0]:.3f} m x {span[1]:.3f} m")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vertices", type=int, default=121, help="of the OBJ dome, per side")
    ap.add_argument("--run", type=Path, help="a finished generate run to check")
    args = ap.parse_args()
    obj_dome(args.vertices)
    if args.run is not None:
        check_run(args.run)


if __name__ == "__main__":
    main()
