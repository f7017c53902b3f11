"""The command line: outputs, exit codes, one-line errors without tracebacks."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import run_cli
from rigidfold.cli.commands import main
from rigidfold.io import read_fold, write_fold


def test_optimize_writes_fold_and_summary(tmp_path, capsys):
    code = main(
        ["optimize", "--surface", "bezier", "--seed", "2", "--pattern", "1", "--out", str(tmp_path)]
    )
    assert code == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "converged"
    assert summary["F"] <= 1e-7
    assert (summary["V"], summary["E"], summary["F_faces"]) == (49, 120, 72)
    assert summary["n_variables"] == 115
    assert summary["max_abs_dz_m"] <= 0.3
    assert summary["min_sector_angle_deg"] >= 30 - 1e-6
    assert summary["max_sector_angle_deg"] <= 120 + 1e-6
    data = read_fold(tmp_path / "solution.fold")
    assert data.pattern.n_vertices == 49
    assert data.metadata["status"] == "converged"
    assert data.metadata["surface"]["seed"] == 2
    assert data.frame_classes == ["foldedForm"]
    assert "converged" in capsys.readouterr().out


def test_optimize_fixed_creases_are_joins(tmp_path):
    code = main(
        [
            "optimize",
            "--surface",
            "bezier",
            "--seed",
            "2",
            "--pattern",
            "1",
            "--fixed",
            "7,8",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    raw = json.loads((tmp_path / "solution.fold").read_text())
    assert raw["edges_assignment"][7] == "J" and raw["edges_assignment"][8] == "J"
    assert json.loads((tmp_path / "summary.json").read_text())["fixed_creases"] == [7, 8]


def test_optimize_symmetric_expression(tmp_path):
    code = main(
        ["optimize", "--surface", "hp", "--pattern", "11", "--symmetric", "--out", str(tmp_path)]
    )
    assert code == 0
    assert json.loads((tmp_path / "summary.json").read_text())["n_variables"] == 83


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--surface", "cone", "--pattern", "1"], "unknown surface 'cone' (choose from bezier"),
        (["--surface", "bezier", "--pattern", "9"], "unknown pattern '9'"),
        (["--surface", "bezier", "--pattern", "1", "--dz", "0"], "dz must be a positive"),
        (["--surface", "bezier", "--pattern", "1", "--dz", "-1"], "dz must be a positive"),
        (
            ["--surface", "bezier", "--pattern", "1", "--theta-min", "120", "--theta-max", "30"],
            "theta_min < theta_max",
        ),
        (["--surface", "expr", "--expr", "__import__('os')", "--pattern", "1"], "refused"),
        (["--surface", "expr", "--expr", "x +", "--pattern", "1"], "invalid expression"),
        (["--surface", "expr", "--expr", "log(x)", "--pattern", "1"], "not finite"),
        (["--surface", "expr", "--pattern", "1"], "needs --expr"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "999"], "out of range"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "0"], "boundary edge"),
        (["--surface", "bezier", "--pattern", "1", "--fixed", "a"], "comma-separated"),
        (["--surface", "bezier", "--pattern", "1", "--symmetric"], "no mirror planes"),
        (["--surface", "bezier", "--pattern", "1", "--seed", "x"], "invalid int value"),
    ],
)
def test_bad_input_one_line_exit_2(tmp_path, args, message):
    proc = run_cli("optimize", *args, "--out", str(tmp_path / "o"))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert message in lines[0]
    assert "Traceback" not in proc.stderr


def test_output_path_that_is_a_file(tmp_path):
    target = tmp_path / "file"
    target.write_text("")
    proc = run_cli("optimize", "--surface", "dome", "--pattern", "11", "--out", str(target))
    assert proc.returncode == 2
    assert "cannot write to output directory" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


OPTIMIZE_RUN = ["optimize", "--surface", "dome", "--pattern", "grid:3x3"]


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_optimize_refuses_to_replace_its_input(tmp_path, capsys):
    """A pattern or a surface read from a file that optimize would write, directly or through
    a symbolic link, is refused before anything is written (issue 30)."""
    assert main([*OPTIMIZE_RUN, "--out", str(tmp_path / "a")]) == 0
    solution = tmp_path / "a" / "solution.fold"
    cases = []
    for name, option in (("solution.fold", "--pattern"), ("summary.json", "--surface")):
        folder = tmp_path / f"in_{name}"
        folder.mkdir()
        given = folder / name
        given.write_bytes(solution.read_bytes())
        spec = str(given) if option == "--pattern" else f"fold:{given}"
        cases.append((folder, given, {"--pattern": "grid:3x3", option: spec}, []))
    link_dir = tmp_path / "linked"
    link_dir.mkdir()
    (link_dir / "solution.fold").write_bytes(solution.read_bytes())
    link = tmp_path / "link.fold"
    link.symlink_to(link_dir / "solution.fold")
    cases.append((link_dir, link, {"--pattern": str(link)}, ["--overwrite"]))
    for folder, given, specs, extra in cases:
        before = {p.name: p.read_bytes() for p in folder.iterdir()}
        capsys.readouterr()
        options = {"--surface": "dome", **specs}
        argv = ["optimize", *[t for kv in options.items() for t in kv], "--out", str(folder)]
        assert main([*argv, *extra]) == 2
        error = _one_line_error(capsys)
        assert f"would replace the input file '{given}'" in error
        assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_optimize_refuses_an_earlier_run_unless_overwrite(tmp_path, capsys):
    """Like generate: the files of an earlier run in --out are refused, --overwrite replaces
    them and keeps the other files (issue 30, item 24)."""
    out = tmp_path / "run"
    assert main([*OPTIMIZE_RUN, "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    (out / "summary.json").write_text("{}")
    capsys.readouterr()
    assert main([*OPTIMIZE_RUN, "--out", str(out)]) == 2
    error = _one_line_error(capsys)
    assert "holds an earlier run (solution.fold, summary.json): give --overwrite" in error
    assert (out / "summary.json").read_text() == "{}"
    assert main([*OPTIMIZE_RUN, "--out", str(out), "--overwrite"]) == 0
    assert json.loads((out / "summary.json").read_text())["status"] == "converged"
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "solution.fold", "summary.json"]
    assert (out / "notes.txt").read_text() == "mine"


def test_help_lists_optimize():
    proc = run_cli("--help")
    assert proc.returncode == 0 and "optimize" in proc.stdout


def test_closed_pipe_is_no_traceback():
    """``rigidfold analyze X --json | head -c 0``: the reader is gone before anything is
    written."""
    fold = Path(__file__).parent / "data" / "fold_examples" / "squaretwist.fold"
    proc = subprocess.Popen(
        [sys.executable, "-m", "rigidfold.cli", "analyze", str(fold), "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()
    with proc.stderr:
        err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141
    assert "Traceback" not in err and "BrokenPipe" not in err and err == ""


def test_version_and_quiet_exit():
    from rigidfold import __version__

    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", "--version"], capture_output=True, text=True
    )
    assert proc.returncode == 0 and proc.stdout.strip() == f"rigidfold {__version__}"


@pytest.mark.parametrize("verbose", [False, True])
def test_what_opensees_prints_at_exit_is_hidden_unless_verbose(tmp_path, verbose):
    fold = Path(__file__).parent / "data" / "fold_examples" / "squaretwist.fold"
    flags = ["--verbose"] if verbose else []
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "rigidfold.cli",
            *flags,
            "deform",
            str(fold),
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert ("Process 0 Terminating" in proc.stderr) is verbose


def test_develop_of_a_sheet_folded_flat_prints_nothing_from_casadi(tmp_path):
    """simple.fold has creases folded 180 degrees: the start of problem (13) puts vertices on
    one point, where CasADi used to print NaN-gradient warnings."""
    fold = Path(__file__).parent / "data" / "fold_examples" / "simple.fold"
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", "develop", str(fold), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert proc.stdout.startswith("converged: D = ")


# ------------------------------------------------------------------------- --help texts
def subcommands():
    """(name, parser) of every subcommand."""
    import argparse

    from rigidfold.cli.commands import build_parser

    parser = build_parser()
    (sub,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [(parser.prog, parser), *sub.choices.items()]


def test_every_option_with_a_default_shows_it_in_its_help():
    """Every option whose default is a value (not None, not a flag's False) says
    "default: <value>" in its help, as --help prints it."""
    import argparse

    checked = 0
    for name, parser in subcommands():
        formatter = parser._get_formatter()
        for action in parser._actions:
            default = action.default
            if default is None or default is argparse.SUPPRESS or isinstance(default, bool):
                continue
            text = " ".join(formatter._expand_help(action).split())
            said = text.split("(default: ")[-1] if "(default: " in text else ""
            # a typed number may be shown in its own words: the limit 250.0 as "L/250"
            shown = isinstance(default, float) and f"{default:g}" in said
            assert f"default: {default}" in text or shown, (name, action.option_strings, text)
            checked += 1
    assert checked >= 20


def test_every_argument_says_what_it_means():
    import argparse

    for name, parser in subcommands():
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                continue
            assert action.help and len(action.help) > 10, (name, action.dest)


def test_defaults_come_from_the_library():
    from rigidfold.cli.commands import build_parser
    from rigidfold.config import DEFAULT_SEED, DEFAULTS
    from rigidfold.generate import GenerateOptions
    from rigidfold.study import STUDY_DEFAULTS

    parser = build_parser()
    gen = parser.parse_args(["generate", "--surface", "dome", "--pattern", "1", "--out", "x"])
    options = GenerateOptions()
    assert (gen.seed, gen.target_dof, gen.dz) == (
        DEFAULT_SEED,
        options.target_dof,
        DEFAULTS.design.dz,
    )
    assert (gen.criterion, gen.solver, gen.check) == (
        options.criterion,
        options.solver,
        options.check,
    )
    assert gen.hessian == DEFAULTS.solver.ipopt_hessian
    study = parser.parse_args(["study", "--db", "x.db"])
    assert (study.surfaces, study.workers, study.first_seed) == (
        STUDY_DEFAULTS.surfaces,
        STUDY_DEFAULTS.workers,
        STUDY_DEFAULTS.first_seed,
    )


# ------------------------------------- what OpenSees, CasADi and IPOPT print: only --verbose
@pytest.fixture
def noisy_solvers(monkeypatch):
    """IPOPT at print level 5 (its banner and every iteration, through CasADi) and OpenSees
    printing its model (``printModel``) whenever rigidfold wipes it, as each would when
    something went wrong."""
    import openseespy.opensees as ops

    import rigidfold.develop.diagram
    import rigidfold.optimize.ipopt

    real_options, real_wipe = rigidfold.optimize.ipopt.ipopt_options, ops.wipe

    def loud_options(*args, **kwargs):
        return {**real_options(*args, **kwargs), "ipopt.print_level": 5, "print_time": True}

    def loud_wipe():
        ops.printModel()
        real_wipe()

    for module in (rigidfold.optimize.ipopt, rigidfold.develop.diagram):
        monkeypatch.setattr(module, "ipopt_options", loud_options)
    monkeypatch.setattr(ops, "wipe", loud_wipe)


SOLVER_NOISE = ("Ipopt", "EXIT:", "Number of Iterations", "Node:", "Element:", "Domain")
"""Text that IPOPT (print level 5) and OpenSees (printModel) print."""


def solver_text(text: str) -> list[str]:
    return [marker for marker in SOLVER_NOISE if marker in text]


def test_nothing_from_opensees_or_ipopt_reaches_the_terminal(tmp_path, capfd, noisy_solvers):
    """generate, optimize, deform, develop, analyze, export and report run in this process
    with the solvers made to print: standard output holds rigidfold's lines only, standard
    error nothing."""
    from rigidfold.patterns import miura

    shape = miura(3, 3)
    fold = write_fold(tmp_path / "miura.fold", shape)
    run = tmp_path / "run"
    commands = {
        "generate": (["--surface", "dome", "--pattern", "grid:3x3", "--quiet"], run, 6),
        "optimize": (["--surface", "dome", "--pattern", "grid:3x3"], tmp_path / "opt", 2),
        "deform": ([str(fold)], tmp_path / "deform", 4),
        "develop": ([str(fold)], tmp_path / "develop", 2),
        "export": ([str(fold), "--to", "obj"], tmp_path / "export", 2),
        "analyze": ([str(fold)], None, 4),
        "report": ([str(run)], None, 1),
    }
    for command, (args, out, n_lines) in commands.items():
        argv = [command, *args, *([] if out is None else ["--out", str(out)])]
        assert main(argv) in (0, 1), command
        captured = capfd.readouterr()
        assert solver_text(captured.out + captured.err) == [], (command, captured)
        assert captured.err == "", (command, captured.err)
        assert len(captured.out.strip().splitlines()) == n_lines, (command, captured.out)
    # --verbose lets them through
    assert main(["--verbose", "deform", str(fold), "--out", str(tmp_path / "loud")]) == 0
    captured = capfd.readouterr()
    assert "Ipopt" in captured.out and "Node:" in captured.out + captured.err
    loud = ["--verbose", "optimize", *commands["optimize"][0]]
    assert main([*loud, "--out", str(tmp_path / "loud_opt")]) in (0, 1)
    assert "Number of Iterations" in capfd.readouterr().out


def test_a_study_prints_only_its_own_lines(tmp_path):
    """The study's Dask workers run in processes of their own, which inherit the terminal:
    nothing of theirs (IPOPT, CasADi, Dask) reaches it."""
    db = tmp_path / "s.db"
    args = ["study", "--surfaces", "1", "--patterns", "1", "--criteria", "s", "--no-deform"]
    proc = run_cli(*args, "--quiet", "--workers", "1", "--db", str(db))
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert proc.stdout.startswith("1 runs done, 0 already in") and proc.stdout.count("\n") == 1


def test_native_quiet_drops_what_the_quiet_thread_prints_only(capsys, monkeypatch):
    import threading

    from rigidfold.runtime.quiet import VERBOSE_ENV, native_quiet

    streams = sys.stdout, sys.stderr
    monkeypatch.delenv(VERBOSE_ENV, raising=False)
    with native_quiet():
        print("hidden")
        with native_quiet():
            print("hidden too", file=sys.stderr)
        thread = threading.Thread(target=lambda: print("from a progress bar's thread"))
        thread.start()
        thread.join()
        print("hidden again")
    print("shown")
    assert (sys.stdout, sys.stderr) == streams
    captured = capsys.readouterr()
    assert captured.out == "from a progress bar's thread\nshown\n" and captured.err == ""
    monkeypatch.setenv(VERBOSE_ENV, "1")
    with native_quiet():
        print("verbose")
    assert capsys.readouterr().out == "verbose\n"


# ----------------------------------------- bad input or a bug; flags made from the records
@pytest.mark.parametrize(
    "argv",
    [
        [*OPTIMIZE_RUN, "--out", ""],
        ["generate", "--surface", "dome", "--pattern", "1", "--out", ""],
        ["develop", "x.fold", "--out", ""],
        ["study-report", "x.sqlite", "--out", ""],
    ],
)
def test_an_empty_output_directory_is_refused(tmp_path, monkeypatch, capsys, argv):
    """``--out ""`` would write into the current directory: refused, one line, exit 2."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    assert "argument --out: an empty directory name" in _one_line_error(capsys)
    assert list(tmp_path.iterdir()) == []


def test_a_bug_is_not_called_bad_input(tmp_path, monkeypatch, capsys):
    """An exception that is not a RigidfoldError (here a ValueError of a library below) is a
    bug: one line saying so and where its traceback is, exit code 1."""
    import rigidfold.pipeline.workflows

    def broken(*args, **kwargs):
        raise ValueError("operands could not be broadcast together")

    monkeypatch.setattr(rigidfold.pipeline.workflows, "optimize_case", broken)
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    assert main([*OPTIMIZE_RUN, "--out", str(tmp_path / "o")]) == 1
    line = _one_line_error(capsys)
    assert line.startswith("rigidfold: error: a bug in rigidfold, not in the input: ValueError")
    (written,) = tmp_path.glob("rigidfold-bug-*.txt")
    assert f"the traceback is in {written}" in line
    assert "Traceback" in written.read_text() and "broken" in written.read_text()


def test_a_documented_field_is_a_flag():
    """A field of an options record made by flags.option is a flag, its help the field's
    documentation, its default the record's, its value checked by its parse."""
    import argparse
    from dataclasses import dataclass

    from rigidfold.cli.parser import Parser, add_options, options_of
    from rigidfold.flags import option

    @dataclass(frozen=True)
    class Options:
        time_limit: float | None = option(
            None, "stop after this many seconds", parse="positive", metavar="S"
        )
        retries: int = option(2, "tries of each solve", parse="count")
        fast: bool = option(False, "the fast path")
        check: bool = option(True, "the final check")
        hidden: str = option("x", "not on the command line", flag=False)

    parser = Parser(prog="t")
    add_options(parser, Options)
    assert parser.long_options == ["--help", "--time-limit", "--retries", "--fast", "--no-check"]
    help_text = " ".join(parser.format_help().split())
    assert "--time-limit S stop after this many seconds" in help_text
    assert (
        "tries of each solve (default: 2)" in help_text and "turn off the final check" in help_text
    )
    args = parser.parse_args(["--time-limit", "60", "--fast", "--no-check"])
    assert options_of(Options, args) == Options(60.0, 2, True, False)
    assert (
        isinstance(args, argparse.Namespace) and options_of(Options, args, hidden="y").hidden == "y"
    )
    with pytest.raises(SystemExit):
        parser.parse_args(["--retries", "-1"])
