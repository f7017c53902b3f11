"""Command-line interface: parses arguments, calls library functions and prints.

A user error (a :class:`rigidfold.RigidfoldError`: a bad option value, a refused expression,
an unwritable directory, a malformed file) is reported as one line on stderr with exit code 2,
never a traceback; any other exception is a bug of rigidfold: one line saying so and where
its traceback was written, exit code 1. The options of each command come from the records it
fills (:mod:`rigidfold.cli.parser`), its words from :mod:`rigidfold.cli.text`.
"""

from __future__ import annotations

import argparse
import atexit
import io
import json
import math
import os
import sys
import tempfile
import traceback
from collections.abc import Sequence

from rigidfold import __version__
from rigidfold.cli.arguments import add_arguments
from rigidfold.cli.checks import fabricate_options, structure_options, structure_progress
from rigidfold.cli.parser import EXIT_USAGE, Parser, attached_values, one_line, options_of
from rigidfold.cli.text import COMMANDS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import GenerateOptions
from rigidfold.generate.case_options import CaseOptions, SettingsOptions
from rigidfold.io import jsonable
from rigidfold.runtime.interrupts import (
    EXIT_INTERRUPTED,
    decide_exit,
    decided_exit,
    forget_exit,
    held_interrupts,
    interrupt_handled,
)
from rigidfold.runtime.quiet import VERBOSE_ENV, native_output_shown
from rigidfold.study import STUDY_OPTIONS

__all__ = ["build_parser", "main", "one_line"]

EXIT_FAILED = 1  # generate fell short; runs of a study failed; a bug
EXIT_PIPE = 141  # as a shell reports a process ended by SIGPIPE


def build_parser() -> Parser:
    """The parser of every command. Every option's help says what its value means and, where
    it has one, its default ("default: ..."), taken from the library."""
    parser = Parser(
        prog="rigidfold", description="Form generation of developable, rigid-foldable origami."
    )
    parser.add_argument("--version", action="version", version=f"rigidfold {__version__}")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="show what OpenSees, CasADi and IPOPT print (their warnings and logs, and "
        "OpenSees's message when the process ends); hidden by default",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name, func in _COMMANDS.items():
        p = parser.add_command(sub, name, **COMMANDS[name])
        p.set_defaults(func=func)
        add_arguments(name, p)
    return parser


def _case(args: argparse.Namespace):
    """The case of the parsed arguments; its warnings printed."""
    case = options_of(CaseOptions, args).make(options_of(SettingsOptions, args).settings())
    for warning in case.warnings:
        print(one_line(f"rigidfold: warning: {warning}"), file=sys.stderr)
    for note in case.notes:
        print(one_line(f"rigidfold: note: {note}"), file=sys.stderr)
    return case


def _cmd_optimize(args: argparse.Namespace) -> int:
    from rigidfold.cli.units import parse_fixed
    from rigidfold.pipeline.workflows import optimize_case

    case = _case(args)
    fixed = () if args.fixed is None else parse_fixed(args.fixed)
    out = optimize_case(case, args.out, fixed=fixed, solver=args.solver, overwrite=args.overwrite)
    result = out.result
    print(
        f"{result.status.value}: F = {result.F:.3e} (F1 = {result.F1:.2e}, F2 = {result.F2:.2e}), "
        f"{result.iterations} iterations, {result.wall_time:.2f} s solve + "
        f"{out.build_time:.2f} s build, {result.n_variables} variables"
    )
    print(f"wrote {' and '.join(str(p) for p in out.written)}")
    if not result.converged:
        from rigidfold.pipeline.verdict import SOLVE_HINT

        print(f"not accepted: {SOLVE_HINT}")
    return 0 if result.converged else 1


