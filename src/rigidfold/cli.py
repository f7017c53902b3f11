"""Command-line interface: parses arguments and calls library functions.

Every user error (bad option value, refused expression, unwritable directory, malformed
file) is reported as one line on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from rigidfold.config import DEFAULTS

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) and exit code 2."""

    def error(self, message: str):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _positive(text: str) -> float:
    value = float(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="rigidfold",
        description="Form generation of developable, rigid-foldable origami.",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    opt = sub.add_parser(
        "optimize",
        help="solve problem (6): a developable polyhedron near a target surface",
        description="Solve problem (6) once and write DIR/solution.fold and DIR/summary.json. "
        "Exit code 0 when the solution is accepted (F <= F_tol, constraints met), 1 when not "
        "(the files are written all the same), 2 on bad input.",
    )
    opt.add_argument("--surface", required=True, choices=["bezier", "dome", "hp", "expr"])
    opt.add_argument("--seed", type=int, default=0, help="seed of the random Bezier surface")
    opt.add_argument("--expr", help="z = f(x, y) for --surface expr, e.g. '0.2*sin(x)*y'")
    opt.add_argument("--pattern", required=True, choices=["1", "2", "11"])
    opt.add_argument(
        "--symmetric", action="store_true", help="impose the surface's mirror planes (9)"
    )
    opt.add_argument("--fixed", help="comma-separated indices of fixed crease lines")
    opt.add_argument("--solver", default="ipopt", choices=["ipopt", "slsqp", "slsqp-fd"])
    opt.add_argument("--dz", type=float, default=DEFAULTS.dz, help="bound on |dz| in metres")
    opt.add_argument("--theta-min", type=float, default=30.0, help="degrees")
    opt.add_argument("--theta-max", type=float, default=120.0, help="degrees")
    opt.add_argument("--rho-max", type=_positive, help="bound (12) on |fold angle|, degrees")
    opt.add_argument("--out", required=True, metavar="DIR")
    opt.set_defaults(func=_cmd_optimize)
    return parser


def _cmd_optimize(args: argparse.Namespace) -> int:
    from rigidfold.case import make_case, parse_fixed, prepare_output_dir, shape_report, write_json
    from rigidfold.config import Settings
    from rigidfold.io import write_fold

    if args.surface == "expr" and not args.expr:
        raise ValueError("--surface expr needs --expr TEXT, e.g. --expr '0.3*sin(x)*cos(y)'")
    if args.expr and args.surface != "expr":
        raise ValueError(f"--expr is only used with --surface expr, not {args.surface}")
    settings = Settings.from_degrees(
        dz=args.dz,
        theta_min_deg=args.theta_min,
        theta_max_deg=args.theta_max,
        rho_bar_deg=args.rho_max,
    )
    out = prepare_output_dir(args.out)
    case = make_case(
        args.surface,
        args.pattern,
        seed=args.seed,
        expr=args.expr,
        symmetric=args.symmetric,
        settings=settings,
    )
    fixed = parse_fixed(args.fixed, case.pattern)
    problem = case.problem(build_ipopt=args.solver == "ipopt")
    result = problem.solve(fixed=fixed, solver=args.solver)
    report = shape_report(case, result, problem.build_time)
    write_fold(
        out / "solution.fold",
        result.pattern,
        title=f"rigidfold optimize: {case.surface.name} on pattern {case.pattern_name}",
        metadata={**case.metadata(), **result.summary()},
    )
    write_json(out / "summary.json", report)
    print(
        f"{result.status.value}: F = {result.F:.3e} (F1 = {result.F1:.2e}, F2 = {result.F2:.2e}), "
        f"{result.iterations} iterations, {result.wall_time:.2f} s solve + "
        f"{problem.build_time:.2f} s build, {result.n_variables} variables"
    )
    print(f"wrote {out / 'solution.fold'} and {out / 'summary.json'}")
    return 0 if result.converged else 1


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        print(f"rigidfold: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("rigidfold: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
