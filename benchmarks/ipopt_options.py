"""Try extra IPOPT options on generation runs, against the defaults in the same process.

Run with ``python benchmarks/ipopt_options.py --option ipopt.min_refinement_steps=0
[--patterns 1 2] [--criteria ss random] [--seeds 10]``: every (seed, pattern, criterion) run
of ``generate`` (Steps 2-7) goes once with rigidfold's options and once with the extra ones,
one after the other; it prints N_lock, solves, mean IPOPT iterations and seconds per solve of
each, then totals and the ratio of seconds per solve. Lock counts follow the optimiser's path,
so an option that changes the path changes them; judge them on many seeds.

``--timing`` instead prints IPOPT's own timing statistics for one Step 6 solve (pattern 2,
seed 7, the first solution with 8 more creases fixed), with the extra options if given.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics

import numpy as np

from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import ipopt

_defaults = ipopt.ipopt_options


@contextlib.contextmanager
def extra_options(options: dict):
    """Add ``options`` to the IPOPT options of every problem built inside the block."""
    ipopt.ipopt_options = lambda settings, tol=None: _defaults(settings, tol) | options
    try:
        yield
    finally:
        ipopt.ipopt_options = _defaults


def _value(text: str):
    for kind in (int, float):
        with contextlib.suppress(ValueError):
            return kind(text)
    return text


def _run(pattern: str, criterion: str, seed: int) -> dict:
    run = generate(case_from_specs("bezier", pattern, seed=seed), criterion=criterion, seed=seed)
    return {
        "lock": run.n_lock,
        "solves": len(run.attempts),
        "iterations": statistics.mean(a.iterations for a in run.attempts),
        "solve_s": sum(a.solve_time for a in run.attempts),
    }


def timing(options: dict) -> None:
    with extra_options(options | {"ipopt.print_timing_statistics": "yes", "ipopt.print_level": 3}):
        problem = case_from_specs("bezier", "2", seed=7).problem()
        first = problem.solve()
        fixed = first.pattern.fixed.copy()
        free = np.flatnonzero(~fixed & ~first.pattern.is_boundary_edge)
        fixed[free[:8]] = True
        print("=== Step 6 solve: 8 more creases fixed", flush=True)
        result = problem.solve(fixed=fixed, start=first.coords)
    print(f"{result.iterations} iterations, {result.wall_time:.3f} s, {result.status.value}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--patterns", nargs="+", default=["1", "2"])
    parser.add_argument("--criteria", nargs="+", default=["shat", "s", "ss", "random"])
    parser.add_argument("--seeds", type=int, default=10, help="Bezier seeds 0..N-1")
    parser.add_argument("--timing", action="store_true")
    args = parser.parse_args()
    options = {}
    for item in args.option:
        key, sep, value = item.partition("=")
        if not sep or not key:
            parser.error(f"--option must be KEY=VALUE, got {item!r}")
        options[key] = _value(value)
    if args.timing:
        timing(options)
        return
    if not options:
        parser.error("give at least one --option KEY=VALUE to compare with the defaults")
    totals = {"default": np.zeros(3), "extra": np.zeros(3)}  # locks, solves, seconds
    for seed in range(args.seeds):
        for pattern in args.patterns:
            for criterion in args.criteria:
                try:
                    base = _run(pattern, criterion, seed)
                    with extra_options(options):
                        new = _run(pattern, criterion, seed)
                except (ValueError, RuntimeError) as exc:
                    parser.error(str(exc))
                for name, r in (("default", base), ("extra", new)):
                    totals[name] += (r["lock"], r["solves"], r["solve_s"])
                print(
                    f"seed {seed} pattern {pattern} {criterion:<6} N_lock {base['lock']:4d} / "
                    f"{new['lock']:4d}  solves {base['solves']:4d} / {new['solves']:4d}  "
                    f"iterations {base['iterations']:5.1f} / {new['iterations']:5.1f}  "
                    f"s per solve {base['solve_s'] / base['solves']:.3f} / "
                    f"{new['solve_s'] / new['solves']:.3f}  (default / extra)",
                    flush=True,
                )
    per_solve = {k: v[2] / v[1] for k, v in totals.items()}
    print(
        f"total N_lock {totals['default'][0]:.0f} / {totals['extra'][0]:.0f}, s per solve "
        f"{per_solve['default']:.3f} / {per_solve['extra']:.3f}: default / extra = "
        f"{per_solve['default'] / per_solve['extra']:.2f}x"
    )


if __name__ == "__main__":
    main()
