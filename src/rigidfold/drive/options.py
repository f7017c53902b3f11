"""The options of the drive as the user gives them: ``rigidfold deploy`` and ``rigidfold
generate --deploy`` build one :class:`DriveOptions`.

Every field is a typed value (a thickness in metres, a :class:`~rigidfold.material.Material`,
a base that is a panel's index or :data:`AUTO`, cables as pairs of vertices), made by
:func:`rigidfold.flags.option` whose doc is also its flag's help and whose ``parse`` names the
parser of the command line's text (:mod:`rigidfold.cli.units`: ``18mm``, ``panel:3``,
``V,W``, ``V:KG``); defaults from ``Settings.drive`` (the
hinges, the hardware) and ``Settings.structure`` (the panels' thickness and material, as
``rigidfold structure`` has them). Every value is checked once, when the options are made
(:class:`rigidfold.errors.RigidfoldError`, one line naming what was received); the indices
against a design by :meth:`DriveOptions.check_indices`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Literal

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.flags import option
from rigidfold.material import Material, material_named, presets_help

AUTO: Literal["auto"] = "auto"
"""The base chosen by the drive (``--base auto``)."""

Base = int | Literal["auto"]
"""How the structure is held during the motion: the index of the clamped panel, or
:data:`AUTO` (the panel of the smallest peak effort among those whose motion keeps every
vertex above the ground)."""

SPRING_RESTS = ("flat", "built")
"""Where the hinges' springs are at rest: the flat sheet or the built design."""

_D = DEFAULTS.drive
_S = DEFAULTS.structure


def _base(base: object) -> Base:
    """A :data:`Base`: :data:`AUTO` or a panel's index >= 0."""
    if base == AUTO and isinstance(base, str):
        return AUTO
    if isinstance(base, bool) or not isinstance(base, int):
        raise RigidfoldError(f"base must be auto or a panel's index, got {base!r}")
    if base < 0:
        raise RigidfoldError(f"base must be auto or panel:P with P >= 0, got {base!r}")
    return base


def _cable(cable: object) -> tuple[int, int]:
    """A cable: a pair of two different vertices >= 0."""
    pair = tuple(cable) if isinstance(cable, tuple | list) else ()
    if len(pair) != 2 or any(isinstance(v, bool) or not isinstance(v, int) for v in pair):
        raise RigidfoldError(f"a cable is a pair of vertices (V, W), got {cable!r}")
    v, w = pair
    if v < 0 or w < 0 or v == w:
        raise RigidfoldError(f"a cable joins two different vertices >= 0, got {cable!r}")
    return v, w


def _point_mass(mass: object) -> tuple[int, float]:
    """A point mass: (a vertex >= 0, kg finite and >= 0)."""
    pair = tuple(mass) if isinstance(mass, tuple | list) else ()
    if (
        len(pair) != 2
        or isinstance(pair[0], bool)
        or not isinstance(pair[0], int)
        or isinstance(pair[1], bool)
        or not isinstance(pair[1], int | float)
    ):
        raise RigidfoldError(f"a point mass is a pair (vertex, kg), got {mass!r}")
    v, m = pair[0], float(pair[1])
    if v < 0 or not (math.isfinite(m) and m >= 0):
        raise RigidfoldError(f"a point mass is (V, KG) with V >= 0 and KG >= 0, got {mass!r}")
    return v, m


