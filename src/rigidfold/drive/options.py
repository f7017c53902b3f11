"""The options of the drive as the user gives them: ``rigidfold deploy`` and ``rigidfold
generate --deploy`` build one :class:`DriveOptions`.

Every field is a typed value (a thickness in metres, a :class:`~rigidfold.structure.
material.Material`, a base that is a panel's index or :data:`AUTO`, cables as pairs of
vertices), made by :func:`rigidfold.flags.option` whose doc is also its flag's help and
whose ``parse`` reads the command line's text; defaults from ``Settings.drive`` (the
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
from rigidfold.fabricate.build import parse_length
from rigidfold.flags import option
from rigidfold.material import Material, parse_material, presets_help

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


def parse_base(text: str | int) -> Base:
    """``"auto"``, ``"panel:P"`` or ``"P"`` (a panel's index, >= 0) as a :data:`Base`."""
    if isinstance(text, bool):
        raise RigidfoldError(f"base must be auto or panel:P, got {text!r}")
    if isinstance(text, int):
        if text < 0:
            raise RigidfoldError(f"base must be auto or panel:P with P >= 0, got {text!r}")
        return text
    if not isinstance(text, str):
        raise RigidfoldError(f"base must be auto or panel:P, got {text!r}")
    raw = text.strip().lower()
    if raw == AUTO:
        return AUTO
    number = raw.removeprefix("panel:").strip()
    try:
        value = int(number)
    except ValueError:
        raise RigidfoldError(f"base must be auto or panel:P, got {text!r}") from None
    if value < 0:
        raise RigidfoldError(f"base must be auto or panel:P with P >= 0, got {text!r}")
    return value


def parse_cable(text: str | tuple[int, int]) -> tuple[int, int]:
    """``"V,W"`` (or a pair) as a cable between two different vertices ``(V, W)``."""
    parts: list
    if isinstance(text, str):
        parts = [p.strip() for p in text.replace("-", ",").split(",")]
    elif isinstance(text, tuple | list):
        parts = list(text)
    else:
        raise RigidfoldError(f"a cable is V,W (two vertices), got {text!r}")
    try:
        if len(parts) != 2 or any(isinstance(p, bool | float) for p in parts):
            raise ValueError
        v, w = (int(p) for p in parts)
    except (TypeError, ValueError):
        raise RigidfoldError(f"a cable is V,W (two vertices), got {text!r}") from None
    if v < 0 or w < 0 or v == w:
        raise RigidfoldError(f"a cable joins two different vertices >= 0, got {text!r}")
    return v, w


def parse_point_mass(text: str | tuple[int, float]) -> tuple[int, float]:
    """``"V:KG"`` (or a pair) as a point mass ``(vertex, kg)``, kg finite and >= 0."""
    if isinstance(text, str):
        vertex, sep, kg = text.partition(":")
        if not sep:
            raise RigidfoldError(f"a point mass is V:KG, got {text!r}")
        parts: list = [vertex.strip(), kg.strip()]
    elif isinstance(text, tuple | list) and len(text) == 2:
        parts = list(text)
    else:
        raise RigidfoldError(f"a point mass is V:KG, got {text!r}")
    try:
        if isinstance(parts[0], bool | float):
            raise ValueError
        v, m = int(parts[0]), float(parts[1])
    except (TypeError, ValueError):
        raise RigidfoldError(f"a point mass is V:KG, got {text!r}") from None
    if v < 0 or not (math.isfinite(m) and m >= 0):
        raise RigidfoldError(f"a point mass is V:KG with V >= 0 and KG >= 0, got {text!r}")
    return v, m


def _non_negative(value: object, what: str, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RigidfoldError(f"{what} must be a number >= 0 ({unit}), got {value!r}")
    if not (math.isfinite(value) and value >= 0):
        raise RigidfoldError(f"{what} must be a finite number >= 0 ({unit}), got {value!r}")
    return float(value)


def _number_text(what: str, unit: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise RigidfoldError(f"{what} must be a number ({unit}), got {text!r}") from None
        return _non_negative(value, what, unit)

    return parse


def _positive_text(what: str, unit: str):
    def parse(text: str) -> float:
        value = _number_text(what, unit)(text)
        if value <= 0:
            raise RigidfoldError(f"{what} must be positive ({unit}), got {text!r}")
        return value

    return parse


def _ground(text: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise RigidfoldError(f"ground must be a height in metres, got {text!r}") from None
    if not math.isfinite(value):
        raise RigidfoldError(f"ground must be a finite height in metres, got {text!r}")
    return value


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
        parse=lambda text: parse_length(text, "thickness"),
        metavar="T",
        shown=f"the thickness fabricate recorded beside the design, else {_S.thickness:g}",
    )
    material: Material = option(  # noqa: RUF009 (frozen)
        parse_material(_S.material),
        f"the panels' material: a preset ({presets_help()}) or E,nu,density in SI units (Pa, "
        "-, kg/m^3); its density gives the masses",
        parse=parse_material,
        metavar="NAME|E,nu,density",
        shown=_S.material,
    )
    density: float | None = option(
        None,
        "density of the panels, kg/m^3, instead of the material's",
        parse=_positive_text("density", "kg/m^3"),
        metavar="KG/M3",
        shown="the material's",
    )
    hinge_stiffness: float = option(
        _D.hinge_stiffness,
        "rotational stiffness of every hinge, N m/rad per metre of crease (as structure "
        "--hinge-stiffness)",
        parse=_number_text("hinge stiffness", "N m/rad per m"),
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
        parse=_number_text("friction", "N m per m"),
        metavar="NM/M",
    )
    hardware: float = option(
        _D.hardware,
        "mass of the hinge hardware, kg per metre of hinge",
        parse=_number_text("hardware", "kg/m"),
        metavar="KG/M",
    )
    point_masses: tuple[tuple[int, float], ...] = option(
        (),
        "a mass at a vertex, kg, repeatable",
        name="--point-mass",
        parse=parse_point_mass,
        metavar="V:KG",
        repeat=True,
    )
    base: Base = option(  # noqa: RUF009 (a str or an int)
        AUTO,
        "how the structure is held during the motion: panel:P clamps panel P in its built "
        "pose; auto chooses the panel of the smallest peak effort among those whose motion "
        "keeps every vertex above the ground",
        parse=parse_base,
        metavar="panel:P|auto",
    )
    ground: float | None = option(
        None,
        "height of the ground, metres: a state in which a vertex passes below it is reported",
        parse=_ground,
        metavar="Z",
        shown="the lowest point of the built design",
    )
    cables: tuple[tuple[int, int], ...] = option(
        (),
        "a cable between two vertices, repeatable: its tension along the motion",
        name="--cable",
        parse=parse_cable,
        metavar="V,W",
        repeat=True,
    )
    cables_auto: bool = option(
        False, "also the best cables between pairs of boundary vertices", switch=""
    )
    max_torque: float | None = option(
        None,
        "the largest torque a crease drive may need, N m",
        parse=_positive_text("max torque", "N m"),
        metavar="NM",
        shown="no limit",
    )
    max_tension: float | None = option(
        None,
        "the largest tension a cable may need, N",
        parse=_positive_text("max tension", "N"),
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
            if isinstance(t, str):
                t = parse_length(t, "thickness")
            if isinstance(t, bool) or not isinstance(t, int | float):
                raise RigidfoldError(f"thickness must be a positive length in metres, got {t!r}")
            if not (math.isfinite(t) and t > 0):
                raise RigidfoldError(f"thickness must be a positive length in metres, got {t!r}")
            object.__setattr__(self, "thickness", float(t))
        object.__setattr__(self, "material", parse_material(self.material))
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
        object.__setattr__(
            self, "point_masses", tuple(parse_point_mass(p) for p in self.point_masses)
        )
        object.__setattr__(self, "base", parse_base(self.base))
        if self.ground is not None:
            if isinstance(self.ground, bool) or not isinstance(self.ground, int | float):
                raise RigidfoldError(f"ground must be a height in metres, got {self.ground!r}")
            if not math.isfinite(self.ground):
                raise RigidfoldError(f"ground must be a finite height, got {self.ground!r}")
            object.__setattr__(self, "ground", float(self.ground))
        if isinstance(self.cables, str) or not isinstance(self.cables, tuple | list):
            raise RigidfoldError(f"cables must be V,W pairs, got {self.cables!r}")
        object.__setattr__(self, "cables", tuple(parse_cable(c) for c in self.cables))
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
