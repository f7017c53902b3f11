"""The texts that name a case, read into typed specs: the one place that parses them.

A crease pattern (``1``, ``1p``, ``2``, ``11``, ``grid:NXxNY``, ``mesh:POLYGON`` or
``mesh:FILE``, ``FILE.fold``, ``FILE.svg``: :func:`parse_pattern_spec`, a
:data:`rigidfold.patterns.PatternSpec`), a plan size ``WxH`` (:func:`parse_size`, metres), a
target surface (``bezier``, ``dome``, ``hp``, ``expr``, ``mesh:FILE``, ``fold:FILE``:
:func:`parse_surface_spec`, a :class:`rigidfold.surfaces.SurfaceSpec`) and a surface's
formula z = f(x, y) (:func:`parse_expression`, a checked
:class:`rigidfold.surfaces.Expression`). The command line and the study (its stored keys)
call these; the library below takes the typed values (:func:`rigidfold.patterns.make_plan`,
:func:`rigidfold.surfaces.surface_of`, :func:`rigidfold.generate.case.make_case`).
:func:`parse_pattern` and :func:`case_from_specs` read and make in one call, in the order the
command line checks its options. Each refuses what it cannot read with a RigidfoldError, one
line naming what was received; each spec's ``text`` reads back as the same spec.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Unpack

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.generate.case import Case, make_case
from rigidfold.patterns import (
    DEFAULT_SIZE,
    FILE_FORMATS,
    FORMS,
    PATTERNS,
    FilePattern,
    GridPattern,
    MeshPattern,
    PaperPattern,
    PatternSpec,
    Plan,
    PlanKeywords,
    check_size,
    footprint_points,
    given_options,
    make_plan,
    refuse_options,
)
from rigidfold.surfaces import SURFACE_FORMS, Expression, Surface, SurfaceKind, SurfaceSpec
from rigidfold.surfaces.expression import (
    BINARY,
    CONSTANTS,
    FUNCTIONS,
    MAX_DEPTH,
    MAX_LENGTH,
    UNARY,
    VARIABLES,
)

_COUNTS = re.compile(r"\s*(\d+)\s*[xX]\s*(\d+)\s*")


# ------------------------------------------------------------------------------ patterns
def is_pattern_file(spec: str) -> bool:
    """True when a pattern spec names a file by one of the suffixes of
    :data:`rigidfold.patterns.FILE_FORMATS`."""
    return Path(spec.strip()).suffix.lower() in FILE_FORMATS


def _pattern_type(text: str, spec: object) -> type[PatternSpec]:
    """The spec type of the stripped pattern text ``text`` (``spec`` as given, for the
    message); an unknown form is refused."""
    kind, colon, _ = text.partition(":")
    kind = kind.strip().lower()
    if not colon and text in PATTERNS:
        return PaperPattern
    if colon and kind == "grid":
        return GridPattern
    if colon and kind == "mesh":
        return MeshPattern
    if is_pattern_file(text):
        return FilePattern
    raise RigidfoldError(f"unknown pattern {spec!r} (choose from {FORMS})")


def parse_pattern_spec(spec: str) -> PatternSpec:
    """The typed spec of a pattern's text: one of the paper's names (``1``, ``1p``, ``2``,
    ``11``); ``grid:NXxNY``, vertex counts; ``mesh:POLYGON``, a polygon ``x1,y1;x2,y2;...``
    in metres, or ``mesh:FILE``, a file of ``x,y`` lines (read when the plan is made);
    ``FILE.fold`` or ``FILE.svg``. The spec's ``text`` is ``spec`` stripped. A one-line
    RigidfoldError naming what was received if it cannot be read."""
    text = str(spec).strip()
    kind = _pattern_type(text, spec)
    rest = text.partition(":")[2]
    if kind is PaperPattern:
        return PaperPattern(text)
    if kind is GridPattern:
        counts = _COUNTS.fullmatch(rest)
        if counts is None:
            raise RigidfoldError(
                f"a grid pattern is grid:NXxNY (vertex counts, e.g. grid:15x9), got {text!r}"
            )
        return GridPattern(int(counts[1]), int(counts[2]), text=text)
    if kind is MeshPattern:
        rest = rest.strip()
        if ";" in rest:
            outline = footprint_points(rest.split(";"), "footprint: point")
            return MeshPattern(outline=outline, text=text)
        if not rest:
            raise RigidfoldError(
                f"mesh footprint {rest!r} is neither 'x1,y1;x2,y2;...' nor an existing file"
            )
        return MeshPattern(file=Path(rest), text=text)
    return FilePattern(Path(text), text=text)


def parse_pattern(
    spec: str,
    *,
    size: str | tuple[float, float] | None = None,
    settings: Settings = DEFAULTS,
    **options: Unpack[PlanKeywords],
) -> Plan:
    """The plan of a pattern's text (:func:`parse_pattern_spec`, then
    :func:`rigidfold.patterns.make_plan` with these options); a one-line RigidfoldError
    naming what was received if bad. The options a form does not take are refused before
    its text is read (:func:`rigidfold.patterns.refuse_options`).

    size : "WxH" or (W, H) in metres (:func:`parse_size`), of a ``grid:`` pattern (default
        3 x 3), or the box a file drawn without units is fitted into (default 3 x 3);
    the other options : as :func:`rigidfold.patterns.make_plan` takes them.
    """
    text = str(spec).strip()
    refuse_options(text, _pattern_type(text, spec), given_options(size, options))
    return make_plan(
        parse_pattern_spec(spec),
        size=None if size is None else parse_size(size),
        settings=settings,
        **options,
    )


def parse_size(size: str | tuple[float, float] | None) -> tuple[float, float]:
    """(W, H) in metres from "WxH" (e.g. "12x8") or a pair; None gives
    :data:`rigidfold.patterns.DEFAULT_SIZE`."""
    if size is None:
        return DEFAULT_SIZE
    if not isinstance(size, str):
        return check_size(size)
    try:
        pair = tuple(float(t) for t in re.split(r"[xX]", size.strip()))
    except ValueError:
        pair = ()
    return check_size(pair, size)


# ------------------------------------------------------------------------------ surfaces
def parse_surface_spec(
    name: str, *, seed: int | None = None, expr: str | None = None
) -> SurfaceSpec:
    """The typed spec of a target surface's text: ``bezier`` (of ``seed``, default
    :data:`rigidfold.config.DEFAULT_SEED`), ``dome``, ``hp``, ``expr`` (z = f(x, y) of the
    text ``expr``, :func:`parse_expression`), ``mesh:FILE`` (an OBJ, STL, PLY or OFF mesh) or
    ``fold:FILE`` (the 3D shape of a FOLD file). ``seed`` and ``expr`` are ignored by the
    surfaces that do not take them. A one-line RigidfoldError naming what was received if
    it cannot be read."""
    kind, colon, path = str(name).partition(":")
    if kind.strip().lower() == SurfaceKind.FOLD.value:
        return SurfaceSpec(SurfaceKind.FOLD, path=Path(path.strip()))
    if name == SurfaceKind.BEZIER.value:
        return SurfaceSpec(SurfaceKind.BEZIER, seed=seed)
    if name in (SurfaceKind.DOME.value, SurfaceKind.HP.value):
        return SurfaceSpec(SurfaceKind(name))
    if name == SurfaceKind.EXPR.value:
        if expr is None:
            raise RigidfoldError("surface 'expr' needs an expression z = f(x, y)")
        return SurfaceSpec(SurfaceKind.EXPR, expression=parse_expression(expr))
    if colon and kind.strip().lower() == SurfaceKind.MESH.value and path.strip():
        return SurfaceSpec(SurfaceKind.MESH, path=Path(path.strip()))
    raise RigidfoldError(f"unknown surface {name!r} (choose from {SURFACE_FORMS})")


def parse_expression(text: str) -> Expression:
    """The checked expression of ``text``, z = f(x, y) (the whitelist:
    :mod:`rigidfold.surfaces.expression`); a one-line RigidfoldError for anything not
    allowed, before anything is evaluated."""
    if not isinstance(text, str):
        raise TypeError(f"an expression must be text, got {type(text).__name__}")
    if not text.strip():
        raise RigidfoldError("empty expression: give z = f(x, y), e.g. '0.3*sin(x)*cos(y)'")
    shown = " ".join(text.split())
    if len(shown) > 60:
        shown = shown[:57] + "..."
    if len(text) > MAX_LENGTH:
        raise RigidfoldError(f"refused expression {shown!r}: longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        reason = " ".join(str(getattr(exc, "msg", exc) or "nested too deeply").split())
        raise RigidfoldError(f"invalid expression {shown!r}: {reason}") from None
    if _depth(tree) > MAX_DEPTH:
        raise RigidfoldError(f"refused expression {shown!r}: nested deeper than {MAX_DEPTH} levels")
    called = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
    for node in ast.walk(tree):
        if id(node) in called and isinstance(node, ast.Name):
            continue  # a function name, checked with its call
        problem = _check(node)
        if problem:
            raise RigidfoldError(f"refused expression {shown!r}: {problem}")
    return Expression(" ".join(text.split()), tree)


_REFUSED = {  # node type -> what the error message calls it
    ast.Attribute: "attribute access",
    ast.Subscript: "subscripting",
    ast.Lambda: "a lambda",
    ast.Compare: "a comparison",
    ast.BoolOp: "a boolean operator",
    ast.IfExp: "a conditional expression",
    ast.NamedExpr: "an assignment expression",
    ast.JoinedStr: "an f-string",
    ast.Starred: "a starred argument",
    ast.List: "a list",
    ast.Tuple: "a tuple",
    ast.Dict: "a dict",
    ast.Set: "a set",
    ast.ListComp: "a comprehension",
    ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension",
    ast.GeneratorExp: "a comprehension",
}


def _depth(tree: ast.AST) -> int:
    """Nesting depth of a syntax tree, found without recursion."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _check(node: ast.AST) -> str | None:
    """Why ``node`` is not allowed, or None."""
    if isinstance(node, (ast.Expression, ast.Load)):
        return None
    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"constant {value!r} is not allowed (only real numbers)"
        try:
            float(value)
        except OverflowError:
            return "a number is too large"
        return None
    if isinstance(node, ast.Name):
        if node.id in VARIABLES or node.id in CONSTANTS:
            return None
        if node.id in FUNCTIONS:
            return f"function '{node.id}' must be called"
        return f"name '{node.id}' is not allowed (use x, y, pi, e)"
    if isinstance(node, ast.BinOp):
        return None if type(node.op) in BINARY else "only + - * / ** are allowed"
    if isinstance(node, ast.UnaryOp):
        return None if type(node.op) in UNARY else "only unary + and - are allowed"
    if isinstance(node, tuple(BINARY) + tuple(UNARY)):
        return None
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name):
            return _check(node.func) or "only maths functions may be called, by plain name"
        name = node.func.id
        if name not in FUNCTIONS:
            return f"function '{name}' is not allowed (allowed: {', '.join(FUNCTIONS)})"
        if node.keywords:
            return f"keyword arguments are not allowed in {name}()"
        if any(isinstance(a, ast.Starred) for a in node.args):
            return f"starred arguments are not allowed in {name}()"
        nargs = FUNCTIONS[name][0]
        if len(node.args) != nargs:
            return f"{name}() takes {nargs} argument{'s' if nargs > 1 else ''}"
        return None
    return f"{_REFUSED.get(type(node), type(node).__name__ + ' syntax')} is not allowed"


