"""Diagnostic: the exact and near mechanisms of a run's saved shapes, and of a shape's children.

Run with::

    python benchmarks/chain_spectrum.py RUN/solutions [--steps 19,20]
    python benchmarks/chain_spectrum.py RUN/solutions --steps 71 --children 25 \\
        --surface dome --pattern tests/data/origami_simulator/miura_sharpangle.svg
    python benchmarks/chain_spectrum.py RUN/solutions --steps 67 --children 25 \\
        --surface dome --pattern ... --paths [--turn-back 100]

For each saved shape (``step_NN_dof_MM.fold`` of ``rigidfold generate``) it prints the DOF
counted with the gap (``Settings.mechanism.dof_gap`` times the rank threshold, the search's
count), the exact DOF (at the rank threshold), the smallest singular values over the largest,
and how many free creases turn in the counted and in the exact mechanisms (rows of H_phi
above 1e-3 of the largest). With ``--children N`` (one step, and the run's case given as
``generate`` takes it) the N creases that turn least in the shape's exact mechanisms are
fixed one at a time and solved from its coordinates, and each child is printed the same way,
with whether it locks a crease. With ``--paths`` the path of each DOF-1 child without a
lock is traced (:func:`rigidfold.mechanism.path.trace_path`; ``--turn-back`` sets
``Settings.path.turn_back``) and printed with the largest rise of its folding measure above
its running low. ``docs/broad_set.md`` (sessions 36-37) quotes its figures.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import read_fold
from rigidfold.mechanism import Mechanism, analyze
from rigidfold.mechanism.path import trace_path
from rigidfold.mesh import CreasePattern

MOVING = 1e-3
"""A crease turns in a set of mechanisms when its row of H_phi is above this of the largest."""


def turning(mech: Mechanism) -> np.ndarray:
    """(h,) bool: the free creases that turn in ``mech``'s modes."""
    rows = np.linalg.norm(mech.H_phi, axis=1)
    return rows > MOVING * rows.max(initial=0.0)


def describe(shape: CreasePattern) -> tuple[str, Mechanism, Mechanism]:
    """One line on a shape: counted and exact DOF, smallest singular values, turning creases;
    with its two analyses (the gap count's, the rank threshold's)."""
    m = DEFAULTS.mechanism
    counted = analyze(shape, settings=DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap))
    exact = analyze(shape)
    values = np.sort(counted.rank_values / counted.rank_scale)[: counted.dof + 2]
    line = (
        f"counted {counted.dof:3d}  exact {exact.dof:3d}  fixed {int(shape.fixed.sum()):4d}  "
        f"turning {int(turning(counted).sum())}/{len(counted.hinges)} (exact "
        f"{int(turning(exact).sum()) if exact.dof else 0})  lock {counted.has_lock}  "
        f"smallest {np.array2string(values[:6], precision=1)}"
    )
    return line, counted, exact


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("solutions", type=Path, help="a run's solutions folder")
    parser.add_argument("--steps", default=None, help="comma-separated steps (default: all)")
    parser.add_argument("--children", type=int, default=0, help="children of one step to solve")
    parser.add_argument("--surface", default=None)
    parser.add_argument("--pattern", default=None)
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--paths", action="store_true", help="trace the DOF-1 children's paths")
    parser.add_argument("--turn-back", type=float, default=None, help="Settings.path.turn_back")
    args = parser.parse_args(argv)
    wanted = None if args.steps is None else {int(s) for s in args.steps.split(",")}
    files = sorted(args.solutions.glob("step_*.fold"))
    shapes: dict[int, CreasePattern] = {}
    for path in files:
        found = re.match(r"step_(\d+)_dof_\d+\.fold$", path.name)
        if found is None or (wanted is not None and int(found.group(1)) not in wanted):
            continue
        step = int(found.group(1))
        shapes[step] = read_fold(path).pattern
        print(f"step {step:3d}  {describe(shapes[step])[0]}", flush=True)
    if not args.children:
        return 0
    if len(shapes) != 1 or args.surface is None or args.pattern is None:
        parser.error("--children takes one step (--steps) and the run's --surface and --pattern")
    ((step, shape),) = shapes.items()
    settings = DEFAULTS if args.turn_back is None else DEFAULTS.with_(path_turn_back=args.turn_back)
    case = case_from_specs(args.surface, args.pattern, seed=args.seed)
    problem = case.problem()
    _, counted, exact = describe(shape)
    rows = np.linalg.norm(counted.H_phi, axis=1)
    share = np.linalg.norm(exact.H_phi, axis=1) / np.maximum(rows, np.finfo(float).tiny)
    order = [j for j in np.argsort(share, kind="stable") if rows[j] > MOVING * rows.max()]
    for j in order[: args.children]:
        crease = int(counted.hinges[j])
        fixed = shape.fixed.copy()
        fixed[crease] = True
        result = problem.solve(fixed=fixed, start=shape.coords)
        if not result.converged:
            print(f"  crease {crease:4d}  {result.status.value}")
            continue
        moved = float(np.abs(result.coords - shape.coords).max())
        line, child, _ = describe(result.pattern)
        print(f"  crease {crease:4d}  share {share[j]:.1e}  moved {moved:.1e}  {line}", flush=True)
        if args.paths and child.dof == 1 and not child.has_lock:
            path = trace_path(result.pattern, dof=1, settings=settings)
            rise = float(np.max(path.measure - np.minimum.accumulate(path.measure)))
            print(
                f"      path {path.status.value}  lowest m {path.measure.min():.3f}  "
                f"rise {rise:.3f}  steps {path.steps}: {path.message}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
