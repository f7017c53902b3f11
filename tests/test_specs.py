"""The texts that name a case (``--pattern``, ``--size``, ``--surface``, ``--expr``) are read
in one module, :mod:`rigidfold.generate.specs`, into typed specs; the library below takes
only the typed values (issue 46, item 2)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from rigidfold import patterns, surfaces
from rigidfold.generate.case import make_case
from rigidfold.generate.specs import (
    case_from_specs,
    parse_expression,
    parse_pattern,
    parse_pattern_spec,
    parse_size,
    parse_surface_spec,
)
from rigidfold.patterns import FilePattern, GridPattern, MeshPattern, PaperPattern, make_plan
from rigidfold.surfaces import (
    Dome,
    Expression,
    ExpressionSurface,
    SurfaceKind,
    SurfaceSpec,
    surface_of,
)

SRC = Path(__file__).resolve().parents[1] / "src" / "rigidfold"
SPECS = SRC / "generate" / "specs.py"


# ------------------------------------------------------------------------------ patterns
@pytest.mark.parametrize(
    ("text", "spec"),
    [
        ("1", PaperPattern("1")),
        ("1p", PaperPattern("1p")),
        ("11", PaperPattern("11")),
        ("grid:15x9", GridPattern(15, 9)),
        ("mesh:0,0;12,0;12,8;0,8", MeshPattern(outline=[[0, 0], [12, 0], [12, 8], [0, 8]])),
        ("mesh:0.5,0;1e3,0;1e3,2.25", MeshPattern(outline=[[0.5, 0], [1000, 0], [1000, 2.25]])),
        ("mesh:roof.txt", MeshPattern(file=Path("roof.txt"))),
        ("cp.fold", FilePattern(Path("cp.fold"))),
        ("drawings/cp.SVG", FilePattern(Path("drawings/cp.SVG"))),
    ],
)
def test_each_pattern_form_reads_into_its_spec_and_back(text, spec):
    read = parse_pattern_spec(text)
    assert read == spec and type(read) is type(spec)
    assert read.text == text == str(read)
    assert parse_pattern_spec(read.text) == read and parse_pattern_spec(read.text).text == text
    # a spec made in code has a text that reads back as the same spec
    again = parse_pattern_spec(spec.text)
    assert again == spec and again.text == spec.text


def test_pattern_specs_keep_the_text_as_given():
    """The text recorded (summary.json's ``case.pattern``, ``Plan.spec``) is the user's,
    stripped; the typed values compare equal whatever the spelling."""
    spec = parse_pattern_spec("  GRID: 4 x 5 ")
    assert spec == GridPattern(4, 5) and spec.text == "GRID: 4 x 5"
    assert parse_pattern("grid:4x5").metadata()["pattern"] == "grid:4x5"
    assert GridPattern(4, 5).text == "grid:4x5"
    assert MeshPattern(outline=np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 1.5]])).text == (
        "mesh:0,0;3,0;0,1.5"
    )
    assert MeshPattern(file=Path("a.txt")) != MeshPattern(outline=[[0, 0], [1, 0], [0, 1]])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("7", "unknown pattern '7' (choose from 1, 1p, 2, 11, grid:NXxNY"),
        ("grid:7", "a grid pattern is grid:NXxNY (vertex counts, e.g. grid:15x9), got 'grid:7'"),
        ("mesh:", "mesh footprint '' is neither 'x1,y1;x2,y2;...' nor an existing file"),
        ("mesh:0,0;1,x", "footprint: point 2 is not an 'x,y' pair of numbers: '1,x'"),
    ],
)
def test_bad_pattern_texts_are_one_line(text, message):
    with pytest.raises(ValueError) as info:
        parse_pattern_spec(text)
    assert message in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("text", "size"), [("3x3", (3.0, 3.0)), ("12X8", (12.0, 8.0)), (" 1x2.5 ", (1.0, 2.5))]
)
def test_sizes(text, size):
    assert parse_size(text) == size
    assert parse_size(size) == size and parse_size(None) == patterns.DEFAULT_SIZE


@pytest.mark.parametrize("text", ["12", "0x3", "-2x3", "nanx3", "3xinf", "12by8", "1x2x3"])
def test_bad_sizes(text):
    with pytest.raises(
        ValueError, match=f"a pattern size is WxH in metres with W, H > 0 .*got {text!r}"
    ):
        parse_size(text)


def test_typed_plan_is_the_plan_of_the_text():
    typed = make_plan(GridPattern(9, 7), size=(6.0, 4.0), diagonals="parallel")
    read = parse_pattern("grid:9x7", size="6x4", diagonals="parallel")
    assert np.array_equal(typed.xy, read.xy) and np.array_equal(typed.faces, read.faces)
    assert typed.metadata() == read.metadata()
    with pytest.raises(ValueError, match="pattern 'grid:9x7' takes no edge length"):
        make_plan(GridPattern(9, 7), edge_length=1.0)
    with pytest.raises(ValueError, match=r"got \(0.0, 4.0\)"):
        make_plan(GridPattern(9, 7), size=(0.0, 4.0))


# ------------------------------------------------------------------------------ surfaces
@pytest.mark.parametrize(
    ("text", "options", "kind"),
    [
        ("bezier", {"seed": 7}, SurfaceKind.BEZIER),
        ("dome", {"seed": 7}, SurfaceKind.DOME),  # the seed is the run's too: not refused
        ("hp", {}, SurfaceKind.HP),
        ("expr", {"expr": " 0.3*sin(x)*  cos(y) "}, SurfaceKind.EXPR),
        ("mesh:roof.obj", {}, SurfaceKind.MESH),
        ("fold:shape.fold", {}, SurfaceKind.FOLD),
    ],
)
def test_each_surface_form_reads_into_its_spec_and_back(text, options, kind):
    spec = parse_surface_spec(text, **options)
    assert spec.kind is kind and spec.text == text == str(spec)
    expr = None if spec.expression is None else spec.expression.text
    assert parse_surface_spec(spec.text, seed=spec.seed, expr=expr) == spec
    assert spec.seed == (7 if kind is SurfaceKind.BEZIER else None)
    if kind is SurfaceKind.EXPR:
        assert spec.expression == parse_expression("0.3*sin(x)* cos(y)")
        assert spec.expression.text == "0.3*sin(x)* cos(y)"
    assert (spec.path is None) == (kind not in (SurfaceKind.MESH, SurfaceKind.FOLD))


def test_surface_spec_defaults_and_errors():
    assert parse_surface_spec("bezier").seed == 0 == SurfaceSpec(SurfaceKind.BEZIER).seed
    with pytest.raises(ValueError, match=r"unknown surface 'cone' \(choose from bezier, dome"):
        parse_surface_spec("cone")
    with pytest.raises(ValueError, match="unknown surface 'mesh:'"):
        parse_surface_spec("mesh:")
    with pytest.raises(ValueError, match="surface 'expr' needs an expression"):
        parse_surface_spec("expr")
    with pytest.raises(ValueError, match="refused expression"):
        parse_surface_spec("expr", expr="__import__('os')")
    with pytest.raises(ValueError, match="non-negative integer"):
        surface_of(parse_surface_spec("bezier", seed=-1))
    with pytest.raises(TypeError, match="takes no seed"):
        SurfaceSpec(SurfaceKind.DOME, seed=3)


# ------------------------------------------------------------------------------ typed API
def test_the_typed_api_makes_the_case_the_texts_make():
    typed = make_case(
        SurfaceSpec(SurfaceKind.DOME), GridPattern(5, 4), size=(4.0, 3.0), symmetric=True
    )
    read = case_from_specs("dome", "grid:5x4", size="4x3", symmetric=True)
    assert typed.metadata() == read.metadata()
    assert np.array_equal(typed.pattern.coords, read.pattern.coords)
    expr = make_case(
        SurfaceSpec(SurfaceKind.EXPR, expression=parse_expression("x*y/9")), PaperPattern("1")
    )
    assert expr.metadata() == case_from_specs("expr", "1", expr="x*y/9").metadata()
    plan = parse_pattern("11")
    assert make_case(Dome(), plan).plan is plan


@pytest.mark.parametrize(
    "call",
    [
        lambda: make_case("dome", "1"),
        lambda: make_case(SurfaceSpec(SurfaceKind.DOME), "1"),
        lambda: make_case(SurfaceSpec(SurfaceKind.DOME), parse_pattern("1"), size=(3.0, 3.0)),
        lambda: make_plan("grid:3x3"),
        lambda: patterns.build("11", Dome()),
        lambda: surface_of("dome"),
        lambda: SurfaceSpec("dome"),
        lambda: SurfaceSpec(SurfaceKind.EXPR),
        lambda: SurfaceSpec(SurfaceKind.MESH, path="roof.obj"),
        lambda: ExpressionSurface("x*y"),
        lambda: GridPattern("3", 3),
        lambda: MeshPattern(outline="0,0;1,0;0,1"),
        lambda: FilePattern("cp.fold"),
        lambda: Expression("x", "x"),
    ],
)
def test_the_typed_api_refuses_text(call):
    """Text given where a typed value belongs is a caller's slip (TypeError), never parsed."""
    with pytest.raises(TypeError):
        call()


def test_parsers_are_not_public_below_the_specs_module():
    for name in ("parse_pattern", "parse_size", "is_pattern_file"):
        assert not hasattr(patterns, name) and name not in patterns.__all__
    for name in ("get_surface", "parse_expression"):
        assert not hasattr(surfaces, name) and name not in surfaces.__all__


# ------------------------------------------------------------------------------ one reader
def _modules():
    for path in sorted(SRC.rglob("*.py")):
        if "__pycache__" not in path.parts:
            yield path, ast.parse(path.read_text())


def _in_cli(path: Path) -> bool:
    return path.relative_to(SRC).parts[0] == "cli"


PARSERS = {
    "parse_pattern",
    "parse_pattern_spec",
    "parse_size",
    "parse_surface_spec",
    "parse_expression",
    "get_surface",
    "is_pattern_file",
}
SPEC_PACKAGES = ("patterns", "surfaces", "generate", "study", "pipeline", "rundir", "reporting")


def test_no_module_but_the_specs_module_and_the_command_line_parses_the_specs():
    """The spec parsers are defined in generate/specs.py alone; nothing else calls
    ``ast.parse`` (the expression's reader) or splits a ``kind:value`` text in the packages
    that handle the case's specs."""
    defined, parsed, split = [], [], []
    for path, tree in _modules():
        if path == SPECS or _in_cli(path):
            continue
        name = str(path.relative_to(SRC))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef) and node.name in PARSERS:
                defined.append(f"{name}: {node.name}")
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
                func = node.func
                if func.attr == "parse" and getattr(func.value, "id", None) == "ast":
                    parsed.append(name)
                colon = [a for a in node.args if isinstance(a, ast.Constant) and a.value == ":"]
                if func.attr == "partition" and colon and name.split("/")[0] in SPEC_PACKAGES:
                    split.append(name)
    assert not defined, defined
    assert not parsed, parsed
    assert not split, split


READERS = {
    "generate/case_options.py",  # the command line's case options, read (CaseOptions.make)
    "study/runner.py",  # the study's stored keys, read into cases
    "rundir/reader.py",  # summary.json's stored expression, read to draw the target
}


def test_only_the_command_line_and_the_stored_specs_call_the_specs_module():
    callers = set()
    for path, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "rigidfold.generate.specs":
                callers.add(str(path.relative_to(SRC)))
    assert {c for c in callers if not c.startswith("cli/")} <= READERS, callers