# ------------------------------------------------------------------------------ cases
def case_from_specs(
    surface: str | Surface,
    pattern: str,
    *,
    seed: int | None = None,
    expr: str | None = None,
    symmetric: bool = False,
    size: str | tuple[float, float] | None = None,
    settings: Settings = DEFAULTS,
    **options: Unpack[PlanKeywords],
) -> Case:
    """The case of the texts the command line takes (:func:`rigidfold.generate.case.make_case`
    of the pattern's plan, :func:`parse_pattern`, and the surface's spec,
    :func:`parse_surface_spec`, read in this order), e.g.
    ``case_from_specs("bezier", "1", seed=1)`` or ``case_from_specs("dome", "grid:9x7",
    size="6x4")``.

    surface : a surface's text or a Surface (used as it is); pattern : a pattern's text;
    seed, expr : of a ``bezier`` and an ``expr`` surface; up : the up axis (``"z"`` or
    ``"y"``) of a FOLD pattern and of a mesh or FOLD surface; symmetric : the surface's own
    mirror planes (9) imposed; the other options : :func:`parse_pattern`'s.
    """
    plan = parse_pattern(pattern, size=size, settings=settings, **options)
    spec = (
        surface
        if isinstance(surface, Surface)
        else parse_surface_spec(surface, seed=seed, expr=expr)
    )
    up = options.get("up", "z")
    return make_case(spec, plan, symmetric=symmetric, up=up, settings=settings)
