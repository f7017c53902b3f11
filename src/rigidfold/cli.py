"""Command-line interface: parses arguments and calls library functions.

Every user error (bad option value, refused expression, unwritable directory, malformed
file) is reported as one line on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
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

    gen = sub.add_parser(
        "generate",
        help="Steps 2-7: fix crease lines one by one down to the target DOF",
        description="Generate developable, rigid-foldable shapes of decreasing DOF. Writes "
        "DIR/solutions/step_XX_dof_YY.fold, DIR/log.json and DIR/summary.json as it goes.",
    )
    _case_options(gen)
    gen.add_argument("--criterion", default="shat", choices=["shat", "s", "ss", "random"])
    gen.add_argument("--target-dof", type=int, default=1)
    gen.add_argument(
        "--retry-zero-dof",
        action="store_true",
        help="treat a 0-DOF solution as a lock and try the next crease (the paper's Step 5 "
        "ends generation there)",
    )
    gen.add_argument(
        "--no-deform", action="store_true", help="skip the large-deformation check (Step 9)"
    )
    gen.add_argument("--quiet", action="store_true", help="no progress bar")
    gen.set_defaults(func=_cmd_generate)

    ana = sub.add_parser(
        "analyze",
        help="mechanism analysis of a FOLD shape: DOF, locked creases, fold angles",
        description="Read a FOLD file (3D vertices_coords; polygon faces are triangulated with "
        "fixed 'J' edges) and report its DOF and locked crease lines.",
    )
    ana.add_argument("file", metavar="FILE.fold")
    ana.add_argument("--json", action="store_true", help="print one JSON object")
    ana.set_defaults(func=_cmd_analyze)

    dev = sub.add_parser(
        "develop",
        help="Step 8: development diagram of a FOLD shape (problem 13)",
        description="Flatten a FOLD shape to its development diagram. Writes DIR/<name>.fold "
        "(the input plus a 'creasePattern' frame with 2D coordinates) and DIR/<name>.svg.",
    )
    dev.add_argument("file", metavar="FILE.fold")
    dev.add_argument("--out", required=True, metavar="DIR")
    dev.add_argument("--json", action="store_true", help="print one JSON object")
    dev.set_defaults(func=_cmd_develop)

    dfm = sub.add_parser(
        "deform",
        help="Step 9: large-deformation check of a FOLD shape (OpenSees) and its folding motion",
        description="Drive the frame model of a FOLD shape to the plane with OpenSees and trace "
        "its folding motion. Writes DIR/<name>.fold (the input plus the development diagram and "
        "the motion frames) and DIR/<name>_deform.json (figures and the load-step history). Exit "
        "code 0 when the plane is reached, 1 when not, 2 on bad input.",
    )
    dfm.add_argument("file", metavar="FILE.fold")
    dfm.add_argument("--out", required=True, metavar="DIR")
    dfm.add_argument("--json", action="store_true", help="print one JSON object")
    dfm.set_defaults(func=_cmd_deform)

    stu = sub.add_parser(
        "study",
        help="many generate runs on Dask, results in SQLite (Tables 5-8), resumable",
        description="Run generate for every (Bezier seed, pattern, criterion), or a preset, on "
        "Dask workers; store each finished run in DB. Re-running the same command skips "
        "finished runs, so a killed study resumes where it stopped.",
    )
    stu.add_argument("--patterns", default="1,2", help="comma-separated (default 1,2)")
    stu.add_argument("--criteria", default="shat,s,ss,random", help="comma-separated")
    stu.add_argument("--surfaces", type=int, default=100, help="number of Bezier seeds")
    stu.add_argument("--first-seed", type=int, default=0)
    stu.add_argument(
        "--preset", help="dome, hp or dome,hp: Sections 6.5-6.6 instead of Bezier surfaces"
    )
    stu.add_argument("--db", required=True, metavar="DB", help="SQLite file (created if absent)")
    where = stu.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=2, help="local worker processes")
    where.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler")
    stu.add_argument("--no-deform", action="store_true", help="skip Steps 8-9 of each solution")
    stu.add_argument(
        "--hessian",
        default=DEFAULTS.ipopt_hessian,
        choices=["closed-form", "casadi"],
        help="IPOPT's Hessian of the Lagrangian: closed-form (default) or casadi (the symbolic "
        "reference, used by studies made before the closed form)",
    )
    stu.add_argument("--quiet", action="store_true", help="no progress bar")
    stu.set_defaults(func=_cmd_study)

    rep = sub.add_parser(
        "study-report",
        help="Tables 5-8 of a study database beside the paper's, with box plots",
    )
    rep.add_argument("db", metavar="DB", nargs="+", help="one or more study databases")
    rep.add_argument("--out", metavar="DIR", help="write DIR/results.md and PNG box plots")
    rep.set_defaults(func=_cmd_study_report)

    opt = sub.add_parser(
        "optimize",
        help="solve problem (6): a developable polyhedron near a target surface",
        description="Solve problem (6) once and write DIR/solution.fold and DIR/summary.json. "
        "Exit code 0 when the solution is accepted (F <= F_tol, constraints met), 1 when not "
        "(the files are written all the same), 2 on bad input.",
    )
    _case_options(opt)
    opt.add_argument("--fixed", help="comma-separated indices of fixed crease lines")
    opt.set_defaults(func=_cmd_optimize)
    return parser


def _case_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--surface", required=True, choices=["bezier", "dome", "hp", "expr"])
    p.add_argument("--seed", type=int, default=0, help="seed of the random Bezier surface")
    p.add_argument("--expr", help="z = f(x, y) for --surface expr, e.g. '0.2*sin(x)*y'")
    p.add_argument("--pattern", required=True, choices=["1", "1p", "2", "11"])
    p.add_argument("--symmetric", action="store_true", help="impose the surface's mirror planes")
    p.add_argument("--solver", default="ipopt", choices=["ipopt", "slsqp", "slsqp-fd"])
    p.add_argument(
        "--hessian",
        default=DEFAULTS.ipopt_hessian,
        choices=["closed-form", "casadi"],
        help="IPOPT's Hessian of the Lagrangian (both exact; they differ by round-off)",
    )
    p.add_argument("--dz", type=float, default=DEFAULTS.dz, help="bound on |dz| in metres")
    p.add_argument("--theta-min", type=float, default=30.0, help="degrees")
    p.add_argument("--theta-max", type=float, default=120.0, help="degrees")
    p.add_argument("--rho-max", type=_positive, help="bound (12) on |fold angle|, degrees")
    p.add_argument("--out", required=True, metavar="DIR")


def _case(args: argparse.Namespace):
    from rigidfold.case import make_case
    from rigidfold.config import Settings

    if args.surface == "expr" and not args.expr:
        raise ValueError("--surface expr needs --expr TEXT, e.g. --expr '0.3*sin(x)*cos(y)'")
    if args.expr and args.surface != "expr":
        raise ValueError(f"--expr is only used with --surface expr, not {args.surface}")
    settings = Settings.from_degrees(
        dz=args.dz,
        theta_min_deg=args.theta_min,
        theta_max_deg=args.theta_max,
        rho_bar_deg=args.rho_max,
        zero_dof_ends=not getattr(args, "retry_zero_dof", False),
        ipopt_hessian=args.hessian,
    )
    return make_case(
        args.surface,
        args.pattern,
        seed=args.seed,
        expr=args.expr,
        symmetric=args.symmetric,
        settings=settings,
    )


def _cmd_optimize(args: argparse.Namespace) -> int:
    from rigidfold.case import parse_fixed, shape_report
    from rigidfold.io import prepare_output_dir, write_fold, write_json

    out = prepare_output_dir(args.out)
    case = _case(args)
    fixed = parse_fixed(args.fixed, case.pattern)
    problem = case.problem(build_ipopt=args.solver == "ipopt")
    result = problem.solve(fixed=fixed, solver=args.solver)
    report = shape_report(case, result, problem.build_time)
    write_fold(
        out / "solution.fold",
        result.pattern,
        title=f"rigidfold optimize: {case.surface.name} on pattern {case.pattern_name}",
        metadata={**case.metadata(), **result.to_dict()},
    )
    write_json(out / "summary.json", report)
    print(
        f"{result.status.value}: F = {result.F:.3e} (F1 = {result.F1:.2e}, F2 = {result.F2:.2e}), "
        f"{result.iterations} iterations, {result.wall_time:.2f} s solve + "
        f"{problem.build_time:.2f} s build, {result.n_variables} variables"
    )
    print(f"wrote {out / 'solution.fold'} and {out / 'summary.json'}")
    return 0 if result.converged else 1


def _cmd_generate(args: argparse.Namespace) -> int:
    from rigidfold.generate import generate
    from rigidfold.report import RunWriter

    if args.target_dof < 0:
        raise ValueError(f"--target-dof must be >= 0, got {args.target_dof}")
    options = {
        "criterion": args.criterion,
        "target_dof": args.target_dof,
        "seed": args.seed,
        "solver": args.solver,
        "symmetric": args.symmetric,
        "deform": not args.no_deform,
    }
    writer = RunWriter(args.out, _case(args), options, deform=not args.no_deform)
    progress = _Progress(enabled=not args.quiet, target=args.target_dof)

    def on_attempt(run, attempt):
        writer.on_attempt(run, attempt)
        progress.update(run, attempt)

    def on_solution(run, solution):
        writer.on_solution(run, solution)
        progress.update(run, None)

    try:
        run = generate(
            writer.case,
            criterion=args.criterion,
            target_dof=args.target_dof,
            seed=args.seed,
            solver=args.solver,
            on_attempt=on_attempt,
            on_solution=on_solution,
        )
    except KeyboardInterrupt:
        progress.close()
        print(
            f"rigidfold: interrupted; {len(writer.files)} solution(s), log.json and "
            f"summary.json are in {writer.out}",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    progress.close()
    writer.write_summary(run)
    summary = run.to_dict()
    print(
        f"{run.stop_reason}: DOF {summary['initial_dof']} -> {summary['final_dof']}, "
        f"N_reduce={summary['N_reduce']} N_lock={summary['N_lock']} "
        f"N_exceed={summary['N_exceed']}, {summary['n_solves']} solves"
    )
    print(f"wrote {len(writer.files)} solutions, log.json and summary.json to {writer.out}")
    return 0 if run.solutions else 1


def _cmd_analyze(args: argparse.Namespace) -> int:
    import json

    import numpy as np

    from rigidfold.io import read_fold
    from rigidfold.mechanism import analyze

    data = read_fold(args.file)
    mech = analyze(data.pattern)
    pattern = data.pattern
    locked = [int(e) for e in mech.locked_creases]
    report = {
        "file": str(args.file),
        "vertices": pattern.n_vertices,
        "faces": pattern.n_faces,
        "free_creases": len(mech.hinges),
        "fixed_creases": len(pattern.fixed_creases),
        "dof": mech.dof,
        "locked_edges": [e for e in locked if e < data.n_file_edges],
        "locked_vertex_pairs": [pattern.edges[e].tolist() for e in locked],
        "fold_angles_deg": np.round(
            np.degrees(pattern.fold_angles[: data.n_file_edges]), 6
        ).tolist(),
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(
        f"{args.file}: V={pattern.n_vertices} F={pattern.n_faces} "
        f"free creases={len(mech.hinges)} fixed={len(pattern.fixed_creases)}"
    )
    print(f"DOF: {mech.dof}")
    if locked:
        print(
            f"locked crease lines ({len(locked)}): edges {report['locked_edges']} "
            f"(vertex pairs {report['locked_vertex_pairs']})"
        )
    else:
        print("locked crease lines: none")
    angles = np.degrees(pattern.fold_angles[mech.hinges])
    print(
        "fold angles of free creases (deg, valley > 0): "
        + ", ".join(f"{int(e)}:{a:+.3f}" for e, a in zip(mech.hinges, angles, strict=True))
    )
    return 0


def _cmd_develop(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from rigidfold.develop import develop
    from rigidfold.io import (
        crease_pattern_frame,
        prepare_output_dir,
        read_fold,
        write_fold,
        write_svg,
    )

    out = prepare_output_dir(args.out)
    data = read_fold(args.file)
    result = develop(data.pattern)
    stem = Path(args.file).stem
    figures = result.to_dict()
    write_fold(
        out / f"{stem}.fold",
        data.pattern,
        title=f"{stem} (folded form)",
        metadata={**data.metadata, "development": figures},
        frames=[crease_pattern_frame(result.coords2d)],
    )
    write_svg(out / f"{stem}.svg", data.pattern, result.coords2d, title=f"{stem}: development")
    if args.json:
        print(json.dumps({k: v for k, v in figures.items()}))
    else:
        print(
            f"{result.status}: D = {result.D:.3e}, max |dl|/l = {result.max_length_error:.2e}, "
            f"{result.flipped} flipped, {result.overlaps} overlapping pairs, "
            f"{result.wall_time:.2f} s"
        )
        print(f"wrote {out / (stem + '.fold')} and {out / (stem + '.svg')}")
    return 0 if result.status == "converged" else 1


def _cmd_deform(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from rigidfold.deform import verify
    from rigidfold.io import prepare_output_dir, read_fold, write_fold, write_json

    out = prepare_output_dir(args.out)
    data = read_fold(args.file)
    check = verify(data.pattern)
    stem = Path(args.file).stem
    figures = check.to_dict()
    write_fold(
        out / f"{stem}.fold",
        data.pattern,
        title=f"{stem} (folded form)",
        metadata={**data.metadata, **{k: v for k, v in figures.items() if k != "deformation"}},
        frames=check.fold_frames(),
    )
    write_json(out / f"{stem}_deform.json", figures)
    d = check.deformation
    keys = ("mean_dl_mm", "max_dl_mm", "mean_drho_fix_deg", "max_drho_fix_deg", "reached_plane")
    if args.json:
        report = {k: figures["deformation"][k] for k in keys}
        report["steps"] = d.steps
        report["status"] = d.status
        report["motion"] = figures["motion"]
        print(json.dumps(report))
    else:
        print(
            f"{d.status}: {d.steps} load steps, mean/max |dl| = {d.mean_dl_mm:.4g}/"
            f"{d.max_dl_mm:.4g} mm, mean/max |drho_fix| = {d.mean_drho_fix_deg:.4g}/"
            f"{d.max_drho_fix_deg:.4g} deg, {d.wall_time:.2f} s"
            + (f" ({d.message})" if d.message else "")
        )
        m = check.motion
        if m is not None:
            print(
                f"folding motion: {m.status}, {len(m.frames)} frames, max |dl|/l = "
                f"{m.max_length_error:.2e}" + (f" ({m.message})" if m.message else "")
            )
        print(f"wrote {out / (stem + '.fold')} and {out / (stem + '_deform.json')}")
    return 0 if d.reached_plane else 1


def _cmd_study(args: argparse.Namespace) -> int:
    from rigidfold.study import Store, StudyConfig, plan, preset, run_study

    if args.preset is not None:
        keys = preset(args.preset)
    else:
        keys = plan(
            [p.strip() for p in args.patterns.split(",") if p.strip()],
            [c.strip() for c in args.criteria.split(",") if c.strip()],
            args.surfaces,
            args.first_seed,
        )
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    config = StudyConfig(
        deform=not args.no_deform, settings=DEFAULTS.with_(ipopt_hessian=args.hessian)
    )
    store = Store(args.db, config.as_dict())  # refuses another configuration untouched
    bar = _StudyProgress(enabled=not args.quiet)
    started, t0 = _utc_now(), time.perf_counter()

    def n_done() -> int:
        return len(store.done().intersection(keys))

    before = n_done()

    def log(outcome: str, ran: int) -> None:
        from rigidfold import __version__

        store.add_invocation(
            started=started,
            argv=["rigidfold", *sys.argv[1:]],
            workers=None if args.scheduler else args.workers,
            scheduler=args.scheduler,
            ran=ran,
            skipped=before,
            total=len(keys),
            wall_s=time.perf_counter() - t0,
            outcome=outcome,
            version=__version__,
        )

    try:
        result = run_study(
            keys,
            store,
            config,
            workers=args.workers,
            scheduler=args.scheduler,
            on_done=bar.update,
        )
    except KeyboardInterrupt:
        bar.close()
        log("interrupted", n_done() - before)
        print(
            f"rigidfold: interrupted; {len(store.done())} finished runs are in {args.db}; run the "
            "same command to resume",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    finally:
        bar.close()
    log("completed", result["ran"])
    print(
        f"{result['ran']} runs done, {result['skipped']} already in {args.db}, "
        f"{result['total']} in the study, {result['wall_s']:.1f} s"
    )
    store.close()
    return 0


def _cmd_study_report(args: argparse.Namespace) -> int:
    from rigidfold.study import Store
    from rigidfold.study.report import markdown, write_report

    stores = [Store(db, readonly=True) for db in args.db]
    if args.out:
        path = write_report(stores, args.out)
        print(path.read_text())
        print(f"wrote {path} and its figures")
    else:
        print(markdown(stores))
    return 0


def _utc_now() -> str:
    from datetime import UTC, datetime

    return datetime.now(UTC).isoformat(timespec="seconds")


class _StudyProgress:
    """One rich bar for a study: runs done / total, failures, rate, ETA (stderr).

    When stderr is not a terminal (a batch job, ``nohup``, a log file) a live bar would show
    nothing until the end, so a plain line with the same figures is printed instead, at most
    every ``log_every`` seconds and for the last run.
    """

    def __init__(self, *, enabled: bool, log_every: float = 60.0) -> None:
        self.enabled, self.bar, self.task, self.failures = enabled, None, None, 0
        self.plain = not sys.stderr.isatty()
        self.log_every, self.t0 = log_every, time.monotonic()
        self.last, self.first = -math.inf, None

    def _line(self, finished: int, total: int) -> None:
        now = time.monotonic()
        if self.first is None:  # runs already in the database before this command
            self.first = finished - 1
        if now - self.last < self.log_every and finished < total:
            return
        self.last = now
        done, elapsed = finished - self.first, now - self.t0
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = f"{(total - finished) / rate / 60:.0f} min" if rate > 0 else "?"
        print(
            f"study {finished}/{total}  failures {self.failures}  {rate * 60:.1f} runs/min  "
            f"elapsed {elapsed / 60:.1f} min  ETA {eta}",
            file=sys.stderr,
            flush=True,
        )

    def update(self, key, row, finished: int, total: int) -> None:
        if row.get("error"):
            self.failures += 1
        if not self.enabled:
            return
        if self.plain:
            self._line(finished, total)
            return
        if self.bar is None:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.bar = Progress(
                TextColumn("[bold]study"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("{task.description}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            self.bar.start()
            self.task = self.bar.add_task("", total=total, completed=finished - 1)
        rate = self.bar.tasks[0].speed
        self.bar.update(
            self.task,
            completed=finished,
            description=f"failures {self.failures}"
            + (f"  {rate * 60:.1f} runs/min" if rate else ""),
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


class _Progress:
    """A rich progress bar on stderr over the DOF to remove; silent when disabled."""

    def __init__(self, *, enabled: bool, target: int) -> None:
        self.enabled, self.target, self.bar, self.task = enabled, target, None, None

    def update(self, run, attempt) -> None:
        if not self.enabled or run.initial_dof is None:
            return
        if self.bar is None:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

            self.bar = Progress(
                TextColumn("[bold]generate"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("{task.description}"),
                console=Console(stderr=True),
                transient=False,
            )
            self.bar.start()
            self.task = self.bar.add_task("", total=max(run.initial_dof - self.target, 0))
        self.bar.update(
            self.task,
            completed=run.n_reduce,
            description=f"DOF {run.final_dof}  lock {run.n_lock}  exceed {run.n_exceed}",
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


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
