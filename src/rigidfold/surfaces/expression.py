"""A user's target surface ``z = f(x, y)`` given as text, parsed safely.

The text is parsed with :mod:`ast` and checked against a whitelist *before* anything is
evaluated: numbers, ``x``, ``y``, ``pi``, ``e``, ``+ - * / **``, unary signs, parentheses and
calls of whitelisted maths functions by plain name with positional arguments. The checked tree
is then evaluated by a small interpreter of our own on NumPy arrays or CasADi symbols; user
text never reaches ``eval`` or ``compile``.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from types import ModuleType
from typing import Any, Literal

import casadi as ca
import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.surfaces.builtin import MirrorPlane, Surface

# function name -> (number of arguments, NumPy implementation, CasADi implementation)
FUNCTIONS: dict[str, tuple[int, Callable[..., Any], Callable[..., Any]]] = {
    "sin": (1, np.sin, ca.sin),
    "cos": (1, np.cos, ca.cos),
    "tan": (1, np.tan, ca.tan),
    "asin": (1, np.arcsin, ca.asin),
    "acos": (1, np.arccos, ca.acos),
    "atan": (1, np.arctan, ca.atan),
    "arcsin": (1, np.arcsin, ca.asin),
    "arccos": (1, np.arccos, ca.acos),
    "arctan": (1, np.arctan, ca.atan),
    "atan2": (2, np.arctan2, ca.atan2),
    "sinh": (1, np.sinh, ca.sinh),
    "cosh": (1, np.cosh, ca.cosh),
    "tanh": (1, np.tanh, ca.tanh),
    "exp": (1, np.exp, ca.exp),
    "log": (1, np.log, ca.log),
    "log10": (1, np.log10, ca.log10),
    "sqrt": (1, np.sqrt, ca.sqrt),
    "abs": (1, np.abs, ca.fabs),
    "hypot": (2, np.hypot, ca.hypot),
    "min": (2, np.minimum, ca.fmin),
    "max": (2, np.maximum, ca.fmax),
}
CONSTANTS = {"pi": math.pi, "e": math.e}
VARIABLES = ("x", "y")
MAX_LENGTH = 1000  # characters of text
MAX_DEPTH = 100  # nesting depth of the syntax tree

_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.UAdd: operator.pos,
    ast.USub: operator.neg,
}
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


def parse_expression(text: str) -> ast.Expression:
    """Parse and check ``text``; raise a one-line ValueError for anything not allowed."""
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
    return tree


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
        return None if type(node.op) in _BINARY else "only + - * / ** are allowed"
    if isinstance(node, ast.UnaryOp):
        return None if type(node.op) in _UNARY else "only unary + and - are allowed"
    if isinstance(node, tuple(_BINARY) + tuple(_UNARY)):
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


def evaluate(tree: ast.Expression, x: Any, y: Any, xp: ModuleType = np) -> Any:
    """Evaluate a checked tree on NumPy arrays (xp=numpy) or CasADi symbols (xp=casadi)."""
    column: Literal[1, 2]
    number: Callable[[Any], Any]
    if xp is np:
        column, number = 1, np.float64  # NumPy scalars: 1/0 gives inf, not an exception
    elif xp is ca:
        column, number = 2, ca.DM
    else:
        raise TypeError(f"unknown backend {getattr(xp, '__name__', xp)!r} (numpy or casadi)")
    names = {"x": x, "y": y, **{k: number(v) for k, v in CONSTANTS.items()}}

    def ev(node: ast.AST) -> Any:
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant):
            assert isinstance(node.value, (int, float))  # parse_expression admits only these
            return number(node.value)
        if isinstance(node, ast.Name):
            return names[node.id]
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](ev(node.operand))
        if isinstance(node, ast.Call):
            assert isinstance(node.func, ast.Name)  # parse_expression admits no other call
            return FUNCTIONS[node.func.id][column](*(ev(a) for a in node.args))
        raise RigidfoldError(
            f"unchecked node {type(node).__name__}"
        )  # parse_expression excludes it

    return ev(tree)


class ExpressionSurface(Surface):
    """z = f(x, y) from user text; exact gradient by CasADi's automatic differentiation.

    text : e.g. ``"0.3*sin(x)*cos(y) + 0.1*x**2"`` (see :data:`FUNCTIONS`, :data:`CONSTANTS`).
    mirror_planes : the surface's mirror planes, if the user knows any (none are derived).
    """

    name = "expr"

    def __init__(self, text: str, mirror_planes: tuple[MirrorPlane, ...] = ()) -> None:
        self._tree = parse_expression(text)
        self.text = " ".join(text.split())
        self.mirror_planes = tuple(mirror_planes)
        sx, sy = ca.SX.sym("x"), ca.SX.sym("y")
        z = evaluate(self._tree, sx, sy, xp=ca) + 0 * sx
        self._gradient = ca.Function("grad", [sx, sy], [ca.gradient(z, sx), ca.gradient(z, sy)])

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        """z at plan points; NumPy x, y broadcast together, z has their shape."""
        if xp is not np:
            return evaluate(self._tree, x, y, xp=xp) + 0 * x
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        with np.errstate(all="ignore"):  # non-finite values are reported by check_finite
            z = evaluate(self._tree, x, y)
        return np.broadcast_to(np.asarray(z, dtype=float), x.shape).copy()

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """(dz/dx, dz/dy) at plan points, each of the broadcast shape of x and y."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        if x.size == 0:
            return np.zeros(x.shape), np.zeros(x.shape)
        # a 1 x n row evaluates the scalar function at n points
        gx, gy = self._gradient(x.reshape(1, -1), y.reshape(1, -1))
        return np.asarray(gx).reshape(x.shape), np.asarray(gy).reshape(x.shape)

    def check_finite(self, x: Any, y: Any) -> None:
        """Raise ValueError if z is not finite at some plan point; x, y (N,)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        bad = np.flatnonzero(~np.isfinite(self.height(x, y)))
        if bad.size:
            px, py = x.ravel()[bad[0]], y.ravel()[bad[0]]
            raise RigidfoldError(
                f"expression {self.text!r} is not finite at (x, y) = ({px:g}, {py:g})"
            )

    def metadata(self) -> dict[str, Any]:
        return {"name": self.name, "expression": self.text}

    def __repr__(self) -> str:
        return f"ExpressionSurface({self.text!r})"
