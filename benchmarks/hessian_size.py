"""Size of IPOPT's Hessian of the Lagrangian and its share of one solve of problem (6).

Run with ``python benchmarks/hessian_size.py [--patterns 1 2] [--seed 7]``.

Per Bezier pattern: the number of variables, the nonzeros of the Hessian, the number of
CasADi SX instructions that evaluate it, and, for the first solve from the target surface,
the IPOPT iterations, the wall time of the solve and the part of it spent in the Hessian.
"""

from __future__ import annotations

import argparse

from rigidfold.case import make_case
from rigidfold.optimize.ipopt import ipopt_solver


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patterns", nargs="+", default=["1", "2"])
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    for name in args.patterns:
        try:
            problem = make_case("bezier", name, seed=args.seed).problem()
        except ValueError as exc:
            parser.error(str(exc))
        result = problem.solve()
        solver = ipopt_solver(problem)
        hess = solver.get_function("nlp_hess_l")
        stats = solver.stats()
        t_hess = stats["t_wall_nlp_hess_l"]
        print(
            f"pattern {name:<3} n={problem.map.n_variables}  Hessian nnz "
            f"{hess.sparsity_out(0).nnz()}  SX instructions {hess.n_instructions()}  "
            f"solve {result.iterations} iterations {result.wall_time:.3f} s, "
            f"Hessian {t_hess:.3f} s ({t_hess / result.wall_time:.0%})",
            flush=True,
        )


if __name__ == "__main__":
    main()
