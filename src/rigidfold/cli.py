"""Command-line interface: parses arguments and calls library functions.

Every user error (bad option value, refused expression, unwritable directory, malformed
file: a :class:`rigidfold.RigidfoldError`, or another ``ValueError``) is reported as one line
on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import atexit
import difflib
import io
import json
import math
import os
import re
import sys
import unicodedata
from collections.abc import Sequence

from rigidfold import __version__
from rigidfold.cli_checks import (
    fabricate_arguments,
    fabricate_options,
    positive,
    structure_arguments,
    structure_options,
    structure_progress,
)
from rigidfold.config import CHECKS, DEFAULT_SEED, DEFAULTS, HESSIANS, check_seed
from rigidfold.errors import RigidfoldError
from rigidfold.exports import CONVENTIONS, EXPORT_FORMATS
from rigidfold.generate import GenerateOptions
from rigidfold.interrupts import EXIT_INTERRUPTED, terminate_interrupts
from rigidfold.io import UP_AXES, jsonable
from rigidfold.optimize import SOLVERS
from rigidfold.patterns import DEFAULT_SIZE, DIAGONALS, FORMS
from rigidfold.quiet import VERBOSE_ENV, native_output_shown
from rigidfold.selection import CRITERIA
from rigidfold.structure import MATERIALS
from rigidfold.study import STUDY_DEFAULTS
from rigidfold.surfaces import SURFACE_FORMS

GENERATE_DEFAULTS = GenerateOptions()
"""The defaults of ``generate``'s options (criterion, target DOF, solver, check)."""

EXIT_USAGE = 2
BACKTRACK_HELP = (
    "with the deployability check: how many times a run may retract a solution whose shape "
    "had no deployable candidate and resume at the shape before, with its next candidates "
    f"(default: {DEFAULTS.generation.backtrack_max}; 0: never, as in the paper's Step 7)"
)


