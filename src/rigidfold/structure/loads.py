"""Loads on the deployed structure: self-weight, snow on the plan, wind normal to the panels,
point loads, as nodal forces of the shell mesh.

``--load`` values (one per option, any number):

* ``uniform=Q``: a load of Q per plan area, downwards (snow): each element carries Q x its
  area projected on the xy plane;
* ``pressure=Q``: a pressure of Q normal to the panels (wind), positive pressing on the
  upper face (against the upward normal of a counter-clockwise pattern), negative a suction;
* ``point=V:FX,FY,FZ``: a force at vertex V (``point=12:0,0,-500``, ``point=12:0,0,-2kN``).

Units: a pressure or uniform load in ``Pa``, ``kPa`` (= ``kN/m2``) or ``MPa``, a bare number
in kPa (``uniform=0.5``, ``0.5kPa`` and ``500Pa`` are the same load); a point load's
components in ``N``, ``kN`` or ``MN``, a bare number in newtons. The command line reads them
(:func:`rigidfold.cli.structure_specs.parse_load`) into the typed loads here: a
:class:`Uniform` or :class:`Pressure` in kPa, a :class:`Point` in newtons.

Self-weight (on unless ``--no-self-weight``) is density x g x thickness per panel area. An
element's load goes to its three nodes in equal shares (the consistent load of a uniform
load on a linear triangle's translations).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.structure.model import ShellMesh

LOAD_KINDS = ("uniform", "pressure", "point")
"""The kinds of ``--load`` (self-weight is on unless ``--no-self-weight``)."""


@dataclass(frozen=True)
class _AreaLoad:
    """A load of ``kpa`` kN/m^2 over the panels."""

    kpa: float
    kind: ClassVar[str] = ""

    def to_dict(self) -> dict:
        return {"kind": self.kind, "kPa": self.kpa}

    def describe(self) -> str:
        return f"{self.kind} {self.kpa:g} kPa"

    @property
    def text(self) -> str:
        """The ``--load`` text of this load, its number in kPa, bare
        (:func:`rigidfold.cli.structure_specs.parse_load` reads it back)."""
        return f"{self.kind}={self.kpa!r}"


@dataclass(frozen=True)
class Uniform(_AreaLoad):
    """A load of ``kpa`` kN/m^2 per plan area, downwards (snow)."""

    kind: ClassVar[str] = "uniform"


@dataclass(frozen=True)
class Pressure(_AreaLoad):
    """A pressure of ``kpa`` kN/m^2 normal to the panels (wind), positive pressing on the
    upper face, negative a suction."""

    kind: ClassVar[str] = "pressure"


@dataclass(frozen=True)
class Point:
    """A force ``force`` (3,) newtons at the design's vertex ``vertex``."""

    vertex: int
    force: tuple[float, float, float]
    kind: ClassVar[str] = "point"

    def to_dict(self) -> dict:
        return {"kind": self.kind, "vertex": self.vertex, "force_N": list(self.force)}

    def describe(self) -> str:
        return f"point load {list(self.force)} N at vertex {self.vertex}"

    @property
    def text(self) -> str:
        """The ``--load`` text of this load (:func:`rigidfold.cli.structure_specs.parse_load`
        reads it back)."""
        return f"point={self.vertex}:" + ",".join(repr(f) for f in self.force)


@dataclass(frozen=True)
class SelfWeight:
    """The panels' weight, density x g x thickness per panel area: in
    :class:`~rigidfold.structure.StructureOptions` ``loads`` the same as ``self_weight``."""

    kind: ClassVar[str] = "self_weight"

    def to_dict(self) -> dict:
        return {"kind": self.kind}

    def describe(self) -> str:
        return "self-weight"

    @property
    def text(self) -> str:
        return self.kind


Load = Uniform | Pressure | Point | SelfWeight
"""One load term: :class:`Uniform`, :class:`Pressure`, :class:`Point` or :class:`SelfWeight`."""

LOAD_TYPES = (Uniform, Pressure, Point, SelfWeight)
"""The classes of :data:`Load`, for ``isinstance``."""


def check_magnitudes(loads: tuple[Load, ...], largest: float) -> None:
    """ValueError (one line) for a load above ``largest`` in SI units (Pa, N)."""
    for load in loads:
        if isinstance(load, Point):
            size, unit = max(abs(f) for f in load.force), "N"
        elif isinstance(load, _AreaLoad):
            size, unit = abs(load.kpa) * 1e3, "Pa"
        else:
            continue
        if not size <= largest:
            raise RigidfoldError(
                f"the {load.describe()} is above {largest:g} {unit} "
                "(Settings.limits.max_structure_value)"
            )


def check_loads(loads: tuple[Load, ...], n_vertices: int) -> None:
    """ValueError when a load is not a :data:`Load` or a point load names a vertex the
    design does not have."""
    for load in loads:
        if not isinstance(load, LOAD_TYPES):
            raise RigidfoldError(
                f"a load must be Uniform, Pressure, Point or SelfWeight, got {load!r}"
            )
        if isinstance(load, Point) and not 0 <= load.vertex < n_vertices:
            raise RigidfoldError(
                f"point load at vertex {load.vertex}: the design has vertices 0..{n_vertices - 1}"
            )


def nodal_loads(
    mesh: ShellMesh,
    loads: tuple[Load, ...],
    *,
    self_weight: float,
) -> np.ndarray:
    """(N, 3) nodal forces in newtons of ``loads`` plus a self-weight of ``self_weight``
    N/m^2 of panel (density x g x thickness; 0 for none)."""
    per_area = np.zeros((mesh.n_elements, 3))
    per_area[:, 2] -= self_weight
    area = mesh.triangle_areas
    normal = mesh.triangle_normals
    for load in loads:
        if isinstance(load, Pressure):
            per_area -= 1e3 * load.kpa * normal
        elif isinstance(load, Uniform):
            per_area[:, 2] -= 1e3 * load.kpa * np.abs(normal[:, 2])
    forces = np.zeros((mesh.n_nodes, 3))
    share = (per_area * area[:, None] / 3.0)[:, None, :].repeat(3, axis=1)
    np.add.at(forces, mesh.triangles.ravel(), share.reshape(-1, 3))
    for load in loads:
        if isinstance(load, Point):
            forces[mesh.vertex_nodes(load.vertex)[0]] += load.force
    return forces
