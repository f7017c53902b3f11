"""A whole generation run on a large grid (issue 19): Steps 2-7 to the target DOF.

Run with ``python benchmarks/bench_generate_scale.py [--grid 41] [--criterion s]
[--lookahead] [--ipopt-alone]``; ``--ipopt-alone`` solves every step with IPOPT only
(``Settings.solver.projection_vertices`` above the grid's size: rigidfold before the projection).

The case is the issue's: ``grid:NxN`` spanning 3 m with diagonals towards the centre, on the
dome, criterion S, no Step 9 (``generate`` itself, as ``rigidfold generate --pattern
grid:41x41 --size 3x3 --surface dome --criterion s --no-deform`` runs it). Printed: the wall
time to the lowest DOF, the number of solves, N_lock and N_exceed, how the solves ended
(the projection alone, or IPOPT and then the projection), the medians and totals of the
solve and analysis times per attempt, and the five slowest solves with the solver's words.
"""

from __future__ import annotations

import argparse
import statistics
import time

from rigidfold.config import DEFAULTS
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=41)
    parser.add_argument("--criterion", default="s")
    parser.add_argument("--lookahead", action="store_true")
    parser.add_argument("--ipopt-alone", action="store_true")
    args = parser.parse_args()
    settings = DEFAULTS.with_(projection_vertices=10**9) if args.ipopt_alone else DEFAULTS
    case = case_from_specs("dome", f"grid:{args.grid}x{args.grid}", size="3x3", settings=settings)
    messages: list[tuple[float, str]] = []  # (seconds, the solver's words) of every solve
    build = case.problem

    def recording_problem(*a, **kw):
        problem = build(*a, **kw)
        solve = problem.solve

        def recording_solve(*sa, **skw):
            result = solve(*sa, **skw)
            messages.append((result.wall_time, result.message))
            return result

        problem.solve = recording_solve
        return problem

    object.__setattr__(case, "problem", recording_problem)  # Case is a frozen dataclass
    t0 = time.perf_counter()
    run = generate(case, criterion=args.criterion, lookahead=args.lookahead)
    wall = time.perf_counter() - t0
    solve = [a.solve_time for a in run.attempts]
    analysis = [a.analysis_time for a in run.attempts]
    summary = run.to_dict()
    print(
        f"grid {args.grid} x {args.grid} (V = {case.pattern.n_vertices}) on the dome, "
        f"criterion {args.criterion}{', look-ahead' if args.lookahead else ''}"
        f"{', IPOPT alone' if args.ipopt_alone else ''}"
    )
    print(
        f"{run.stop_reason}: DOF {summary['initial_dof']} -> {summary['final_dof']} in "
        f"{wall:.1f} s ({wall / 60:.1f} min), {len(run.attempts)} solves, "
        f"N_lock {run.n_lock}, N_exceed {run.n_exceed}"
    )
    with_ipopt = sum("IPOPT" in message for _, message in messages)
    print(f"solves by the projection alone: {len(messages) - with_ipopt}, with IPOPT: {with_ipopt}")
    print(
        f"per attempt: solve median {statistics.median(solve):.2f} s (total {sum(solve):.1f} s, "
        f"largest {max(solve):.1f} s), analysis median {statistics.median(analysis):.2f} s "
        f"(total {sum(analysis):.1f} s); build {run.build_time:.1f} s"
    )
    print("slowest solves:")
    for seconds, message in sorted(messages, reverse=True)[:5]:
        print(f"  {seconds:7.2f} s  {message}")


if __name__ == "__main__":
    main()