def _counters(summary: dict, stop_reason: str) -> str:
    """The line of a finished run's counters: the DOF reduced, N_*, the solves (and the
    attempts that repeated one, where there are any), and the final design's DOF where it
    is not the lowest reached."""
    rigid = f" N_rigid={summary['n_rigid']}" if summary["n_rigid"] else ""
    repeats = f" ({summary['n_repeats']} repeated)" if summary.get("n_repeats") else ""
    final = summary["final_dof"]
    return (
        f"{stop_reason}: DOF {summary['initial_dof']} -> {summary['lowest_dof']}, "
        f"N_reduce={summary['n_reduce']} N_lock={summary['n_lock']} "
        f"N_exceed={summary['n_exceed']} N_path={summary['n_path']}{rigid}, "
        f"{summary['n_solves']} solves{repeats}"
        + ("" if final == summary["lowest_dof"] else f"; final design DOF {final}")
    )


def _cmd_generate(args: argparse.Namespace) -> int:
    from rigidfold.cli.progress import GenerateProgress
    from rigidfold.drive import DriveOptions
    from rigidfold.pipeline import Interrupted, RunWriter, run
    from rigidfold.runtime.clock import command_started

    structure = structure_options(args)  # checked even without --structure
    options = options_of(
        GenerateOptions,
        args,
        seed=args.seed,
        material=args.material,
        fabricate=fabricate_options(args),
        structure=structure if args.structure else None,
        drive=DriveOptions() if args.deploy else None,
    )
    case = _case(args)
    progress = GenerateProgress(enabled=not args.quiet, target=args.target_dof)
    # the lock on DIR is released however the run ends
    with RunWriter(
        args.out, case, options, overwrite=args.overwrite, report=not args.no_report
    ) as writer:
        try:
            # --time-limit counts from the command's start, imports and the case too
            result = run(case, options, (writer, progress), started=command_started())
        except Interrupted as stop:
            return _interrupted(stop.result, writer, progress)
        except KeyboardInterrupt:  # before the run began, or as it returned
            interrupt_handled()
            result = writer.interrupted()  # its end, or summary.json saying interrupted
            if result.interrupted:
                return _interrupted(result, writer, progress)
    with held_interrupts(reraise=False):  # the run's files are written: it has ended
        progress.close()
        return decide_exit(_print_generated(args, writer.out, result))


def _interrupted(result, writer, progress) -> int:
    """Say where an interrupted ``generate`` left its files; exit code 130."""
    writer.release()
    progress.close()
    best = None if result.verdict is None else result.verdict.final_design
    n = len(result.records)
    print(
        one_line(
            f"rigidfold: interrupted; {_count(n, 'solution')}, log.jsonl "
            f"and summary.json are in {writer.out}"
            + (
                f"; best design known to deploy: {writer.out / best}"
                if best is not None
                else "; no design is known to deploy"
                if n
                else ""
            )
        ),
        file=sys.stderr,
    )
    return EXIT_INTERRUPTED


def _print_generated(args: argparse.Namespace, out, result) -> int:
    """Print what a finished ``generate`` run (``result``, a
    :class:`rigidfold.pipeline.RunResult`) wrote into ``out`` and its verdict; its exit
    code."""
    from rigidfold.pipeline import RunOutcome
    from rigidfold.pipeline.built import DRIVE_DIR, STRUCTURE_DIR, THICK_DIR
    from rigidfold.rundir.layout import FINAL_DIR, REPORT_FILE

    run = result.generation
    print(_counters(run.to_dict(), run.stop_reason))
    print(f"wrote {_count(len(result.records), 'solution')}, log.jsonl and summary.json to {out}")
    if result.exports:
        names = ", ".join(p.name for p in result.exports)
        print(f"exported the final design to {out / FINAL_DIR}: {names}")
    if result.final_verdicts is not None:
        print(f"final design: {result.final_verdicts}")
    if result.fabrication is not None:
        print(one_line(f"thick panels ({out / THICK_DIR}): {result.fabrication.last_line()}"))
    if result.structure is not None:
        print(
            one_line(
                f"structure ({out / STRUCTURE_DIR}): "
                f"{result.structure.status}: {result.structure.message}"
            )
        )
    if result.drive is not None:
        print(one_line(f"deployment ({out / DRIVE_DIR}): {result.drive.summary_line()}"))
    if not args.no_report and result.write_error is None:
        print(f"report: {out / REPORT_FILE}")
    verdict = result.verdict
    assert verdict is not None  # the run ended with its verdict
    final = "none" if verdict.final_design is None else out / verdict.final_design
    print(f"{verdict.outcome.value.replace('_', ' ')}: {verdict.message}; final design: {final}")
    return 0 if verdict.outcome is RunOutcome.PASSED else EXIT_FAILED


