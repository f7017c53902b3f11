"""Loads on the deployed structure: self-weight, snow on the plan, wind normal to the panels,
point loads, as nodal forces of the shell mesh.

``--load`` values (one per option, any number):

* ``uniform=KPA``: a load of KPA kN/m^2 per plan area, downwards (snow): each element
  carries KPA x its area projected on the xy plane;
* ``pressure=KPA``: a pressure of KPA kN/m^2 normal to the panels (wind), positive pressing
  on the upper face (against the upward normal of a counter-clockwise pattern), negative a
  suction;
* ``point=V:FX,FY,FZ``: a force in newtons at vertex V (``point=12:0,0,-500``).

Self-weight (on unless ``--no-self-weight``) is density x g x thickness per panel area. An
element's load goes to its three nodes in equal shares (the consistent load of a uniform
load on a linear triangle's translations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.structure.model import ShellMesh

LOAD_KINDS = ("uniform", "pressure", "point")


@dataclass(frozen=True)
class Load:
    """One load case term.

    kind : one of :data:`LOAD_KINDS`; kpa : kN/m^2 of a uniform load or a pressure;
    vertex, force : of a point load (vertex index, (3,) newtons).
    """

    kind: str
    kpa: float = 0.0
    vertex: int = -1
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def to_dict(self) -> dict:
        if self.kind == "point":
            return {"kind": "point", "vertex": self.vertex, "force_N": list(self.force)}
        return {"kind": self.kind, "kPa": self.kpa}

    def describe(self) -> str:
        if self.kind == "point":
            return f"point load {list(self.force)} N at vertex {self.vertex}"
        return f"{self.kind} {self.kpa:g} kPa"


def parse_load(text: str) -> Load:
    """``uniform=KPA``, ``pressure=KPA`` or ``point=V:FX,FY,FZ`` (see the module's text);
    ValueError naming what was received for anything else."""
    if not isinstance(text, str) or "=" not in text:
        raise RigidfoldError(
            f"a load is uniform=KPA, pressure=KPA or point=V:FX,FY,FZ, got {text!r}"
        )
    kind, _, value = (s.strip() for s in text.partition("="))
    kind = kind.lower()
    if kind in ("uniform", "pressure"):
        kpa = _number(value, text)
        return Load(kind, kpa=kpa)
    if kind == "point":
        vertex, sep, force = value.partition(":")
        parts = force.split(",")
        if not sep or len(parts) != 3:
            raise RigidfoldError(f"a point load is point=V:FX,FY,FZ (newtons), got {text!r}")
        try:
            v = int(vertex.strip())
        except ValueError:
            raise RigidfoldError(
                f"a point load's vertex must be an integer, got {text!r}"
            ) from None
        if v < 0:
            raise RigidfoldError(f"a point load's vertex must be >= 0, got {text!r}")
        fx, fy, fz = (_number(p, text) for p in parts)
        return Load("point", vertex=v, force=(fx, fy, fz))
    raise RigidfoldError(
        f"unknown load kind {kind!r} in {text!r} (choose from {', '.join(LOAD_KINDS)})"
    )


def _number(value: str, text: str) -> float:
    try:
        x = float(value)
    except ValueError:
        x = math.nan
    if not math.isfinite(x):
        raise RigidfoldError(f"a load's value must be a finite number, got {text!r}")
    return x


def check_loads(loads: tuple[Load, ...], n_vertices: int) -> None:
    """ValueError when a point load names a vertex the design does not have."""
    for load in loads:
        if load.kind == "point" and not 0 <= load.vertex < n_vertices:
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
        if load.kind == "uniform":
            per_area[:, 2] -= 1e3 * load.kpa * np.abs(normal[:, 2])
        elif load.kind == "pressure":
            per_area -= 1e3 * load.kpa * normal
    forces = np.zeros((mesh.n_nodes, 3))
    share = (per_area * area[:, None] / 3.0)[:, None, :].repeat(3, axis=1)
    np.add.at(forces, mesh.triangles.ravel(), share.reshape(-1, 3))
    for load in loads:
        if load.kind == "point":
            forces[mesh.vertex_nodes(load.vertex)[0]] += load.force
    return forces