LOOKAHEAD_HELP = (
    "skip the candidate creases whose fix would lock another crease at first order, or "
    "locked one at an earlier shape (tried only once every other candidate failed, first "
    "together with the nearly flat creases they would lock)"
)
EXIT_FAILED = 1  # generate fell short; runs of a study failed
EXIT_PIPE = 141  # as a shell reports a process ended by SIGPIPE
OUT_HELP = "output directory (created if absent)"
WORKERS_HELP = "local worker processes, each running one generate at a time (default: %(default)s)"
FOLD_HELP = (
    "a FOLD file of the shape (its top-level frame): vertices_coords in 3D (2D: a flat "
    "sheet), faces_vertices (polygons are triangulated, the added diagonals fixed); edges "
    "assigned J or marked in edges_rigidfold:fixed are fixed creases, the other interior "
    "edges free creases"
)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) and exit code 2; an invalid choice gets
    the nearest one ("did you mean 'generate'?")."""

    def error(self, message: str):
        choice = _INVALID_CHOICE.search(message)
        if choice is not None:
            near = _nearest(choice[1], re.findall(r"'([^']*)'", choice[2]))
            message += f" (did you mean '{near}'?)" if near else ""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {one_line(message)}\n")


_INVALID_CHOICE = re.compile(r"invalid choice: '(.*)' \(choose from (.*)\)$")


def _nearest(word: str, names: Sequence[str]) -> str | None:
    """The name of ``names`` nearest to a misspelt ``word``; None when none is near."""
    near = difflib.get_close_matches(word, names, n=1, cutoff=0.6)
    return near[0] if near else None


def _unknown_options(parser: argparse.ArgumentParser, argv: Sequence[str]) -> None:
    """Refuse, through the command's parser, the first ``--option`` of ``argv`` that the
    command does not know (nor abbreviates), naming the nearest option it has ("did you mean
    --target-dof?"); before argparse's own checks, so that a misspelt required option is
    called misspelt rather than missing."""
    commands = next(
        (a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), {}
    )
    at = next((k for k, a in enumerate(argv) if not a.startswith("-")), None)
    sub = commands.get(argv[at]) if at is not None else None
    if at is None or not isinstance(sub, argparse.ArgumentParser):
        return
    known = [o for a in sub._actions for o in a.option_strings if o.startswith("--")]
    for arg in argv[at + 1 :]:  # those before the command are the program's (--verbose)
        if arg == "--":
            return
        name = arg.partition("=")[0]
        if not name.startswith("--") or any(o.startswith(name) for o in known):
            continue
        near = _nearest(name, known)
        sub.error(f"unrecognized arguments: {arg}" + (f" (did you mean {near}?)" if near else ""))


_ESCAPES = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def one_line(text: str) -> str:
    """``text`` with its control characters escaped as Python writes them in strings (a
    newline as ``\\n``, ESC as ``\\x1b``, U+2028 as ``\\u2028``), so that a message that
    carries a file name or a value read from a file prints as one line and cannot move the
    cursor, clear the screen or retitle the terminal. Backslashes are kept as they are."""
    out = []
    for ch in text:
        if unicodedata.category(ch) in ("Cc", "Zl", "Zp"):
            ch = _ESCAPES.get(ch) or ascii(ch)[1:-1]
        out.append(ch)
    return "".join(out)


def _error(message: str) -> None:
    """Print ``rigidfold: error: <message>`` on stderr, on one line (:func:`one_line`)."""
    print(f"rigidfold: error: {one_line(message)}", file=sys.stderr)


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value < 1:
        raise argparse.ArgumentTypeError(f"must be a number from 0 to below 1, got {text!r}")
    return value


def _svg_tolerance(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--svg-tolerance",
        type=_fraction,
        default=DEFAULTS.inputs.svg_snap_tol,
        metavar="FRACTION",
        help="slips of the pen in an SVG pattern mended, as a fraction of the drawing's "
        "diagonal: a crease overshooting the line it ends on, or ending short of one, by up "
        "to this much is cut or extended to it; 0 mends nothing (default: %(default)g, "
        "Settings.inputs.svg_snap_tol)",
    )


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
    try:
        return check_seed(value)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command. Every option's help says what its value means and, where
    it has one, its default ("default: ..."), taken from the library."""
    parser = _Parser(
        prog="rigidfold",
        description="Form generation of developable, rigid-foldable origami.",
    )
    parser.add_argument("--version", action="version", version=f"rigidfold {__version__}")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="show what OpenSees, CasADi and IPOPT print (their warnings and logs, and "
        "OpenSees's message when the process ends); hidden by default",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    gen = sub.add_parser(
        "generate",
        help="Steps 2-7: fix crease lines one by one down to the target DOF",
        description="Generate developable, rigid-foldable shapes of decreasing DOF. Writes "
        "DIR/solutions/step_XX_dof_YY.fold, DIR/log.json and DIR/summary.json as it goes; the "
        "last line names the final design (the last solution). Exit code 0 when the target DOF "
        "was reached and every check that ran on the final design (development diagram, "
        "folding motion, large deformation; thick panels and structure with --thickness and "
        "--structure) passed, 1 when the run fell short (the files are "
        "written all the same; the last line says what fell short, and notes the checks that "
        "failed on earlier solutions), 2 on bad input, 130 when interrupted.",
    )
    _case_options(
        gen,
        out="output directory: solutions/, log.json, summary.json, final/ (the final design "
        "exported in every format of rigidfold export) and report.html",
    )
    gen.add_argument(
        "--criterion",
        default=GENERATE_DEFAULTS.criterion,
        choices=CRITERIA,
        help="how the next crease line to fix is chosen, lowest score first (Section 5): shat "
        "= S-hat and s = S, the shape score S^S over the mechanism score (from normalised or "
        "plain mechanism modes), ss = S^S alone, random (default: %(default)s)",
    )
    gen.add_argument(
        "--target-dof",
        type=int,
        default=GENERATE_DEFAULTS.target_dof,
        help="stop at a shape with this many degrees of freedom (DOF: independent rigid "
        "folding motions; 1 = folds along one path; default: %(default)s)",
    )
    gen.add_argument("--lookahead", action="store_true", help=LOOKAHEAD_HELP)
    gen.add_argument(
        "--retry-zero-dof",
        action="store_true",
        help="treat a 0-DOF solution as a lock and try the next crease (the paper's Step 5 "
        "ends generation there; with the deployability check, the default, a 0-DOF solution "
        "is always retried, since it cannot deploy)",
    )
    gen.add_argument(
        "--no-deform",
        action="store_true",
        help="skip the large-deformation check (Step 9, OpenSees); the development diagram "
        "(Step 8) and the folding motion still run",
    )
    gen.add_argument(
        "--no-deploy-check",
        action="store_true",
        help="the paper's Step 5: accept a solution without tracing its folding path to the "
        "flat state (by default a solution of at most DOF max(target, "
        f"{DEFAULTS.generation.deploy_check_max_dof}) whose path does not reach the flat state is "
        "replaced like a lock and counted in N_path)",
    )
    gen.add_argument("--backtrack", type=int, metavar="N", help=BACKTRACK_HELP)
    gen.add_argument(
        "--check",
        choices=CHECKS,
        default=GENERATE_DEFAULTS.check,
        help="which solutions get the folding motion and the large-deformation check: the "
        "final design only, or all (default: %(default)s; the development diagram is drawn "
        "for every solution)",
    )
    fabricate_arguments(gen, generate=True)
    structure_arguments(gen, generate=True)
    gen.add_argument(
        "--quiet", action="store_true", help="no progress bar (the result lines are printed)"
    )
    gen.add_argument(
        "--no-report",
        action="store_true",
        help="do not write DIR/report.html at the end (rigidfold report DIR writes it later)",
    )
    gen.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the files of an earlier run in DIR (refused otherwise); other files in "
        "DIR are kept",
    )
    gen.set_defaults(func=_cmd_generate)

    rpt = sub.add_parser(
        "report",
        help="DIR/report.html of a generate run: the answer, 3D view, figures and tables",
        description="Write DIR/report.html (one self-contained page that opens offline: the "
        "final design in 3D with its folding motion, the figures, the tables of summary.json) "
        "and DIR/figures/*.png for the generate run in DIR.",
    )
    rpt.add_argument("dir", metavar="DIR", help="the --out directory of rigidfold generate")
    rpt.add_argument("--json", action="store_true", help="print one JSON object")
    rpt.set_defaults(func=_cmd_report)

    _file_command(
        sub,
        "analyze",
        _cmd_analyze,
        help="mechanism analysis of a FOLD shape: DOF, locked creases, fold angles",
        description="Read a FOLD file (3D vertices_coords; polygon faces are triangulated with "
        "fixed 'J' edges) and report its DOF and locked crease lines.",
    )
    _file_command(
        sub,
        "develop",
        _cmd_develop,
        out=True,
        help="Step 8: development diagram of a FOLD shape (problem 13)",
        description="Flatten a FOLD shape to its development diagram. Writes DIR/<name>.fold "
        "(the input plus a 'creasePattern' frame with 2D coordinates) and DIR/<name>.svg. Exit "
        "code 0 when the development converged, 1 when not, 2 on bad input.",
    )
    dfm = _file_command(
        sub,
        "deform",
        _cmd_deform,
        out=True,
        help="Step 9: large-deformation check of a FOLD shape (OpenSees) and its folding motion",
        description="Drive the frame model of a FOLD shape to the plane with OpenSees (tubes "
        f"{DEFAULTS.deformation.tube_diameter * 1e3:g} mm x "
        f"{DEFAULTS.deformation.tube_wall * 1e3:g} mm, E = "
        f"{DEFAULTS.deformation.youngs_modulus / 1e9:g} GPa, "
        f"{DEFAULTS.deformation.steps} load steps) and trace "
        "its folding motion (a rigid-folding path from the plane, the support panel held "
        "still); a line says whether the two verdicts agree and, when not, why. Writes "
        "DIR/<name>.fold (the input plus the development diagram and the motion frames), "
        "DIR/<name>.svg (the development diagram) and DIR/<name>_deform.json (figures and the "
        "load-step history). Exit code 0 when the plane is reached, 1 when not, 2 on bad "
        "input.",
    )
    dfm.add_argument(
        "--material",
        default=None,
        metavar="NAME|E,nu,density",
        help="build the frame's members as strips of these panels instead of the paper's "
        "tubes (each triangle's area shared by its three members, the panel's thickness): a "
        f"preset ({', '.join(MATERIALS)}) or E,nu,density in SI units; with --thickness only, "
        f"{DEFAULTS.structure.material} (default: the tubes)",
    )
    dfm.add_argument(
        "--thickness",
        type=float,
        default=None,
        metavar="T",
        help="panel thickness in metres for --material (default with --material: "
        f"{DEFAULTS.structure.thickness:g})",
    )

    exp = _file_command(
        sub,
        "export",
        _cmd_export,
        out=True,
        help="3D, CAD and cut-sheet files of a FOLD design: OBJ, STL, PLY, GLB, DXF, SVG, CSV, "
        "FOLD for Origami Simulator",
        description="Export a FOLD design (a solution of rigidfold generate, or any FOLD shape): "
        "its folded form as OBJ, STL, PLY and GLB (metres, one group or node per panel), its "
        "development diagram as a cut sheet in DXF and SVG (millimetres at 1:1), its panel "
        "and crease schedule as CSV, and its folded form as a FOLD file that Origami "
        "Simulator opens (fold-os: DIR/<name>.os.fold, y up, creases M, V, F, boundary B), "
        "into DIR/<name>.*. The diagram is the file's 'creasePattern' frame, or computed "
        "(Step 8) when it has none. Exit code 0 when written, 1 when the computed diagram did "
        "not converge (written all the same), 2 on bad input.",
    )
    exp.add_argument(
        "--to",
        default=",".join(EXPORT_FORMATS),
        metavar="FORMATS",
        help=f"comma-separated formats, any of {', '.join(EXPORT_FORMATS)} (default: "
        "%(default)s, i.e. all)",
    )
    exp.add_argument(
        "--convention",
        default=CONVENTIONS[0],
        choices=CONVENTIONS,
        help="of the SVG cut sheet: rigidfold's (layers, labels, legend, scale bar) or "
        "origami-simulator (red/blue/black lines, fold angle as stroke opacity, opens in "
        "Origami Simulator) (default: %(default)s)",
    )

    stc = _file_command(
        sub,
        "structure",
        _cmd_structure,
        out=True,
        help="supports that hold a FOLD design and its panels and hinges under load (OpenSees)",
        description="Check the deployed structure of a FOLD design: the supports (given, or "
        "the fewest boundary vertices that make its mechanism first-order rigid with "
        "--supports auto), then a shell model in OpenSees (panels as plates of the material "
        "and thickness, free creases as hinges, fixed creases continuous) under self-weight "
        "and the --load terms: reactions, displacements, hinge moments, panel stresses and "
        "natural frequencies. Writes DIR/structure.json and DIR/structure.png (the deflected "
        "shape, scaled). Exit code 0 when the supports hold the mechanism and the largest "
        "displacement is within the limit, 1 when they leave a mechanism (named), the "
        "analysis does not converge or the limit is exceeded, 2 on bad input.",
    )
    structure_arguments(stc, generate=False)
    stc.add_argument(
        "--overwrite",
        action="store_true",
        help="replace DIR/structure.json and DIR/structure.png of an earlier check",
    )

    fab = _file_command(
        sub,
        "fabricate",
        _cmd_fabricate,
        out=True,
        help="thick panels of a FOLD design that deploy without collision: solids, hinge "
        "and vertex schedules, nested cut sheets",
        description="Turn the panels of a FOLD design (a solution of rigidfold generate) into "
        "solids of the given thickness on one side of the design surface, the hinge axes on "
        "the crease lines (Tachi's tapered thick panels): every hinge is bevelled for its fold "
        "range from flat to the design plus a clearance angle, and panels that meet at a vertex "
        "without a common hinge are relieved there. Every pair of solids is checked over the "
        "whole folding motion (the file's motion frames, or its traced folding path). Writes "
        "DIR/<name>_solids.glb, .stl, .obj and .3dm (Rhino: layers PANELS, HINGES, CREASES, "
        "LABELS), DIR/<name>_hinges.csv, DIR/<name>_vertices.csv, cut sheets in mm nested onto "
        "stock sheets (DIR/<name>_sheet_NN.dxf and .svg) and DIR/<name>_fabricate.json; the "
        "files of an earlier fabricate of the same design in DIR are refused unless "
        "--overwrite, and replacing the input is refused always. Exit "
        "code 0 when the deployment is collision-free, 1 when not (the files are written; the "
        "last line names the panels, the fraction folded where they meet and a thickness that "
        "would pass), 2 on bad input.",
    )
    fabricate_arguments(fab, generate=False)
    fab.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the files of an earlier fabricate of the same design in DIR (its cut "
        "sheets included); without it they are refused",
    )

    stu = sub.add_parser(
        "study",
        help="many generate runs on Dask, results in SQLite (Tables 5-8), resumable",
        description="Run generate for every (Bezier seed, pattern, criterion), or a preset, on "
        "Dask workers; store each finished run in DB. Re-running the same command skips "
        "finished runs, so a killed study resumes where it stopped.",
    )
    plan = STUDY_DEFAULTS
    stu.add_argument(
        "--patterns",
        default=",".join(plan.patterns),
        help="comma-separated crease pattern specs, each with its defaults (the paper's names, "
        "grid:NXxNY, mesh:FILE, FILE.fold, FILE.svg; default: %(default)s)",
    )
    stu.add_argument(
        "--criteria",
        default=",".join(plan.criteria),
        help=f"comma-separated selection criteria, any of {', '.join(CRITERIA)} (see generate "
        "--criterion; default: %(default)s)",
    )
    stu.add_argument(
        "--surfaces",
        type=int,
        default=plan.surfaces,
        help="number of random Bezier target surfaces, seeds --first-seed, --first-seed + 1, "
        "... (default: %(default)s)",
    )
    stu.add_argument(
        "--first-seed",
        type=_seed,
        default=plan.first_seed,
        help="seed of the first Bezier surface, 0 to 2**63 - 1 (default: %(default)s)",
    )
    stu.add_argument(
        "--preset", help="dome, hp or dome,hp: Sections 6.5-6.6 instead of Bezier surfaces"
    )
    stu.add_argument("--db", required=True, metavar="DB", help="SQLite file (created if absent)")
    where = stu.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=plan.workers, help=WORKERS_HELP)
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="address of an existing Dask scheduler (e.g. tcp://host:8786), instead of local "
        "workers",
    )
    stu.add_argument(
        "--connect-timeout",
        type=float,
        default=plan.connect_timeout,
        metavar="S",
        help="seconds that --scheduler has to answer (default: %(default)s)",
    )
    stu.add_argument(
        "--allow-mixed-numerics",
        action="store_true",
        help="add runs to a database whose runs were computed with other numerics (another "
        "machine's BLAS, SIMD or libm, or other library versions), and accept Dask workers "
        "that compute with other numerics than this process",
    )
    stu.add_argument(
        "--no-deform",
        action="store_true",
        help="skip the large-deformation check (Step 9, OpenSees) of each solution, as in "
        "generate; a study writes no development diagram, so Step 8 (its D in Table 7) runs "
        "only with Step 9",
    )
    stu.add_argument("--lookahead", action="store_true", help=LOOKAHEAD_HELP)
    stu.add_argument(
        "--deploy-check",
        action="store_true",
        help="accept only solutions whose folding path reaches the flat state, as generate "
        "does by default (N_path); without it the study runs the paper's Step 5 and traces "
        "only each final design's path (whether it deploys)",
    )
    stu.add_argument("--backtrack", type=int, metavar="N", help=BACKTRACK_HELP)
    stu.add_argument(
        "--hessian",
        default=DEFAULTS.solver.ipopt_hessian,
        choices=HESSIANS,
        help="IPOPT's Hessian of the Lagrangian: closed-form or casadi (the symbolic "
        "reference, used by studies made before the closed form; default: %(default)s)",
    )
    _svg_tolerance(stu)
    stu.add_argument("--quiet", action="store_true", help="no progress bar")
    stu.set_defaults(func=_cmd_study)

    rep = sub.add_parser(
        "study-report",
        help="Tables 5-8 of a study database beside the paper's, with box plots",
    )
    rep.add_argument("db", metavar="DB", nargs="+", help="one or more study databases")
    rep.add_argument(
        "--out",
        metavar="DIR",
        help="also write DIR/results.md and PNG box plots (the tables are printed either way)",
    )
    rep.set_defaults(func=_cmd_study_report)

    opt = sub.add_parser(
        "optimize",
        help="solve problem (6): a developable polyhedron near a target surface",
        description="Solve problem (6) once and write DIR/solution.fold and DIR/summary.json. "
        "Exit code 0 when the solution is accepted (F <= F_tol, constraints met), 1 when not "
        "(the files are written all the same), 2 on bad input. A DIR that holds an earlier "
        "run's files is refused unless --overwrite.",
    )
    _case_options(opt, out=f"{OUT_HELP}: solution.fold and summary.json")
    opt.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the solution.fold and summary.json of an earlier run in DIR (refused "
        "otherwise); other files in DIR are kept",
    )
    opt.add_argument(
        "--fixed",
        help="comma-separated indices (into the pattern's edges, as in its FOLD "
        "edges_vertices) of the crease lines to fix: each is held flat, joining its two "
        "triangles into one rigid panel (default: none)",
    )
    opt.set_defaults(func=_cmd_optimize)
    return parser


