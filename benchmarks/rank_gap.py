"""Diagnostic: the singular values around the DOF cut of every accepted shape of one run.

Run with ``python benchmarks/rank_gap.py [--pattern 2] [--criterion ss] [--seed 7]
[--rank-tol 1e-9] [--solver ipopt]``.

For each accepted solution of ``generate`` it prints the DOF, its change from the shape
before (one more fixed crease), and the smallest singular values of the kinematic constraint
matrix relative to the largest: the DOF counted ones plus the next two. Values near 1e-16
are modes of the shape; values of 1e-12 to 1e-8 are near-singular directions that
``Settings.mechanism.rank_tol`` decides about; the genuine non-zero values are 1e-5 and up.
The shapes whose DOF stays or rises after a fix ("How fixing a crease changes the DOF" in
the study report) are the ones to look at.
"""

from __future__ import annotations

import argparse

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import kinematics


def relative_singular_values(solution) -> np.ndarray:
    """Singular values of the constraint matrix of an accepted shape over the largest,
    ascending, padded with zeros to the number of unknowns: (n,) float64."""
    frame = solution.mechanism.frame
    C = kinematics.constraint_matrix(solution.result.pattern, frame.support_face).toarray()
    sv = np.linalg.svd(C, compute_uv=False)
    full = np.concatenate([sv, np.zeros(max(0, C.shape[1] - len(sv)))])
    return np.sort(full / sv[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pattern", default="2")
    parser.add_argument("--criterion", default="ss")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--rank-tol", type=float, default=DEFAULTS.mechanism.rank_tol)
    parser.add_argument("--solver", default="ipopt", choices=["ipopt", "slsqp"])
    args = parser.parse_args()
    if not 0 < args.rank_tol < 1:
        parser.error(f"--rank-tol must be in (0, 1), got {args.rank_tol:g}")
    try:
        settings = DEFAULTS.with_(mechanism_rank_tol=args.rank_tol)
        case = case_from_specs("bezier", args.pattern, seed=args.seed, settings=settings)
    except ValueError as exc:
        parser.error(str(exc))
    previous: list[int] = []

    def on_solution(run, solution) -> None:
        dof = solution.mechanism.dof
        step = f"{dof - previous[-1]:+d}" if previous else "  "
        previous.append(dof)
        rel = relative_singular_values(solution)[: dof + 2]
        values = " ".join(f"{x:.1e}" for x in rel)
        print(f"solution {solution.step:3d}  DOF {dof:2d} ({step})  {values}", flush=True)

    try:
        run = generate(
            case,
            criterion=args.criterion,
            seed=args.seed,
            solver=args.solver,
            on_solution=on_solution,
        )
    except ValueError as exc:
        parser.error(str(exc))
    print(
        f"pattern {args.pattern} {args.criterion} seed {args.seed} {args.solver} "
        f"rank tol {args.rank_tol:g}: "
        f"N_lock {run.n_lock}, N_reduce {run.n_reduce}, {len(run.attempts)} solves, "
        f"{run.stop_reason}"
    )


if __name__ == "__main__":
    main()