def _cmd_report(args: argparse.Namespace) -> int:
    from rigidfold.pipeline.workflows import report_run
    from rigidfold.rundir.layout import FIGURES_DIR

    report = report_run(args.dir)
    if args.json:
        print(json.dumps(jsonable(report.to_dict())))
    else:
        info = report.to_dict()
        print(
            f"wrote {info['report']} ({info['size_bytes'] / 1e6:.1f} MB) and "
            f"{len(report.figures)} figures in {report.html.parent / FIGURES_DIR}"
        )
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    from rigidfold.pipeline.workflows import analyze_file

    analysis = analyze_file(args.file, up=args.up)
    report = analysis.to_dict()
    if args.json:
        print(json.dumps(report))
        return 0
    mech = analysis.mechanism
    print(
        f"{args.file}: V={report['vertices']} F={report['faces']} "
        f"free creases={report['free_creases']} fixed={report['fixed_creases']}"
    )
    print(f"DOF: {mech.dof}")
    for note in analysis.notes:
        print(f"note: {note}")
    if len(mech.locked_creases):
        print(
            f"locked crease lines ({len(mech.locked_creases)}): edges {report['locked_edges']} "
            f"(vertex pairs {report['locked_vertex_pairs']})"
        )
    else:
        print("locked crease lines: none")
    angles = analysis.fold_angles_deg(mech.hinges)
    print(
        "fold angles of free creases (deg, valley > 0): "
        + ", ".join(f"{int(e)}:{a:+.3f}" for e, a in zip(mech.hinges, angles, strict=True))
    )
    return 0


def _cmd_develop(args: argparse.Namespace) -> int:
    from rigidfold.pipeline.workflows import develop_file

    checked = develop_file(args.file, args.out, up=args.up)
    d = checked.verification.development
    if args.json:
        print(json.dumps(jsonable(checked.to_dict())))
    else:
        print(
            f"{d.status}: D = {d.D:.3e}, max |dl|/l = {d.max_length_error:.2e}, "
            f"{d.flipped} flipped, {d.overlaps} overlapping pairs, {d.wall_time:.2f} s"
        )
        print(f"wrote {' and '.join(str(p) for p in checked.written)}")
    return 0 if d.status == "converged" else 1


def _cmd_deform(args: argparse.Namespace) -> int:
    from rigidfold.config import DEFAULTS
    from rigidfold.material import Panel, material_named
    from rigidfold.pipeline.workflows import deform_file

    panel = None  # either given, the other is the default of Settings.structure
    if args.material is not None or args.thickness is not None:
        structure = DEFAULTS.structure
        panel = Panel(
            material_named(structure.material) if args.material is None else args.material,
            structure.thickness if args.thickness is None else args.thickness,
        )
    checked = deform_file(args.file, args.out, up=args.up, panel=panel)
    d, m = checked.verification.deformation, checked.verification.motion
    assert d is not None  # deform_file runs the analysis
    if args.json:
        print(json.dumps(jsonable(checked.to_dict())))
        return 0 if d.reached_plane else 1
    print(
        f"{d.status}: {d.steps} load steps, mean/max |dl| = {d.mean_dl_mm:.4g}/"
        f"{d.max_dl_mm:.4g} mm, mean/max |drho_fix| = {d.mean_drho_fix_deg:.4g}/"
        f"{d.max_drho_fix_deg:.4g} deg, {d.wall_time:.2f} s"
        + (f" ({d.message})" if d.message else "")
        + (
            f"; frame of {checked.section['material']['name']} strips "
            f"{checked.section['thickness_m'] * 1e3:g} mm thick"
            if checked.section is not None and checked.section["kind"] == "panel"
            else ""
        )
    )
    if m is not None:
        print(
            f"folding motion: {m.status}, {len(m.frames)} frames, max |dl|/l = "
            f"{m.max_length_error:.2e}" + (f" ({m.message})" if m.message else "")
        )
    verdicts = checked.verification.verdicts
    if verdicts is not None:
        print(verdicts.line)
    print(f"wrote {', '.join(str(p) for p in checked.written)}")
    return 0 if d.reached_plane else 1


