"""Target surfaces z = f(x, y) (Step 1): Bezier, dome, hyperbolic paraboloid, user text, and
triangle meshes from CAD.

The built-in ones are given on the paper's 3 m x 3 m square and scale to a pattern's plan box;
a mesh is placed like a pattern, the lower-left corner of its plan's bounding box at (0, 0).
Which surface a case takes is a :class:`SurfaceSpec` (read from the command line's text by
:mod:`rigidfold.generate.specs`), made by :func:`surface_of`."""

from __future__ import annotations

from rigidfold.surfaces.builtin import Bezier, Dome, HyperbolicParaboloid, MirrorPlane, Surface
from rigidfold.surfaces.expression import Expression, ExpressionSurface
from rigidfold.surfaces.mesh import (
    MESH_FORMATS,
    MeshSurface,
    SplineSurface,
    mesh_surface,
    read_mesh,
    sample_mesh,
)
from rigidfold.surfaces.spec import (
    SURFACE_FORMS,
    SURFACES,
    SurfaceKind,
    SurfaceSpec,
    placed_mesh,
    surface_of,
)

__all__ = [
    "MESH_FORMATS",
    "SURFACES",
    "SURFACE_FORMS",
    "Bezier",
    "Dome",
    "Expression",
    "ExpressionSurface",
    "HyperbolicParaboloid",
    "MeshSurface",
    "MirrorPlane",
    "SplineSurface",
    "Surface",
    "SurfaceKind",
    "SurfaceSpec",
    "mesh_surface",
    "placed_mesh",
    "read_mesh",
    "sample_mesh",
    "surface_of",
]
