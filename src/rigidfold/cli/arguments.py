"""The arguments of each command of the command line (:data:`ARGUMENTS`, by command): those
of the records it fills, made from their fields (:func:`rigidfold.cli.parser.add_options`:
:class:`~rigidfold.generate.GenerateOptions`,
:class:`~rigidfold.generate.case_options.CaseOptions`,
:class:`~rigidfold.generate.case_options.SettingsOptions`; the checks' in
:mod:`rigidfold.cli.checks`),
and its own (its files, what it prints)."""

from __future__ import annotations

from collections.abc import Callable

from rigidfold.cli.checks import fabricate_arguments, length, structure_arguments
from rigidfold.cli.parser import Parser, add_options, argument_type, directory
from rigidfold.cli.units import parse_material, seed
from rigidfold.config import DEFAULTS
from rigidfold.drive import DriveOptions
from rigidfold.exports import CONVENTIONS, EXPORT_FORMATS
from rigidfold.generate import GenerateOptions
from rigidfold.generate.case_options import CaseOptions, SettingsOptions
from rigidfold.io import UP_AXES
from rigidfold.selection import CRITERIA
from rigidfold.structure import MATERIALS
from rigidfold.study import STUDY_DEFAULTS, STUDY_OPTIONS

OUT_HELP = "output directory (created if absent)"
FOLD_HELP = (
    "a FOLD file of the shape (its top-level frame): vertices_coords in 3D (2D: a flat "
    "sheet), faces_vertices (polygons are triangulated, the added diagonals fixed); edges "
    "assigned J or marked in edges_rigidfold:fixed are fixed creases, the other interior "
    "edges free creases"
)
OVERWRITE_HELP = {
    "generate": "replace the files of an earlier run in DIR (refused otherwise); other files "
    "in DIR are kept",
    "optimize": "replace the solution.fold and summary.json of an earlier run in DIR (refused "
    "otherwise); other files in DIR are kept",
    "structure": "replace DIR/structure.json and DIR/structure.png of an earlier check",
    "fabricate": "replace the files of an earlier fabricate of the same design in DIR (its cut "
    "sheets included); without it they are refused",
    "deploy": "replace DIR/deploy.json, .fold, .csv and .png of an earlier drive (refused "
    "otherwise); other files in DIR are kept",
}


def _generate(p: Parser) -> None:
    _case(
        p,
        out="output directory: solutions/, log.jsonl, summary.json, final/ (the final design "
        "exported in every format of rigidfold export) and report.html",
    )
    add_options(p, GenerateOptions)
    add_options(
        p,
        SettingsOptions,
        only=(
            "backtrack",
            "fold_limit",
            "reseeds",
            "retry_zero_dof",
            "accept_no_gap",
            "dof_count",
        ),
    )
    fabricate_arguments(p, generate=True)
    structure_arguments(p, generate=True)
    p.add_argument(
        "--deploy",
        action="store_true",
        help="the final design's deployment drive as rigidfold deploy finds it with its "
        "defaults (the panels of --thickness and --material): DIR/final/deploy/; the run "
        "falls short when no crease, pair or cable drives the whole motion",
    )
    p.add_argument(
        "--quiet", action="store_true", help="no progress bar (the result lines are printed)"
    )
    p.add_argument(
        "--no-report",
        action="store_true",
        help="do not write DIR/report.html at the end (rigidfold report DIR writes it later)",
    )


def _optimize(p: Parser) -> None:
    _case(p, out=f"{OUT_HELP}: solution.fold and summary.json")
    add_options(p, GenerateOptions, only=("solver",))
    p.add_argument(
        "--fixed",
        help="comma-separated indices (into the pattern's edges, as in its FOLD "
        "edges_vertices) of the crease lines to fix: each is held flat, joining its two "
        "triangles into one rigid panel (default: none)",
    )


def _case(p: Parser, *, out: str) -> None:
    """The target surface, the crease pattern and the settings of problem (6)."""
    add_options(p, CaseOptions)
    add_options(
        p,
        SettingsOptions,
        only=(
            "dz",
            "theta_min",
            "theta_max",
            "theta_widen",
            "rho_max",
            "hessian",
            "svg_tolerance",
        ),
    )
    p.add_argument("--out", required=True, type=directory, metavar="DIR", help=out)


