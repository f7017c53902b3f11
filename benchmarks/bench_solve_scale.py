"""Form finding at scale (issue 19): build and one solve of problem (6) per grid size.

Run with ``python benchmarks/bench_solve_scale.py [--grids 7,11,21,31,41] [--repeat 3]
[--seeds 5] [--no-reference]``.

Cases: square grids ``grid:NxN`` spanning 3 m with diagonals towards the centre, lifted onto
the dome, one IPOPT solve from the lifted shape with no crease fixed (the issue's table); and
the paper's size for comparison: pattern 1 on ``--seeds`` random Bezier surfaces and the
11 x 11 grid on the dome. Each build (``case.problem()``: the model, the elimination of
(7)-(9), IPOPT and its Hessian) and each solve is timed ``--repeat`` times; printed are
medians of wall-clock and CPU seconds (CPU of this process, all its threads: on a shared
machine it is the steadier figure), IPOPT iterations, the sizes of the Jacobian and Hessian
handed to IPOPT, and the fitted log-log slope of build and solve time against V over the
grids from 121 vertices on.

From ``Settings.solver.projection_vertices`` (200) on, the solver is IPOPT stopped at F <=
``ipopt_stop_f`` and finished by the projection (``rigidfold.optimize.projection``). Each grid
is also solved, in the same process, by IPOPT alone (``projection_vertices`` above the grid's
size: the reference, as before the projection) and the ratio printed; and both solve a step
of ``generate``: from the solution, with the crease folded least (above 1e-3 rad) fixed.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import SolverName

IPOPT_ALONE = DEFAULTS.with_(projection_vertices=10**9)


def timed(fn):
    """(result, wall seconds, CPU seconds) of ``fn()``."""
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def measure(case, repeat: int) -> dict:
    """Medians over ``repeat`` builds and solves of one case."""
    rows = []
    for _ in range(repeat):
        problem, build_wall, build_cpu = timed(case.problem)
        result, solve_wall, solve_cpu = timed(problem.solve)
        rho = np.abs(result.pattern.fold_angles)
        folded = np.flatnonzero(~result.pattern.is_boundary_edge & (rho > 1e-3))
        fixed = result.pattern.fixed.copy()
        fixed[folded[np.argmin(rho[folded])]] = True
        step, step_wall, _ = timed(lambda: problem.solve(fixed=fixed, start=result.coords))  # noqa: B023
        rows.append((build_wall, build_cpu, solve_wall, solve_cpu, step_wall))
    nlpsol = problem.solver(SolverName.IPOPT).nlpsol
    medians = [statistics.median(column) for column in zip(*rows, strict=True)]
    return {
        "V": case.pattern.n_vertices,
        "n": problem.n_variables,
        "jac_nnz": nlpsol.get_function("nlp_jac_g").sparsity_out(1).nnz(),
        "hess_nnz": nlpsol.get_function("nlp_hess_l").sparsity_out(0).nnz(),
        "build_wall": medians[0],
        "build_cpu": medians[1],
        "solve_wall": medians[2],
        "solve_cpu": medians[3],
        "step_wall": medians[4],
        "iterations": result.iterations,
        "step_iterations": step.iterations,
        "F": result.F,
        "status": str(result.status),
    }


def slope(rows: list[dict], key: str) -> float:
    """Fitted log-log slope of ``key`` against V over the rows with V >= 121."""
    used = [r for r in rows if r["V"] >= 121]
    if len(used) < 2:
        return float("nan")
    return float(np.polyfit(np.log([r["V"] for r in used]), np.log([r[key] for r in used]), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grids", default="7,11,21,31,41")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--no-reference", action="store_true", help="skip IPOPT alone")
    args = parser.parse_args()

    print("paper's size (medians of --repeat; pattern 1: median over seeds)")
    paper = [
        measure(case_from_specs("bezier", "1", seed=s), args.repeat) for s in range(args.seeds)
    ]
    dome11 = measure(case_from_specs("dome", "11"), args.repeat)
    for label, rows in (("pattern 1", paper), ("dome 11x11", [dome11])):
        med = {k: statistics.median(r[k] for r in rows) for k in rows[0] if k != "status"}
        print(
            f"  {label:<11} build {med['build_wall']:.3f} s (cpu {med['build_cpu']:.3f})"
            f"  solve {med['solve_wall']:.3f} s (cpu {med['solve_cpu']:.3f})"
            f"  iterations {med['iterations']:g}",
            flush=True,
        )

    print("\ngrid on the dome, one solve from the lifted shape, then one step of generate")
    header = (
        f"{'grid':>7} {'V':>5} {'n':>5} {'jac nnz':>8} {'hess nnz':>8} {'build s':>8} "
        f"{'(cpu)':>7} {'solve s':>8} {'(cpu)':>7} {'iter':>5} {'step s':>7} {'iter':>5} "
        f"{'alone s':>8} {'ratio':>6} {'step s':>7} {'ratio':>6}  F"
    )
    print(header)
    rows = []
    for g in (int(text) for text in args.grids.split(",")):
        r = measure(case_from_specs("dome", f"grid:{g}x{g}", size="3x3"), args.repeat)
        ref = {"solve_wall": float("nan"), "step_wall": float("nan")}
        if not args.no_reference:
            ref = measure(
                case_from_specs("dome", f"grid:{g}x{g}", size="3x3", settings=IPOPT_ALONE),
                args.repeat,
            )
        rows.append(r)
        print(
            f"{g:>3} x {g:<3}{r['V']:>5} {r['n']:>5} {r['jac_nnz']:>8} {r['hess_nnz']:>8} "
            f"{r['build_wall']:>8.3f} {r['build_cpu']:>7.3f} {r['solve_wall']:>8.3f} "
            f"{r['solve_cpu']:>7.3f} {r['iterations']:>5} {r['step_wall']:>7.3f} "
            f"{r['step_iterations']:>5} {ref['solve_wall']:>8.3f} "
            f"{ref['solve_wall'] / r['solve_wall']:>6.2f} {ref['step_wall']:>7.3f} "
            f"{ref['step_wall'] / r['step_wall']:>6.2f}  {r['F']:.1e} {r['status']}",
            flush=True,
        )
    print("(alone: IPOPT without the projection; ratio: its time over the default's)")
    print(
        "\nlog-log slope against V (V >= 121): "
        f"build {slope(rows, 'build_wall'):.2f} (cpu {slope(rows, 'build_cpu'):.2f}), "
        f"solve {slope(rows, 'solve_wall'):.2f} (cpu {slope(rows, 'solve_cpu'):.2f}), "
        f"step {slope(rows, 'step_wall'):.2f}, "
        f"iterations {slope(rows, 'iterations'):.2f}, "
        f"Jacobian nnz {slope(rows, 'jac_nnz'):.2f}, Hessian nnz {slope(rows, 'hess_nnz'):.2f}"
    )


if __name__ == "__main__":
    main()
