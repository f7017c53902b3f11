"""Benchmark of problem (6): one solve per case and solver, medians, solver ratios.

Run with ``make bench`` (or ``python benchmarks/bench_optimize.py [--seeds 5] [--quick]``).

Cases: pattern 1 and pattern 2 on random Bezier surfaces (``--seeds`` seeds each), and the
11 x 11 grid on the dome and the HP, with and without their two mirror planes. Solvers:
IPOPT (exact Hessian, CasADi), SLSQP with CasADi's exact gradients, and SLSQP with SciPy's
finite differences (the paper's set-up; pattern 1 only, as it is slow). Every solve starts
from the triangulated target surface with no fixed crease, as the paper's first solve.

The model build (CasADi expressions and IPOPT's Hessian) is reported apart from the solve.
Ratios are medians measured in this same run. The paper's figures (Section 6, Xeon E5-1620 v3,
SLSQP with finite differences) are printed beside them for reference.
"""

from __future__ import annotations

import argparse
import statistics
import time

from rigidfold.generate.specs import case_from_specs

PAPER_SECONDS = {"pattern 1": 72.4, "pattern 2": 79.3, "dome sym": 202, "dome asym": 1015}
PAPER_SECONDS.update({"hp sym": 218, "hp asym": 1133})


def cases(seeds: int):
    for name, pattern in (("pattern 1", "1"), ("pattern 2", "2")):
        yield name, [case_from_specs("bezier", pattern, seed=s) for s in range(seeds)]
    for surface in ("dome", "hp"):
        for sym in (True, False):
            label = f"{surface} {'sym' if sym else 'asym'}"
            yield label, [case_from_specs(surface, "11", symmetric=sym)]


def run(args: argparse.Namespace) -> None:
    rows = []
    for label, group in cases(args.seeds):
        solvers = ["ipopt", "slsqp"] + (["slsqp-fd"] if label == "pattern 1" else [])
        if args.quick and label != "pattern 1":
            solvers = ["ipopt"]
        builds, times = [], {s: [] for s in solvers}
        accepted = {s: 0 for s in solvers}
        n_var = None
        for case in group:
            t0 = time.perf_counter()
            problem = case.problem(build_ipopt=True)
            builds.append(time.perf_counter() - t0)
            n_var = problem.n_variables
            for solver in solvers:
                runs = []
                for _ in range(args.repeat if solver == "ipopt" else 1):
                    result = problem.solve(solver=solver)
                    runs.append(result.wall_time)
                times[solver].append(statistics.median(runs))
                accepted[solver] += result.converged
        rows.append((label, n_var, len(group), statistics.median(builds), times, accepted))
        print_row(rows[-1])
    print_ratios(rows)


def print_row(row) -> None:
    label, n_var, count, build, times, accepted = row
    parts = [f"{label:<10} n={n_var:<4} cases={count}  build {build:6.3f} s"]
    for solver, values in times.items():
        parts.append(
            f"{solver} {statistics.median(values):7.3f} s ({accepted[solver]}/{count} accepted)"
        )
    paper = PAPER_SECONDS.get(label)
    parts.append(f"paper {paper:g} s" if paper else "")
    print("  ".join(parts), flush=True)


def print_ratios(rows) -> None:
    print("\nmedian solve-time ratios (same run):")
    for label, _, _, _, times, _ in rows:
        ipopt = statistics.median(times["ipopt"])
        text = [f"{label:<10}"]
        for other in ("slsqp", "slsqp-fd"):
            if other in times:
                text.append(f"{other}/ipopt = {statistics.median(times[other]) / ipopt:6.1f}x")
        if label in PAPER_SECONDS:
            text.append(f"paper/ipopt = {PAPER_SECONDS[label] / ipopt:8.0f}x")
        print("  ".join(text))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5, help="Bezier seeds per pattern (>= 5)")
    parser.add_argument("--repeat", type=int, default=3, help="IPOPT repeats per case (median)")
    parser.add_argument("--quick", action="store_true", help="IPOPT only beyond pattern 1")
    run(parser.parse_args())


if __name__ == "__main__":
    main()
