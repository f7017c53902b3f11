"""A user's target surface ``z = f(x, y)`` given as text, evaluated safely.

The text is parsed with :mod:`ast` and checked against a whitelist *before* anything is
evaluated (:func:`rigidfold.generate.specs.parse_expression`, which makes an
:class:`Expression`): numbers, ``x``, ``y``, ``pi``, ``e``, ``+ - * / **``, unary signs,
parentheses and calls of whitelisted maths functions (:data:`FUNCTIONS`) by plain name with
positional arguments. The checked tree is then evaluated by a small interpreter of our own on
NumPy arrays or CasADi symbols; user text never reaches ``eval`` or ``compile``.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from dataclasses import dataclass, field
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

BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.UAdd: operator.pos,
    ast.USub: operator.neg,
}


@dataclass(frozen=True)
class Expression:
    """A user's z = f(x, y), checked: ``text`` as recorded (runs of white space made one
    space) and ``tree``, its syntax tree, whose every node the whitelist admits.

    Made by :func:`rigidfold.generate.specs.parse_expression`, which parses the text and
    checks the tree; :func:`evaluate` interprets only the nodes that check admits.
    """

    text: str
    tree: ast.Expression = field(compare=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.text, str) or not isinstance(self.tree, ast.Expression):
            raise TypeError(
                "an Expression is its text and its checked syntax tree "
                "(rigidfold.generate.specs.parse_expression makes one), got "
                f"{type(self.text).__name__} and {type(self.tree).__name__}"
            )


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
            assert isinstance(node.value, (int, float))  # the check admits only these
            return number(node.value)
        if isinstance(node, ast.Name):
            return names[node.id]
        if isinstance(node, ast.BinOp):
            return BINARY[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp):
            return UNARY[type(node.op)](ev(node.operand))
        if isinstance(node, ast.Call):
            assert isinstance(node.func, ast.Name)  # the check admits no other call
            return FUNCTIONS[node.func.id][column](*(ev(a) for a in node.args))
        raise RigidfoldError(f"unchecked node {type(node).__name__}")  # the check excludes it

    return ev(tree)


class ExpressionSurface(Surface):
    """z = f(x, y) from user text; exact gradient by CasADi's automatic differentiation.

    expression : the checked text (:class:`Expression`, from
        :func:`rigidfold.generate.specs.parse_expression`), e.g. ``"0.3*sin(x)*cos(y) +
        0.1*x**2"`` (see :data:`FUNCTIONS`, :data:`CONSTANTS`).
    mirror_planes : the surface's mirror planes, if the user knows any (none are derived).
    """

    name = "expr"

    def __init__(self, expression: Expression, mirror_planes: tuple[MirrorPlane, ...] = ()) -> None:
        if not isinstance(expression, Expression):
            raise TypeError(
                "an expression surface takes an Expression (rigidfold.generate.specs."
                f"parse_expression reads one from text), got {type(expression).__name__}"
            )
        self._tree = expression.tree
        self.text = expression.text
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