def _cmd_export(args: argparse.Namespace) -> int:
    from rigidfold.cli.units import parse_formats
    from rigidfold.pipeline.workflows import export_file

    formats = parse_formats(args.to)
    done = export_file(args.file, args.out, formats=formats, convention=args.convention, up=args.up)
    if args.json:
        print(json.dumps(jsonable(done.to_dict())))
    else:
        dev = done.design.development
        verdict = "" if dev is None else f" ({dev.status}: D = {dev.D:.3e})"
        panels = done.design.pattern.n_facets
        print(f"{args.file}: {panels} panels; development diagram: {done.design.diagram}{verdict}")
        print(f"wrote {', '.join(str(p) for p in done.written)}")
    return 0 if done.diagram_ok else 1


def _cmd_structure(args: argparse.Namespace) -> int:
    from rigidfold.pipeline.workflows import structure
    from rigidfold.structure import StructureStatus

    run = structure(
        args.file,
        args.out,
        structure_options(args),
        up=args.up,
        overwrite=args.overwrite,
        progress=structure_progress,
    )
    code = 0 if run.status is StructureStatus.PASSED else EXIT_FAILED
    if args.json:
        print(json.dumps(jsonable(run.to_dict())))
        return code
    c = run.check
    sup = c.rigidity.supports
    how = {"given": "given", "auto": "chosen", "service": "chosen for the deflection"}[c.chosen]
    grown = (
        ""
        if c.growth is None
        else f" (rigid with {c.growth.rigid.tolist()}, {len(c.growth.added)} added for the "
        f"deflection; {len(c.growth.trail)} analyses)"
    )
    print(
        f"supports ({how}): pinned {sup.pinned.tolist()}{grown}"
        + (f", clamped {sup.clamped.tolist()}" if len(sup.clamped) else "")
        + f"; mechanism DOF {c.rigidity.dof} without them; smallest stiffness eigenvalue "
        f"{c.rigidity.smallest:.3g}"
        + ("" if c.rigidity.rigid else f"; {c.rigidity.stability.message}")
    )
    if c.response is not None:
        load = c.total_load
        print(
            f"{c.material.describe()}, {c.thickness * 1e3:g} mm: total load "
            f"{math.sqrt(sum(float(f) ** 2 for f in load)) / 1e3:.4g} kN, reactions balance to "
            f"{c.balance_error:.1e}; largest displacement {c.max_displacement * 1e3:.4g} mm; "
            f"largest von Mises stress {c.response.von_mises.max(initial=0.0) / 1e6:.3g} MPa"
            + (
                "; frequencies " + ", ".join(f"{f:.3g}" for f in c.response.frequencies) + " Hz"
                if len(c.response.frequencies)
                else ""
            )
        )
    print(f"{c.status}: {c.message}")
    print(f"wrote {', '.join(str(p) for p in run.written)}")
    return code