def _file_command(
    sub, name: str, func, *, out: bool = False, **text: str
) -> argparse.ArgumentParser:
    """A command on one FOLD file: FILE.fold [--out DIR] [--up AXIS] [--json]; returns its
    parser."""
    p = sub.add_parser(name, **text)
    p.add_argument("file", metavar="FILE.fold", help=FOLD_HELP)
    if out:
        p.add_argument("--out", required=True, metavar="DIR", help=OUT_HELP)
    p.add_argument(
        "--up",
        default=UP_AXES[0],
        choices=UP_AXES,
        help="the file's up axis: y for files drawn y-up (Blender, Origami Simulator); "
        "coordinates are read in the file's frame_unit and converted to metres (default: "
        "%(default)s)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=func)
    return p


def _case_options(p: argparse.ArgumentParser, *, out: str) -> None:
    p.add_argument(
        "--surface",
        required=True,
        metavar="SURFACE",
        help=f"target surface: {SURFACE_FORMS}. bezier, dome, hp: the paper's, scaled to the "
        "pattern's plan; expr: z = f(x, y) of --expr in metres; mesh:FILE: an OBJ, STL, PLY or "
        "OFF mesh, fitted by a smooth surface; fold:FILE: the 3D shape of a FOLD file. A mesh "
        "is placed like the pattern, the lower-left corner of its plan at (0, 0)",
    )
    p.add_argument(
        "--seed",
        type=_seed,
        default=DEFAULT_SEED,
        help="random seed, 0 to 2**63 - 1: of the Bezier surface; generate also draws from it "
        "the fictitious hinge stiffnesses K_j (uniform in "
        f"{DEFAULTS.generation.hinge_stiffness:g} +/- "
        f"{DEFAULTS.generation.hinge_stiffness_spread:g} Nm, Section "
        "6.1) that the s and shat criteria rank by, and the order of the random criterion "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--expr",
        help="z = f(x, y) for --surface expr, e.g. '0.2*sin(x)*y'; the next argument is the "
        "expression even when it starts with '-' (--expr -x*y)",
    )
    p.add_argument(
        "--pattern",
        required=True,
        help=f"crease pattern: {FORMS}. 1, 1p, 2, 11: the paper's, on 3 m x 3 m; grid:NXxNY: "
        "NX x NY vertices over --size with --diagonals; mesh:POLYGON: a quality triangulation "
        "of the polygon 'x1,y1;x2,y2;...' in metres, or of a file of 'x,y' lines, with "
        "--edge-length; FILE.fold, FILE.svg: a crease pattern drawn in another tool (SVG in "
        "Origami Simulator's colours: red mountain, blue valley, black boundary, yellow flat), "
        "in its own unit or, drawn without one, fitted into --size. The plan is placed with "
        "the lower-left corner of its bounding box at (0, 0); the built-in surfaces scale to "
        "that box, --expr is in metres as given",
    )
    _svg_tolerance(p)
    p.add_argument(
        "--size",
        metavar="WxH",
        help="plan size in metres of a grid: pattern, or the box a FOLD or SVG file drawn "
        "without units is fitted into, aspect ratio kept (default: {:g}x{:g})".format(
            *DEFAULT_SIZE
        ),
    )
    p.add_argument(
        "--scale",
        type=positive,
        metavar="M_PER_UNIT",
        help="metres per unit of a FOLD or SVG file drawn without units (instead of --size)",
    )
    p.add_argument(
        "--rigid-panels",
        action="store_true",
        help="a FOLD or SVG file's polygon faces are rigid flat panels: the diagonals that "
        "triangulate them start as fixed creases (default: free creases)",
    )
    p.add_argument(
        "--up",
        default=UP_AXES[0],
        choices=UP_AXES,
        help="the up axis of a FOLD pattern and of a mesh: or fold: surface: y for files drawn "
        "y-up (Blender, Origami Simulator) (default: %(default)s)",
    )
    p.add_argument(
        "--diagonals",
        choices=DIAGONALS,
        help=f"how a grid: pattern's cells are cut into triangles (default: {DIAGONALS[0]})",
    )
    p.add_argument(
        "--edge-length",
        type=positive,
        metavar="L",
        help="target edge length in metres of a mesh: pattern (default: sqrt(footprint area) "
        f"/ {DEFAULTS.inputs.mesh_divisions:g})",
    )
    p.add_argument(
        "--symmetric",
        action="store_true",
        help="make the shape mirror-symmetric about the target surface's mirror planes "
        "(dome, hp; refused for a surface without any)",
    )
    p.add_argument(
        "--solver",
        default=GENERATE_DEFAULTS.solver,
        choices=SOLVERS,
        help="solver of problem (6) (default: %(default)s)",
    )
    p.add_argument(
        "--hessian",
        default=DEFAULTS.solver.ipopt_hessian,
        choices=HESSIANS,
        help="IPOPT's Hessian of the Lagrangian (both exact; they differ by round-off; "
        "default: %(default)s)",
    )
    p.add_argument(
        "--dz",
        type=float,
        default=DEFAULTS.design.dz,
        help="bound on |z - f(x, y)|: how far, in metres, each vertex may lie above or below "
        "the target surface (default: %(default)s)",
    )
    for bound, word in (("min", "smallest"), ("max", "largest")):
        default = math.degrees(getattr(DEFAULTS.design, f"theta_{bound}"))
        p.add_argument(
            f"--theta-{bound}",
            type=float,
            metavar="DEG",
            help=f"{word} sector angle (corner angle of a triangle at a vertex) allowed, "
            f"degrees (default: {default:g})",
        )
    p.add_argument(
        "--rho-max",
        type=positive,
        metavar="DEG",
        help="bound (12) on the fold angle of every free crease, |rho| <= this, degrees "
        "(default: no bound)",
    )
    p.add_argument("--out", required=True, metavar="DIR", help=out)


def _backtrack(args: argparse.Namespace) -> dict:
    """``backtrack_max`` of ``--backtrack`` where given (checked by Settings), else {}."""
    value = getattr(args, "backtrack", None)
    return {} if value is None else {"backtrack_max": value}


def _case(args: argparse.Namespace):
    from rigidfold.case import make_case
    from rigidfold.config import Settings

    if args.surface == "expr" and not args.expr:
        raise RigidfoldError("--surface expr needs --expr TEXT, e.g. --expr '0.3*sin(x)*cos(y)'")
    if args.expr and args.surface != "expr":
        raise RigidfoldError(f"--expr is only used with --surface expr, not {args.surface}")
    settings = Settings.from_degrees(
        dz=args.dz,
        theta_min_deg=args.theta_min,
        theta_max_deg=args.theta_max,
        rho_bar_deg=args.rho_max,
        zero_dof_ends=not getattr(args, "retry_zero_dof", False),
        **_backtrack(args),
        ipopt_hessian=args.hessian,
        svg_snap_tol=args.svg_tolerance,
    )
    case = make_case(
        args.surface,
        args.pattern,
        seed=args.seed,
        expr=args.expr,
        symmetric=args.symmetric,
        size=args.size,
        diagonals=args.diagonals,
        edge_length=args.edge_length,
        scale=args.scale,
        up=args.up,
        rigid_panels=args.rigid_panels,
        settings=settings,
    )
    for warning in case.warnings:
        print(one_line(f"rigidfold: warning: {warning}"), file=sys.stderr)
    return case


def _cmd_optimize(args: argparse.Namespace) -> int:
    from rigidfold.workflows import optimize_case

    out = optimize_case(
        _case(args), args.out, fixed=args.fixed, solver=args.solver, overwrite=args.overwrite
    )
    result = out.result
    print(
        f"{result.status.value}: F = {result.F:.3e} (F1 = {result.F1:.2e}, F2 = {result.F2:.2e}), "
        f"{result.iterations} iterations, {result.wall_time:.2f} s solve + "
        f"{out.build_time:.2f} s build, {result.n_variables} variables"
    )
    print(f"wrote {' and '.join(str(p) for p in out.written)}")
    if not result.converged:
        from rigidfold.run.verdict import SOLVE_HINT

        print(f"not accepted: {SOLVE_HINT}")
    return 0 if result.converged else 1


def _cmd_generate(args: argparse.Namespace) -> int:
    from rigidfold.progress import GenerateProgress
    from rigidfold.run import RunOutcome, RunWriter
    from rigidfold.workflows import generate_case

    if args.target_dof < 0:
        raise RigidfoldError(f"--target-dof must be >= 0, got {args.target_dof}")
    structure = structure_options(args)  # checked even without --structure
    options = GenerateOptions(
        criterion=args.criterion,
        target_dof=args.target_dof,
        seed=args.seed,
        solver=args.solver,
        lookahead=args.lookahead,
        deploy_check=not args.no_deploy_check,
        deform=not args.no_deform,
        check=args.check,
        material=args.material,
        fabricate=fabricate_options(args),
        structure=structure if args.structure else None,
    )
    writer = RunWriter(args.out, _case(args), options, overwrite=args.overwrite)
    progress = GenerateProgress(enabled=not args.quiet, target=args.target_dof)
    try:
        run = generate_case(writer, progress=progress.update, report=not args.no_report)
    except KeyboardInterrupt:
        progress.close()
        print(
            one_line(
                f"rigidfold: interrupted; {_count(len(writer.files), 'solution')}, log.json "
                f"and summary.json are in {writer.out}"
            ),
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    progress.close()
    summary = run.to_dict()
    print(
        f"{run.stop_reason}: DOF {summary['initial_dof']} -> {summary['final_dof']}, "
        f"N_reduce={summary['N_reduce']} N_lock={summary['N_lock']} "
        f"N_exceed={summary['N_exceed']} N_path={summary['N_path']}, "
        f"{summary['n_solves']} solves"
    )
    print(
        f"wrote {_count(len(writer.files), 'solution')}, log.json and summary.json to {writer.out}"
    )
    if writer.exports:
        names = ", ".join(p.name for p in writer.exports)
        print(f"exported the final design to {writer.out / 'final'}: {names}")
    if writer.final_verdicts is not None:
        print(f"final design: {writer.final_verdicts}")
    if writer.fabrication is not None:
        print(
            one_line(
                f"thick panels ({writer.out / 'final' / 'thick'}): {writer.fabrication.last_line()}"
            )
        )
    if writer.structure is not None:
        print(
            one_line(
                f"structure ({writer.out / 'final' / 'structure'}): "
                f"{writer.structure.status}: {writer.structure.message}"
            )
        )
    if not args.no_report:
        print(f"report: {writer.out / 'report.html'}")
    verdict = writer.verdict
    assert verdict is not None  # generate_case ends with writer.finish
    final = "none" if verdict.final_design is None else writer.out / verdict.final_design
    print(f"{verdict.outcome.value.replace('_', ' ')}: {verdict.message}; final design: {final}")
    return 0 if verdict.outcome is RunOutcome.PASSED else EXIT_FAILED


def _cmd_report(args: argparse.Namespace) -> int:
    from rigidfold.workflows import report_run

    report = report_run(args.dir)
    if args.json:
        print(json.dumps(jsonable(report.to_dict())))
    else:
        info = report.to_dict()
        print(
            f"wrote {info['report']} ({info['size_bytes'] / 1e6:.1f} MB) and "
            f"{len(report.figures)} figures in {report.html.parent / 'figures'}"
        )
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    from rigidfold.workflows import analyze_file

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
    from rigidfold.workflows import develop_file

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
    from rigidfold.workflows import deform_file

    checked = deform_file(
        args.file, args.out, up=args.up, material=args.material, thickness=args.thickness
    )
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
    from rigidfold.workflows import export_file

    done = export_file(args.file, args.out, formats=args.to, convention=args.convention, up=args.up)
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
    from rigidfold.structure import StructureStatus
    from rigidfold.workflows import structure

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
    from rigidfold.workflows import fabricate_file

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


def _cmd_study(args: argparse.Namespace) -> int:
    from rigidfold.progress import StudyProgress
    from rigidfold.study import (
        STUDY_OPTIONS,
        StudyConfig,
        StudyInterrupted,
        failure_summary,
        plan,
        preset,
        run_study_command,
    )

    settings = DEFAULTS.with_(
        ipopt_hessian=args.hessian, svg_snap_tol=args.svg_tolerance, **_backtrack(args)
    )
    if args.preset is not None:
        keys = preset(args.preset)
    else:
        keys = plan(
            _names(args.patterns),
            _names(args.criteria),
            args.surfaces,
            args.first_seed,
            settings=settings,
        )
    config = StudyConfig(
        STUDY_OPTIONS.replace(
            deform=not args.no_deform, lookahead=args.lookahead, deploy_check=args.deploy_check
        ),
        settings,
    )
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


def _names(text: str) -> list[str]:
    """Comma-separated names, blanks dropped."""
    return [t.strip() for t in text.split(",") if t.strip()]


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    argv = _attached_values(sys.argv[1:] if argv is None else argv)
    _unknown_options(parser, argv)
    args = parser.parse_args(argv)
    if not (args.verbose or native_output_shown()):
        _quiet_exit()
    shown = os.environ.get(VERBOSE_ENV)
    if args.verbose:  # rigidfold.quiet lets the solvers' output through, here and in workers
        os.environ[VERBOSE_ENV] = "1"
    if isinstance(sys.stdout, io.TextIOWrapper):
        # a file name whose bytes are not UTF-8 is printed as those bytes, as ls does, not
        # refused by the encoder after the files were written
        sys.stdout.reconfigure(errors="surrogateescape")
    try:
        code = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not while Python exits
        return code
    except ValueError as exc:  # rigidfold.RigidfoldError, and those of the libraries below
        _error(str(exc))
        return EXIT_USAGE
    except KeyboardInterrupt:
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
    finally:
        if args.verbose:
            _restore_env(VERBOSE_ENV, shown)


def _restore_env(name: str, value: str | None) -> None:
    """Set the environment variable ``name`` back to ``value`` (None: unset)."""
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value


def _attached_values(argv: Sequence[str]) -> list[str]:
    """``argv`` with ``--expr VALUE`` written ``--expr=VALUE``, so that an expression that
    starts with '-' (``--expr -x*y``) is read as the value, not as an option."""
    out: list[str] = []
    args = iter(argv)
    for arg in args:
        if arg == "--":
            out += [arg, *args]
            break
        value = next(args, None) if arg == "--expr" else None
        out.append(arg if value is None else f"{arg}={value}")
    return out


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


if __name__ == "__main__":
    terminate_interrupts()
    sys.exit(main())
