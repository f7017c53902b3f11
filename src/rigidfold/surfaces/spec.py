"""Surface specs, typed: which target surface a case takes (:class:`SurfaceSpec`), and the
surface it makes (:func:`surface_of`).

The command line's texts (``--surface bezier``, ``mesh:FILE``, ``fold:FILE``, ``--expr``)
are read into them by :mod:`rigidfold.generate.specs`; here the values are only checked for
their types.
"""

from __future__ import annotations

import enum
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULT_SEED, DEFAULTS, Settings
from rigidfold.surfaces.builtin import Bezier, Dome, HyperbolicParaboloid, Surface
from rigidfold.surfaces.expression import Expression, ExpressionSurface
from rigidfold.surfaces.mesh import MeshSurface, read_mesh

SURFACES = ("bezier", "dome", "hp", "expr")
"""The named surfaces."""

SURFACE_FORMS = f"{', '.join(SURFACES)}, mesh:FILE or fold:FILE"
"""The forms of a surface spec, for messages and help texts."""


class SurfaceKind(enum.Enum):
    """The kinds of target surface: the paper's three, a user's expression, a triangle mesh
    (OBJ, STL, PLY, OFF) and the 3D shape of a FOLD file's top frame."""

    BEZIER = "bezier"
    DOME = "dome"
    HP = "hp"
    EXPR = "expr"
    MESH = "mesh"
    FOLD = "fold"


_FILES = (SurfaceKind.MESH, SurfaceKind.FOLD)


@dataclass(frozen=True)
class SurfaceSpec:
    """A target surface as the user chose it.

    kind : :class:`SurfaceKind`;
    seed : int of a Bezier surface (default :data:`rigidfold.config.DEFAULT_SEED`; checked by
        :class:`~rigidfold.surfaces.builtin.Bezier`), else None;
    expression : the checked :class:`~rigidfold.surfaces.expression.Expression` of an
        ``expr`` surface, else None;
    path : the file of a ``mesh`` or ``fold`` surface, else None.

    :attr:`text` is the spec as the command line takes it (``bezier``, ``mesh:FILE``); the
    seed and the expression are options of their own there (``--seed``, ``--expr``).
    """

    kind: SurfaceKind
    seed: int | None = None
    expression: Expression | None = None
    path: Path | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.kind, SurfaceKind):
            raise TypeError(
                f"a surface spec's kind is a SurfaceKind, got {type(self.kind).__name__} "
                f"{self.kind!r} (rigidfold.generate.specs.parse_surface_spec reads text)"
            )
        if self.kind is SurfaceKind.BEZIER and self.seed is None:
            object.__setattr__(self, "seed", DEFAULT_SEED)
        if self.kind is SurfaceKind.EXPR and not isinstance(self.expression, Expression):
            raise TypeError(
                "an expr surface spec needs its Expression "
                "(rigidfold.generate.specs.parse_expression), got "
                f"{type(self.expression).__name__}"
            )
        if self.kind in _FILES and not isinstance(self.path, Path):
            raise TypeError(
                f"a {self.kind.value} surface spec needs its file as a Path, got "
                f"{type(self.path).__name__}"
            )
        given = {
            "seed": self.kind is not SurfaceKind.BEZIER and self.seed is not None,
            "expression": self.kind is not SurfaceKind.EXPR and self.expression is not None,
            "path": self.kind not in _FILES and self.path is not None,
        }
        extra = [name for name, wrong in given.items() if wrong]
        if extra:
            raise TypeError(f"a {self.kind.value} surface spec takes no {' or '.join(extra)}")

    @property
    def text(self) -> str:
        """The spec as the command line's ``--surface`` takes it."""
        if self.path is not None:
            return f"{self.kind.value}:{os.fspath(self.path)}"
        return self.kind.value

    def __str__(self) -> str:
        return self.text


def surface_of(
    spec: SurfaceSpec,
    *,
    box: tuple[float, float] = (3.0, 3.0),
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> Surface:
    """The surface of ``spec``: a built-in one scaled to the plan box (W, H) in metres; an
    expression evaluated in metres as given, whatever the box; a mesh (``up`` its up axis,
    ``"z"`` or ``"y"``) or a FOLD file's 3D shape (its top frame, in metres) fitted by a
    smooth surface and placed with the lower-left corner of its plan at (0, 0)
    (:func:`placed_mesh`)."""
    if not isinstance(spec, SurfaceSpec):
        raise TypeError(
            f"a surface is made from a SurfaceSpec, got {type(spec).__name__} "
            "(rigidfold.generate.specs.parse_surface_spec reads text)"
        )
    kind = spec.kind
    if kind is SurfaceKind.BEZIER:
        return Bezier(DEFAULT_SEED if spec.seed is None else spec.seed, box=box)
    if kind is SurfaceKind.DOME:
        return Dome(box=box)
    if kind is SurfaceKind.HP:
        return HyperbolicParaboloid(box=box)
    if kind is SurfaceKind.EXPR:
        assert spec.expression is not None  # SurfaceSpec checks it
        return ExpressionSurface(spec.expression)
    assert spec.path is not None  # SurfaceSpec checks it
    if kind is SurfaceKind.MESH:
        vertices, triangles = read_mesh(spec.path, up=up, settings=settings)
    else:
        from rigidfold.io.fold import read_fold

        shape = read_fold(spec.path, up=up, settings=settings).pattern
        vertices, triangles = shape.coords, shape.faces
    return placed_mesh(vertices, triangles, source=spec.path.name, settings=settings)


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