def _cmd_fabricate(args: argparse.Namespace) -> int:
    from rigidfold.pipeline.workflows import fabricate_file

    options = fabricate_options(args)
    assert options is not None  # --thickness is required
    done = fabricate_file(args.file, args.out, options, up=args.up, overwrite=args.overwrite)
    fab = done.fabrication
    if args.json:
        print(json.dumps(jsonable(done.to_dict())))
    else:
        s = fab.solids
        print(
            f"{args.file}: {fab.panels.n} panels, {fab.panels.n_hinges} hinges; "
            f"{s.total_volume:.4g} m^3 of panels ({100 * s.trimming_loss:.1f}% trimmed off "
            f"the {fab.thickness * 1e3:g} mm slab), {fab.masses.sum():.1f} kg"
        )
        print(f"wrote {len(done.written)} files to {args.out}")
        print(one_line(fab.last_line()))
    return 0 if done.ok else 1


def _cmd_deploy(args: argparse.Namespace) -> int:
    from rigidfold.drive import DriveOptions
    from rigidfold.pipeline.workflows import deploy_file

    options = options_of(DriveOptions, args)
    done = deploy_file(args.file, args.out, options, up=args.up, overwrite=args.overwrite)
    if args.json:
        print(json.dumps(jsonable(done.to_dict())))
    else:
        print(f"{done.status}: {done.message}")
        print(f"wrote {', '.join(done.written)}")
        print(one_line(done.summary_line()))
    return 0 if done.ok else 1


