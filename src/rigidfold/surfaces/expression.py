"""A user's target surface ``z = f(x, y)`` given as text, parsed safely.

The text is parsed with :mod:`ast` and checked against a whitelist *before* anything is
evaluated: numbers, ``x``, ``y``, ``pi``, ``e``, ``+ - * / **``, unary signs, parentheses and
calls of whitelisted maths functions by plain name. The checked tree is then evaluated by a
small interpreter of our own on NumPy arrays or CasADi symbols; user text never reaches
``eval`` or ``compile``.
"""

from __future__ import annotations

import ast
import math
import operator

import casadi as ca
import numpy as np

from rigidfold.surfaces.builtin import MirrorPlane, Surface

# function name -> (number of arguments, NumPy implementation, CasADi implementation)
FUNCTIONS = {
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
    "sqrt": (1, np.sqrt, ca.sqrt),
    "abs": (1, np.abs, ca.fabs),
    "hypot": (2, np.hypot, lambda a, b: ca.sqrt(a * a + b * b)),
    "min": (2, np.minimum, ca.fmin),
    "max": (2, np.maximum, ca.fmax),
}
CONSTANTS = {"pi": math.pi, "e": math.e}
VARIABLES = ("x", "y")
_BINARY = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
_UNARY = {ast.UAdd: operator.pos, ast.USub: operator.neg}
_WHAT = {
    ast.Attribute: "attribute access",
    ast.Subscript: "subscripts",
    ast.Lambda: "lambdas",
    ast.Compare: "comparisons",
    ast.BoolOp: "boolean operators",
    ast.IfExp: "conditional expressions",
    ast.NamedExpr: "assignment expressions",
    ast.JoinedStr: "f-strings",
    ast.Starred: "starred arguments",
    ast.List: "lists",
    ast.Tuple: "tuples",
    ast.Dict: "dicts",
    ast.Set: "sets",
    ast.ListComp: "comprehensions",
    ast.GeneratorExp: "comprehensions",
    ast.DictComp: "comprehensions",
    ast.SetComp: "comprehensions",
}


def parse_expression(text: str) -> ast.Expression:
    """Parse and check ``text``; raise a one-line ValueError for anything not allowed."""
    if not isinstance(text, str) or not text.strip():
        raise ValueError("empty expression: give z = f(x, y), e.g. '0.3*sin(x)*cos(y)'")
    shown = " ".join(text.split())
    if len(shown) > 60:
        shown = shown[:57] + "..."
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"invalid expression {shown!r}: {exc.msg}") from None
    called = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
    for node in ast.walk(tree):
        if id(node) in called and isinstance(node, ast.Name):
            continue  # a function name, checked with its call
        problem = _check(node)
        if problem:
            raise ValueError(f"refused expression {shown!r}: {problem}")
    return tree


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
    if isinstance(node, tuple(_BINARY)) or isinstance(node, tuple(_UNARY)):
        return None
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name):
            return "only plain calls of maths functions are allowed"
        name = node.func.id
        if name not in FUNCTIONS:
            return f"function '{name}' is not allowed (allowed: {', '.join(FUNCTIONS)})"
        if node.keywords:
            return f"keyword arguments are not allowed in {name}()"
        nargs = FUNCTIONS[name][0]
        if len(node.args) != nargs or any(isinstance(a, ast.Starred) for a in node.args):
            return f"{name}() takes {nargs} argument{'s' if nargs > 1 else ''}"
        return None
    return f"not allowed: {_WHAT.get(type(node), type(node).__name__)}"


def evaluate(tree: ast.Expression, x, y, xp=np):
    """Evaluate a checked tree on NumPy arrays (xp=numpy) or CasADi symbols (xp=casadi)."""
    backend = 1 if xp is np else 2
    number = np.float64 if xp is np else ca.DM  # 1/0 -> inf, not an exception
    names = {"x": x, "y": y, **{k: number(v) for k, v in CONSTANTS.items()}}

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant):
            return number(node.value)
        if isinstance(node, ast.Name):
            return names[node.id]
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](ev(node.operand))
        if isinstance(node, ast.Call):
            return FUNCTIONS[node.func.id][backend](*(ev(a) for a in node.args))
        raise ValueError(f"unexpected node {type(node).__name__}")  # excluded by parse_expression

    return ev(tree)


class ExpressionSurface(Surface):
    """z = f(x, y) from user text; exact gradient by CasADi's automatic differentiation."""

    name = "expr"

    def __init__(self, text: str, mirror_planes: tuple[MirrorPlane, ...] = ()) -> None:
        self.text = " ".join(str(text).split())
        self._tree = parse_expression(text)
        self.mirror_planes = tuple(mirror_planes)
        sx, sy = ca.SX.sym("x"), ca.SX.sym("y")
        z = evaluate(self._tree, sx, sy, xp=ca) + 0 * sx
        self._gradient = ca.Function("grad", [sx, sy], [ca.gradient(z, sx), ca.gradient(z, sy)])

    def height(self, x, y, xp=np):
        if xp is np:
            with np.errstate(all="ignore"):
                z = evaluate(self._tree, np.asarray(x, dtype=float), np.asarray(y, dtype=float))
                return np.broadcast_to(np.asarray(z, dtype=float), np.shape(x)).copy()
        return evaluate(self._tree, x, y, xp=xp) + 0 * x

    def gradient(self, x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        gx, gy = self._gradient(x.ravel(), y.ravel())
        return np.asarray(gx).reshape(x.shape), np.asarray(gy).reshape(x.shape)

    def check_finite(self, x, y) -> None:
        """Raise ValueError where the expression is not finite at plan points x, y (N,)."""
        z = self.height(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        bad = ~np.isfinite(z)
        if bad.any():
            k = int(np.flatnonzero(bad.ravel())[0])
            px, py = np.ravel(x)[k], np.ravel(y)[k]
            raise ValueError(f"expression {self.text!r} is not finite at (x, y) = ({px:g}, {py:g})")

    def metadata(self) -> dict:
        return {"name": self.name, "expression": self.text}
