"""Target surfaces z = f(x, y) (Step 1): Bezier, dome, hyperbolic paraboloid, user text, and
triangle meshes from CAD.

The built-in ones are given on the paper's 3 m x 3 m square and scale to a pattern's plan box;
a mesh is placed like a pattern, the lower-left corner of its plan's bounding box at (0, 0)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULT_SEED, DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.surfaces.builtin import Bezier, Dome, HyperbolicParaboloid, MirrorPlane, Surface
from rigidfold.surfaces.expression import ExpressionSurface, parse_expression
from rigidfold.surfaces.mesh import (
    MESH_FORMATS,
    MeshSurface,
    SplineSurface,
    mesh_surface,
    read_mesh,
    sample_mesh,
)

SURFACES = ("bezier", "dome", "hp", "expr")
"""The named surfaces."""

SURFACE_FORMS = f"{', '.join(SURFACES)}, mesh:FILE or fold:FILE"
"""The forms of a surface spec, for messages and help texts (``fold:FILE`` is read by
:func:`rigidfold.generate.case.make_case`, which can read FOLD files)."""


def get_surface(
    name: str,
    *,
    seed: int | None = None,
    expr: str | None = None,
    box: tuple[float, float] = (3.0, 3.0),
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> Surface:
    """A built-in surface by name, scaled to the plan box (W, H) in metres; ``expr`` for the
    user's text ``expr`` (evaluated in metres as given, whatever the box); ``mesh:FILE`` for
    an OBJ, STL, PLY or OFF mesh (``up`` its up axis, ``"z"`` or ``"y"``), placed with the
    lower-left corner of its plan at (0, 0) (:func:`placed_mesh`)."""
    if name == "bezier":
        return Bezier(DEFAULT_SEED if seed is None else seed, box=box)
    if name == "dome":
        return Dome(box=box)
    if name == "hp":
        return HyperbolicParaboloid(box=box)
    if name == "expr":
        if expr is None:
            raise RigidfoldError("surface 'expr' needs an expression z = f(x, y)")
        return ExpressionSurface(expr)
    kind, colon, path = str(name).partition(":")
    if colon and kind.strip().lower() == "mesh" and path.strip():
        vertices, triangles = read_mesh(path.strip(), up=up, settings=settings)
        return placed_mesh(vertices, triangles, source=Path(path.strip()).name, settings=settings)
    raise RigidfoldError(f"unknown surface {name!r} (choose from {SURFACE_FORMS})")


def placed_mesh(
    vertices: np.ndarray, triangles: np.ndarray, *, source: str, settings: Settings = DEFAULTS
) -> MeshSurface:
    """The smooth fit (:class:`rigidfold.surfaces.mesh.MeshSurface`) of a triangle mesh
    translated in plan so that the lower-left corner of its bounding box is at (0, 0), the
    frame of the crease patterns; heights as given.

    vertices : (N, 3) float metres, z up; triangles : (M, 3) int; source : the file's name.
    """
    vertices = np.array(vertices, dtype=float)
    vertices[:, :2] -= vertices[:, :2].min(axis=0)
    return MeshSurface(vertices, triangles, source=source, settings=settings)


__all__ = [
    "MESH_FORMATS",
    "SURFACES",
    "SURFACE_FORMS",
    "Bezier",
    "Dome",
    "ExpressionSurface",
    "HyperbolicParaboloid",
    "MeshSurface",
    "MirrorPlane",
    "SplineSurface",
    "Surface",
    "get_surface",
    "mesh_surface",
    "parse_expression",
    "placed_mesh",
    "read_mesh",
    "sample_mesh",
]