def _cmd_study(args: argparse.Namespace) -> int:
    from rigidfold.cli.progress import StudyProgress
    from rigidfold.study import (
        StudyConfig,
        StudyInterrupted,
        failure_summary,
        plan,
        preset,
        run_study_command,
    )

    settings = options_of(SettingsOptions, args).settings()
    lists = (args.patterns, args.criteria)
    if args.preset is not None:
        keys = preset(args.preset)
    else:
        patterns, criteria = ([t.strip() for t in s.split(",") if t.strip()] for s in lists)
        keys = plan(patterns, criteria, args.surfaces, args.first_seed, settings=settings)
    fields = {name: getattr(args, name) for name in ("deform", "lookahead", "deploy_check")}
    config = StudyConfig(STUDY_OPTIONS.replace(**fields), settings)
    bar = StudyProgress(enabled=not args.quiet)
    try:
        result = run_study_command(
            keys,
            args.db,
            config,
            workers=args.workers,
            scheduler=args.scheduler,
            connect_timeout=args.connect_timeout,
            argv=["rigidfold", *sys.argv[1:]],
            on_done=bar.update,
            allow_mixed_numerics=args.allow_mixed_numerics,
        )
    except StudyInterrupted as stop:
        bar.close()
        print(
            one_line(
                f"rigidfold: interrupted; {stop.finished} finished runs are in {args.db}; run "
                "the same command to resume"
            ),
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    finally:
        bar.close()
    print(
        f"{result['ran']} runs done, {result['skipped']} already in {args.db}, "
        f"{result['total']} in the study, {result['wall_s']:.1f} s"
    )
    if result["failed"]:
        print(
            one_line(f"rigidfold: {failure_summary(result['failed'], result['ran'], args.db)}"),
            file=sys.stderr,
        )
        return EXIT_FAILED
    return 0


def _cmd_study_report(args: argparse.Namespace) -> int:
    from rigidfold.study import Store
    from rigidfold.study.markdown import markdown, write_report

    stores = [Store(db, readonly=True) for db in args.db]
    if args.out:
        path = write_report(stores, args.out)
        print(path.read_text())
        print(f"wrote {path} and its figures")
    else:
        print(markdown(stores))
    return 0


def _count(n: int, noun: str) -> str:
    """ "1 solution", "3 solutions"."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


_COMMANDS = {
    "generate": _cmd_generate,
    "report": _cmd_report,
    "analyze": _cmd_analyze,
    "develop": _cmd_develop,
    "deform": _cmd_deform,
    "export": _cmd_export,
    "structure": _cmd_structure,
    "fabricate": _cmd_fabricate,
    "deploy": _cmd_deploy,
    "study": _cmd_study,
    "study-report": _cmd_study_report,
    "optimize": _cmd_optimize,
}


def main(argv: Sequence[str] | None = None) -> int:
    forget_exit()  # nothing decided yet (a command run again in-process)
    try:  # a signal while the command line is read ends as any other: exit 130
        parser = build_parser()
        argv = attached_values(sys.argv[1:] if argv is None else argv)
        parser.refuse_unknown_options(argv)
        args = parser.parse_args(argv)
    except KeyboardInterrupt:
        interrupt_handled()
        print("rigidfold: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not (args.verbose or native_output_shown()):
        _quiet_exit()
    shown = os.environ.get(VERBOSE_ENV)
    if (
        args.verbose
    ):  # rigidfold.runtime.quiet lets the solvers' output through, here and in workers
        os.environ[VERBOSE_ENV] = "1"
    if isinstance(sys.stdout, io.TextIOWrapper):
        # a file name whose bytes are not UTF-8 is printed as those bytes, as ls does, not
        # refused by the encoder after the files were written
        sys.stdout.reconfigure(errors="surrogateescape")
    try:
        code = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not while Python exits
        return code
    except RigidfoldError as exc:
        _error(str(exc))
        return EXIT_USAGE
    except KeyboardInterrupt:
        interrupt_handled()
        decided = decided_exit()
        if decided is not None:  # the signal came once the run had ended: it stops nothing
            return decided
        print("rigidfold: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # the reader went away (``rigidfold analyze X --json | head -1``): stop quietly
        _drop_stdout()
        return EXIT_PIPE
    except OSError as exc:
        reason = exc.strerror or str(exc)
        if exc.filename is not None:  # a file the library did not report itself
            _error(f"{exc.filename}: {reason}")
            return EXIT_USAGE
        # standard output cannot be written (``> /dev/full``, a full disk)
        _drop_stdout()
        _error(f"cannot write the output: {reason}")
        return EXIT_USAGE
    except Exception as exc:  # anything else is a bug: said, not hidden
        return _bug(exc)
    finally:
        if args.verbose:
            _restore_env(VERBOSE_ENV, shown)


def _bug(exc: Exception) -> int:
    """Report an exception that is not a user error: one line saying it is a bug of
    rigidfold and where its traceback was written (a temporary file; on stderr when that
    cannot be written); exit code 1."""
    text = traceback.format_exc()
    try:
        with tempfile.NamedTemporaryFile(
            "w", prefix="rigidfold-bug-", suffix=".txt", delete=False, encoding="utf-8"
        ) as f:
            f.write(text)
        where = f"the traceback is in {f.name}"
    except OSError:
        sys.stderr.write(text)
        where = "the traceback is above"
    _error(
        f"a bug in rigidfold, not in the input: {type(exc).__name__}: {exc}; {where}; please "
        "report it"
    )
    return EXIT_FAILED


def _error(message: str) -> None:
    """Print ``rigidfold: error: <message>`` on stderr, on one line (:func:`one_line`)."""
    print(f"rigidfold: error: {one_line(message)}", file=sys.stderr)


def _restore_env(name: str, value: str | None) -> None:
    """Set the environment variable ``name`` back to ``value`` (None: unset)."""
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value


def _drop_stdout() -> None:
    """Send what is still buffered for standard output, and what follows, to the null device
    (so that Python's final flush does not fail again)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


_QUIET_EXIT: list[bool] = []


def _quiet_exit() -> None:
    """Silence standard error once Python has finished, so that what OpenSees prints while the
    process ends ("Process 0 Terminating") does not reach the terminal (``--verbose`` keeps
    it). Registered first, the hook runs after every other exit handler."""
    if _QUIET_EXIT:
        return
    _QUIET_EXIT.append(True)

    def silence() -> None:
        sys.stderr.flush()
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stderr.fileno())

    atexit.register(silence)