def _non_negative(value: object, what: str, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RigidfoldError(f"{what} must be a number >= 0 ({unit}), got {value!r}")
    if not (math.isfinite(value) and value >= 0):
        raise RigidfoldError(f"{what} must be a finite number >= 0 ({unit}), got {value!r}")
    return float(value)


@dataclass(frozen=True)
class DriveOptions:
    """The drive of a design's deployment, as ``rigidfold deploy`` takes it.

    Each field is made by :func:`rigidfold.flags.option` with what it means, also the help of
    its flag; every value is typed and checked when the options are made. ``thickness``
    None: the thickness ``rigidfold fabricate`` recorded beside the design (its
    ``NAME_fabricate.json``), else ``Settings.structure.thickness``; ``density`` None: the
    material's; ``ground`` None: the lowest point of the built design; ``max_torque`` /
    ``max_tension`` None: no limit.
    """

    thickness: float | None = option(
        None,
        "panel thickness in metres, or with a unit: 18mm, 1.8cm",
        parse="thickness",
        metavar="T",
        shown=f"the thickness fabricate recorded beside the design, else {_S.thickness:g}",
    )
    material: Material = option(  # noqa: RUF009 (frozen)
        material_named(_S.material),
        f"the panels' material: a preset ({presets_help()}) or E,nu,density in SI units (Pa, "
        "-, kg/m^3); its density gives the masses",
        parse="material",
        metavar="NAME|E,nu,density",
        shown=_S.material,
    )
    density: float | None = option(
        None,
        "density of the panels, kg/m^3, instead of the material's",
        parse="density",
        metavar="KG/M3",
        shown="the material's",
    )
    hinge_stiffness: float = option(
        _D.hinge_stiffness,
        "rotational stiffness of every hinge, N m/rad per metre of crease (as structure "
        "--hinge-stiffness)",
        parse="hinge-stiffness",
        metavar="K",
    )
    spring_rest: str = option(
        "flat",
        "where the hinges' springs are at rest: the flat sheet or the built design",
        choices=SPRING_RESTS,
    )
    friction: float = option(
        _D.friction,
        "Coulomb friction torque of every hinge, N m per metre of crease; it resists the "
        "motion, in both directions",
        parse="friction",
        metavar="NM/M",
    )
    hardware: float = option(
        _D.hardware,
        "mass of the hinge hardware, kg per metre of hinge",
        parse="hardware",
        metavar="KG/M",
    )
    point_masses: tuple[tuple[int, float], ...] = option(
        (),
        "a mass at a vertex, kg, repeatable",
        name="--point-mass",
        parse="point-mass",
        metavar="V:KG",
        repeat=True,
    )
    base: Base = option(  # noqa: RUF009 (a str or an int)
        AUTO,
        "how the structure is held during the motion: panel:P clamps panel P in its built "
        "pose; auto chooses the panel of the smallest peak effort among those whose motion "
        "keeps every vertex above the ground",
        parse="base",
        metavar="panel:P|auto",
    )
    ground: float | None = option(
        None,
        "height of the ground, metres: a state in which a vertex passes below it is reported",
        parse="ground",
        metavar="Z",
        shown="the lowest point of the built design",
    )
    cables: tuple[tuple[int, int], ...] = option(
        (),
        "a cable between two vertices, repeatable: its tension along the motion",
        name="--cable",
        parse="cable",
        metavar="V,W",
        repeat=True,
    )
    cables_auto: bool = option(
        False, "also the best cables between pairs of boundary vertices", switch=""
    )
    max_torque: float | None = option(
        None,
        "the largest torque a crease drive may need, N m",
        parse="max-torque",
        metavar="NM",
        shown="no limit",
    )
    max_tension: float | None = option(
        None,
        "the largest tension a cable may need, N",
        parse="max-tension",
        metavar="N",
        shown="no limit",
    )
    check: bool = option(
        True,
        "the independent check: OpenSees static analyses at states along the motion",
        switch="leave out",
    )
    thickness_from: str = option(
        "",
        "where the thickness came from, for deploy.json: empty where it was given",
        flag=False,
    )

    def __post_init__(self) -> None:
        t = self.thickness
        if t is not None:
            if isinstance(t, bool) or not isinstance(t, int | float):
                raise RigidfoldError(f"thickness must be a positive length in metres, got {t!r}")
            if not (math.isfinite(t) and t > 0):
                raise RigidfoldError(f"thickness must be a positive length in metres, got {t!r}")
            object.__setattr__(self, "thickness", float(t))
        if not isinstance(self.material, Material):
            raise RigidfoldError(f"material must be a Material, got {self.material!r}")
        if self.density is not None:
            d = _non_negative(self.density, "density", "kg/m^3")
            object.__setattr__(self, "density", d)
        for name, what, unit in (
            ("hinge_stiffness", "hinge stiffness", "N m/rad per m"),
            ("friction", "friction", "N m per m"),
            ("hardware", "hardware", "kg/m"),
        ):
            object.__setattr__(self, name, _non_negative(getattr(self, name), what, unit))
        if self.spring_rest not in SPRING_RESTS:
            raise RigidfoldError(
                f"spring rest must be one of {', '.join(SPRING_RESTS)}, got {self.spring_rest!r}"
            )
        if isinstance(self.point_masses, str) or not isinstance(self.point_masses, tuple | list):
            raise RigidfoldError(f"point masses must be V:KG pairs, got {self.point_masses!r}")
        object.__setattr__(self, "point_masses", tuple(_point_mass(p) for p in self.point_masses))
        object.__setattr__(self, "base", _base(self.base))
        if self.ground is not None:
            if isinstance(self.ground, bool) or not isinstance(self.ground, int | float):
                raise RigidfoldError(f"ground must be a height in metres, got {self.ground!r}")
            if not math.isfinite(self.ground):
                raise RigidfoldError(f"ground must be a finite height, got {self.ground!r}")
            object.__setattr__(self, "ground", float(self.ground))
        if isinstance(self.cables, str) or not isinstance(self.cables, tuple | list):
            raise RigidfoldError(f"cables must be V,W pairs, got {self.cables!r}")
        object.__setattr__(self, "cables", tuple(_cable(c) for c in self.cables))
        for name, unit in (("max_torque", "N m"), ("max_tension", "N")):
            value = getattr(self, name)
            if value is None:
                continue
            what = name.replace("_", " ")
            value = _non_negative(value, what, unit)
            if value <= 0:
                raise RigidfoldError(f"{what} must be positive ({unit}), got {value!r}")
            object.__setattr__(self, name, value)
        for name in ("cables_auto", "check"):
            if not isinstance(getattr(self, name), bool):
                raise RigidfoldError(f"{name} must be true or false, got {getattr(self, name)!r}")
        if not isinstance(self.thickness_from, str):
            raise RigidfoldError(f"thickness_from must be text, got {self.thickness_from!r}")

    @property
    def panel_density(self) -> float:
        """kg/m^3 of the panels: ``density``, else the material's."""
        return self.material.density if self.density is None else self.density

    def check_indices(self, n_vertices: int, n_panels: int) -> None:
        """RigidfoldError (one line) for a base panel, cable vertex or point-mass vertex that
        a design of ``n_vertices`` vertices and ``n_panels`` panels lacks."""
        if self.base != AUTO and not int(self.base) < n_panels:
            raise RigidfoldError(
                f"base panel {self.base} is not in the design (panels 0..{n_panels - 1})"
            )
        for v, w in self.cables:
            for x in (v, w):
                if x >= n_vertices:
                    raise RigidfoldError(
                        f"cable {v},{w}: vertex {x} is not in the design (vertices 0.."
                        f"{n_vertices - 1})"
                    )
        for v, _ in self.point_masses:
            if v >= n_vertices:
                raise RigidfoldError(
                    f"point mass at vertex {v}: not in the design (vertices 0..{n_vertices - 1})"
                )

    def replace(self, **changes) -> DriveOptions:
        """These options with ``changes`` (field names), checked again."""
        return replace(self, **changes)

    def to_dict(self) -> dict:
        """The options as JSON values (the material as its ``to_dict``)."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        data["material"] = self.material.to_dict()
        data["density"] = self.panel_density
        data["cables"] = [list(c) for c in self.cables]
        data["point_masses"] = [[v, m] for v, m in self.point_masses]
        return data

    @classmethod
    def from_dict(cls, data: dict) -> DriveOptions:
        """The options of :meth:`to_dict` (``density`` there is the panels', kept only where
        it is not the material's)."""
        given = {f.name: data[f.name] for f in fields(cls) if f.name in data}
        material = Material.from_dict(given.pop("material"))
        density = given.pop("density", None)
        return cls(
            **given,
            material=material,
            density=None if density == material.density else density,
        )
