"""Compare the selection criteria on random Bezier surfaces (Tables 5 and 6 of the paper).

    python benchmarks/study_criteria.py [--seeds 20] [--patterns 1 2] [--jobs 2]

For each pattern and criterion, runs ``generate`` (target DOF 1, no deformation check) on
Bezier seeds 0..N-1 and prints the means of N_reduce, N_lock, N_exceed and F (the mean
over each run's accepted solutions, then over runs), next to the paper's Tables 5 and 6
(100 surfaces each); each count is followed by the standard error of its mean. The full
100-surface study with its database is a separate tool.
"""

from __future__ import annotations

import argparse
import statistics
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

PAPER = {
    ("1", "s"): (20.00, 1.13, 0.04, 1.18e-9),
    ("1", "shat"): (20.00, 0.06, 0.01, 1.38e-9),
    ("1", "ss"): (19.97, 24.94, 0.03, 2.19e-9),
    ("1", "random"): (19.99, 7.32, 0.20, 2.44e-9),
    ("2", "s"): (19.96, 2.74, 0.00, 1.17e-9),
    ("2", "shat"): (19.97, 0.92, 0.02, 1.28e-9),
    ("2", "ss"): (19.73, 28.60, 0.14, 1.93e-9),
    ("2", "random"): (19.81, 13.32, 0.19, 4.41e-9),
}


def support_face(case, corner: str) -> int | None:
    """The triangle nearest a plan point "x,y" (None: rigidfold's default, nearest the centroid)."""
    if corner == "centroid":
        return None
    point = np.array([float(v) for v in corner.split(",")])
    bary = case.pattern.coords[case.pattern.faces].mean(axis=1)[:, :2]
    return int(np.argmin(np.linalg.norm(bary - point, axis=1)))


COUNTS = ("n_reduce", "n_lock", "n_exceed")


def standard_error(values: list[float]) -> float:
    """Standard error of the mean of ``values`` (0 for fewer than two)."""
    return statistics.stdev(values) / len(values) ** 0.5 if len(values) > 1 else 0.0


def one_run(args: tuple[str, str, int, str, str]) -> dict:
    from rigidfold.generate import generate
    from rigidfold.generate.specs import case_from_specs

    pattern, criterion, seed, solver, support = args
    t0 = time.perf_counter()
    case = case_from_specs("bezier", pattern, seed=seed)
    run = generate(
        case,
        criterion=criterion,
        seed=seed,
        solver=solver,
        support_face=support_face(case, support),
    )
    summary = run.to_dict()
    summary["wall_s"] = time.perf_counter() - t0
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--patterns", nargs="+", default=["1", "2"])
    parser.add_argument("--criteria", nargs="+", default=["shat", "s", "ss", "random"])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--solver", default="ipopt", choices=["ipopt", "slsqp"])
    parser.add_argument(
        "--support",
        default="centroid",
        help='frame support: "centroid" (default) or the triangle nearest a plan point "x,y"',
    )
    args = parser.parse_args()
    header = (
        f"{'pattern':<8}{'criterion':<10}{'N_reduce':>14}{'N_lock':>14}{'N_exceed':>14}"
        f"{'mean F':>10}{'DOF 1':>7}{'wall s':>8}   paper: N_reduce N_lock N_exceed F"
    )
    print(header)
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for pattern in args.patterns:
            for criterion in args.criteria:
                jobs = [
                    (pattern, criterion, s, args.solver, args.support) for s in range(args.seeds)
                ]
                runs = list(pool.map(one_run, jobs))
                means = {k: statistics.mean(r[k] for r in runs) for k in COUNTS}
                errors = {k: standard_error([r[k] for r in runs]) for k in COUNTS}
                wall = statistics.median(r["wall_s"] for r in runs)
                fs = [r["mean_f_accepted"] for r in runs if r["mean_f_accepted"] is not None]
                reached = sum(r["final_dof"] == 1 for r in runs)
                p = PAPER.get((pattern, criterion))
                paper = f"{p[0]:.2f} {p[1]:.2f} {p[2]:.2f} {p[3]:.2e}" if p else ""
                print(
                    f"{pattern:<8}{criterion:<10}"
                    + "".join(f"{means[k]:>7.2f} ±{errors[k]:<5.2f}" for k in COUNTS)
                    + f"{statistics.mean(fs):>10.2e}"
                    f"{reached:>4}/{len(runs):<3}{wall:>7.1f}"
                    f"   {paper}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
