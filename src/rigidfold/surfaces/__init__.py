"""Target surfaces z = f(x, y) (Step 1): Bezier, dome, hyperbolic paraboloid, user text."""

from __future__ import annotations

from rigidfold.surfaces.builtin import Bezier, Dome, HyperbolicParaboloid, MirrorPlane, Surface
from rigidfold.surfaces.expression import ExpressionSurface, parse_expression

SURFACES = ("bezier", "dome", "hp", "expr")


def get_surface(name: str, *, seed: int | None = None, expr: str | None = None) -> Surface:
    """A built-in surface by name, or ``expr`` for the user's text ``expr``."""
    if name == "bezier":
        return Bezier(0 if seed is None else seed)
    if name == "dome":
        return Dome()
    if name == "hp":
        return HyperbolicParaboloid()
    if name == "expr":
        if expr is None:
            raise ValueError("surface 'expr' needs an expression z = f(x, y)")
        return ExpressionSurface(expr)
    raise ValueError(f"unknown surface {name!r} (choose from {', '.join(SURFACES)})")


__all__ = [
    "SURFACES",
    "Bezier",
    "Dome",
    "ExpressionSurface",
    "HyperbolicParaboloid",
    "MirrorPlane",
    "Surface",
    "get_surface",
    "parse_expression",
]
