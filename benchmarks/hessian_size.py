"""IPOPT's Hessian of the Lagrangian: CasADi's symbolic one against the closed-form one.

Run with ``python benchmarks/hessian_size.py [--patterns 1 2] [--seed 7] [--repeats 7]``.

Per Bezier pattern, for both settings of ``Settings.solver.ipopt_hessian`` in the same process: the
nonzeros of the Hessian, the number of CasADi SX instructions of the symbolic one, the median
wall time of one Hessian evaluation inside IPOPT, and the median wall time of the first solve
of (6) from the target surface (``repeats`` solves each, interleaved), with the ratio
casadi / closed-form.
"""

from __future__ import annotations

import argparse
import statistics

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import SolverName

BACKENDS = ("casadi", "closed-form")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patterns", nargs="+", default=["1", "2"])
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1, got {args.repeats}")
    for name in args.patterns:
        problems = {}
        for backend in BACKENDS:
            try:
                case = case_from_specs(
                    "bezier", name, seed=args.seed, settings=DEFAULTS.with_(ipopt_hessian=backend)
                )
            except ValueError as exc:
                parser.error(str(exc))
            problems[backend] = case.problem()
        solve = {b: [] for b in BACKENDS}
        per_call = {b: [] for b in BACKENDS}
        for _ in range(args.repeats):
            for backend, problem in problems.items():
                result = problem.solve()
                stats = problem.solver(SolverName.IPOPT).nlpsol.stats()
                solve[backend].append(result.wall_time)
                per_call[backend].append(stats["t_wall_nlp_hess_l"] / stats["n_call_nlp_hess_l"])
        symbolic = problems["casadi"].solver(SolverName.IPOPT).nlpsol.get_function("nlp_hess_l")
        print(
            f"pattern {name:<3} n={problems['casadi'].n_variables}  Hessian nnz "
            f"{symbolic.sparsity_out(0).nnz()}, {symbolic.n_instructions()} SX instructions; "
            f"{result.iterations} iterations per solve"
        )
        for backend in BACKENDS:
            print(
                f"  {backend:<12} Hessian {1e3 * statistics.median(per_call[backend]):6.2f} ms "
                f"per evaluation, solve {statistics.median(solve[backend]):.3f} s (median of "
                f"{args.repeats})"
            )
        ratio = statistics.median(solve["casadi"]) / statistics.median(solve["closed-form"])
        hess_ratio = statistics.median(per_call["casadi"]) / statistics.median(
            per_call["closed-form"]
        )
        print(f"  casadi / closed-form: Hessian {hess_ratio:.2f}x, solve {ratio:.2f}x", flush=True)


if __name__ == "__main__":
    main()
