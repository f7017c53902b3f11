"""Target surfaces z = f(x, y) (Step 1): Bezier, dome, hyperbolic paraboloid, user text,
triangle meshes.

The built-in ones are given on the paper's 3 m x 3 m square and scale to a pattern's plan box."""

from __future__ import annotations

from rigidfold.surfaces.builtin import Bezier, Dome, HyperbolicParaboloid, MirrorPlane, Surface
from rigidfold.surfaces.expression import ExpressionSurface, parse_expression
from rigidfold.surfaces.mesh import MESH_FORMATS, MeshSurface, mesh_surface, read_mesh

SURFACES = ("bezier", "dome", "hp", "expr")


def get_surface(
    name: str,
    *,
    seed: int | None = None,
    expr: str | None = None,
    box: tuple[float, float] = (3.0, 3.0),
) -> Surface:
    """A built-in surface by name, scaled to the plan box (W, H) in metres, or ``expr`` for the
    user's text ``expr`` (evaluated in metres as given, whatever the box)."""
    if name == "bezier":
        return Bezier(0 if seed is None else seed, box=box)
    if name == "dome":
        return Dome(box=box)
    if name == "hp":
        return HyperbolicParaboloid(box=box)
    if name == "expr":
        if expr is None:
            raise ValueError("surface 'expr' needs an expression z = f(x, y)")
        return ExpressionSurface(expr)
    raise ValueError(f"unknown surface {name!r} (choose from {', '.join(SURFACES)})")


__all__ = [
    "MESH_FORMATS",
    "SURFACES",
    "Bezier",
    "Dome",
    "ExpressionSurface",
    "HyperbolicParaboloid",
    "MeshSurface",
    "MirrorPlane",
    "Surface",
    "get_surface",
    "mesh_surface",
    "parse_expression",
    "read_mesh",
]