def _file(p: Parser, *, out: bool = True) -> None:
    """A command on one FOLD file: FILE.fold [--out DIR] [--up AXIS] [--json]."""
    p.add_argument("file", metavar="FILE.fold", help=FOLD_HELP)
    if out:
        p.add_argument("--out", required=True, type=directory, metavar="DIR", help=OUT_HELP)
    p.add_argument(
        "--up",
        default=UP_AXES[0],
        choices=UP_AXES,
        help="the file's up axis: y for files drawn y-up (Blender, Origami Simulator); "
        "coordinates are read in the file's frame_unit and converted to metres (default: "
        "%(default)s)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _report(p: Parser) -> None:
    p.add_argument("dir", metavar="DIR", help="the --out directory of rigidfold generate")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _deform(p: Parser) -> None:
    _file(p)
    p.add_argument(
        "--material",
        type=argument_type(parse_material),
        default=None,
        metavar="NAME|E,nu,density",
        help="build the frame's members as strips of these panels instead of the paper's "
        "tubes (each triangle's area shared by its three members, the panel's thickness): a "
        f"preset ({', '.join(MATERIALS)}) or E,nu,density in SI units; with --thickness only, "
        f"{DEFAULTS.structure.material} (default: the tubes)",
    )
    p.add_argument(
        "--thickness",
        type=length("thickness"),
        default=None,
        metavar="T",
        help="panel thickness for --material, in metres or with a unit: 18mm, 1.8cm (default "
        f"with --material: {DEFAULTS.structure.thickness:g})",
    )


def _export(p: Parser) -> None:
    _file(p)
    p.add_argument(
        "--to",
        default=",".join(EXPORT_FORMATS),
        metavar="FORMATS",
        help=f"comma-separated formats, any of {', '.join(EXPORT_FORMATS)} (default: "
        "%(default)s, i.e. all)",
    )
    p.add_argument(
        "--convention",
        default=CONVENTIONS[0],
        choices=CONVENTIONS,
        help="of the SVG cut sheet: rigidfold's (layers, labels, legend, scale bar) or "
        "origami-simulator (red/blue/black lines, fold angle as stroke opacity, opens in "
        "Origami Simulator) (default: %(default)s)",
    )


def _structure(p: Parser) -> None:
    _file(p)
    structure_arguments(p, generate=False)


def _fabricate(p: Parser) -> None:
    _file(p)
    fabricate_arguments(p, generate=False)


def _deploy(p: Parser) -> None:
    _file(p)
    add_options(p, DriveOptions)


def _study(p: Parser) -> None:
    plan = STUDY_DEFAULTS
    p.add_argument(
        "--patterns",
        default=",".join(plan.patterns),
        help="comma-separated crease pattern specs, each with its defaults (the paper's names, "
        "grid:NXxNY, mesh:FILE, FILE.fold, FILE.svg; default: %(default)s)",
    )
    p.add_argument(
        "--criteria",
        default=",".join(plan.criteria),
        help=f"comma-separated selection criteria, any of {', '.join(CRITERIA)} (see generate "
        "--criterion; default: %(default)s)",
    )
    p.add_argument(
        "--surfaces",
        type=int,
        default=plan.surfaces,
        help="number of random Bezier target surfaces, seeds --first-seed, --first-seed + 1, "
        "... (default: %(default)s)",
    )
    p.add_argument(
        "--first-seed",
        type=argument_type(seed),
        default=plan.first_seed,
        help="seed of the first Bezier surface, 0 to 2**63 - 1 (default: %(default)s)",
    )
    p.add_argument(
        "--preset", help="dome, hp or dome,hp: Sections 6.5-6.6 instead of Bezier surfaces"
    )
    p.add_argument("--db", required=True, metavar="DB", help="SQLite file (created if absent)")
    p.either(
        (
            ("--workers",),
            {
                "type": int,
                "default": plan.workers,
                "help": "local worker "
                "processes, each running one generate at a time (default: %(default)s)",
            },
        ),
        (
            ("--scheduler",),
            {
                "metavar": "ADDRESS",
                "help": "address of an existing Dask "
                "scheduler (e.g. tcp://host:8786), instead of local workers",
            },
        ),
    )
    p.add_argument(
        "--connect-timeout",
        type=float,
        default=plan.connect_timeout,
        metavar="S",
        help="seconds that --scheduler has to answer (default: %(default)s)",
    )
    p.add_argument(
        "--allow-mixed-numerics",
        action="store_true",
        help="add runs to a database whose runs were computed with other numerics (another "
        "machine's BLAS, SIMD or libm, or other library versions), and accept Dask workers "
        "that compute with other numerics than this process",
    )
    # the study's options, but Step 9 runs unless --no-deform, as in generate
    runs = STUDY_OPTIONS.replace(deform=True)
    add_options(p, GenerateOptions, defaults=runs, only=("deform", "lookahead", "deploy_check"))
    add_options(
        p, SettingsOptions, only=("backtrack", "fold_limit", "reseeds", "hessian", "svg_tolerance")
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _study_report(p: Parser) -> None:
    p.add_argument("db", metavar="DB", nargs="+", help="one or more study databases")
    p.add_argument(
        "--out",
        type=directory,
        metavar="DIR",
        help="also write DIR/results.md and PNG box plots (the tables are printed either way)",
    )


_ARGUMENTS: dict[str, Callable[[Parser], None]] = {
    "generate": _generate,
    "report": _report,
    "analyze": lambda p: _file(p, out=False),
    "develop": _file,
    "deform": _deform,
    "export": _export,
    "structure": _structure,
    "fabricate": _fabricate,
    "deploy": _deploy,
    "study": _study,
    "study-report": _study_report,
    "optimize": _optimize,
}


def add_arguments(command: str, parser: Parser) -> None:
    """The arguments of ``command`` on its ``parser``."""
    _ARGUMENTS[command](parser)
    if command in OVERWRITE_HELP:
        parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP[command])
