"""The panels' material: an isotropic elastic plate of Young's modulus, Poisson's ratio and
density (:class:`Material`), a preset of :data:`MATERIALS` or any other; the panels of a built
design, a material and a thickness (:class:`Panel`). The command line reads a preset's name or
``E,nu,density`` in SI units (:mod:`rigidfold.cli.units`).

The presets are typical values, for a first design; a structural check uses the values of
the product that will be built (its data sheet or the relevant code):

============  ==========  =====  ==============  ===============================================
name          E (GPa)     nu     density (kg/m3) source
============  ==========  =====  ==============  ===============================================
plywood       10          0.30   700             birch plywood: density 7.0 kN/m3 (EN 1991-1-1
                                                 Table A.3); E of the order of 10 GPa along the
                                                 face grain (EN 12369-2 / manufacturers' data
                                                 of birch plywood); modelled isotropic
aluminium     70          0.30   2700            EN 1999-1-1 (Eurocode 9) 3.2.5
steel         210         0.30   7850            EN 1993-1-1 (Eurocode 3) 3.2.6; density
                                                 77-78.5 kN/m3 in EN 1991-1-1 Table A.4
polycarbonate 2.3         0.37   1200            solid polycarbonate sheet, typical data sheets
                                                 (tensile modulus 2.2-2.4 GPa, 1.20 g/cm3)
============  ==========  =====  ==============  ===============================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigidfold.errors import RigidfoldError


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    E : Young's modulus, Pa; nu : Poisson's ratio, -1 < nu < 0.5; density : kg/m^3, >= 0;
    name : the preset's name, or "custom".
    """

    E: float
    nu: float
    density: float
    name: str = "custom"

    def __post_init__(self) -> None:
        for field_name in ("E", "nu", "density"):
            value = getattr(self, field_name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise RigidfoldError(f"material {field_name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise RigidfoldError(f"material {field_name} must be finite, got {value!r}")
        if not self.E > 0:
            raise RigidfoldError(f"Young's modulus E must be positive (Pa), got {self.E!r}")
        if not -1 < self.nu < 0.5:
            raise RigidfoldError(f"Poisson's ratio nu must lie in (-1, 0.5), got {self.nu!r}")
        if self.density < 0:
            raise RigidfoldError(f"density must be >= 0 (kg/m^3), got {self.density!r}")

    def plate_rigidity(self, thickness: float) -> float:
        """Flexural rigidity D = E t^3 / (12 (1 - nu^2)) of a plate of ``thickness`` m, N m."""
        return self.E * thickness**3 / (12 * (1 - self.nu**2))

    def to_dict(self) -> dict:
        return {"name": self.name, "E_Pa": self.E, "nu": self.nu, "density_kg_m3": self.density}

    @classmethod
    def from_dict(cls, data: dict) -> Material:
        """The material of :meth:`to_dict`."""
        return cls(data["E_Pa"], data["nu"], data["density_kg_m3"], data["name"])

    @property
    def key(self) -> str:
        """The material as a record holds it in one word: a preset's name, else
        ``"E,nu,density"`` (SI units; :meth:`from_key` reads it back)."""
        if MATERIALS.get(self.name) == self:
            return self.name
        return ",".join(_number(x) for x in (self.E, self.nu, self.density))

    @classmethod
    def from_key(cls, key: str) -> Material:
        """The material of :attr:`key` (as a record wrote it); RigidfoldError for another
        text."""
        if key in MATERIALS:
            return MATERIALS[key]
        try:
            E, nu, density = (float(x) for x in str(key).split(","))
        except ValueError:
            raise RigidfoldError(
                f"a recorded material is a preset's name or 'E,nu,density', got {key!r}"
            ) from None
        return cls(E, nu, density)

    def describe(self) -> str:
        """``plywood (E = 10 GPa, nu = 0.3, 700 kg/m^3)``."""
        return f"{self.name} (E = {self.E / 1e9:g} GPa, nu = {self.nu:g}, {self.density:g} kg/m^3)"


def _number(x: float) -> str:
    """``x`` in the fewest digits that read back as it (``10000000000``, ``0.3``)."""
    text = repr(float(x))
    return text.removesuffix(".0")


MATERIALS: dict[str, Material] = {
    "plywood": Material(10e9, 0.30, 700.0, "plywood"),
    "aluminium": Material(70e9, 0.30, 2700.0, "aluminium"),
    "steel": Material(210e9, 0.30, 7850.0, "steel"),
    "polycarbonate": Material(2.3e9, 0.37, 1200.0, "polycarbonate"),
}
"""The named presets (see the module's text for their sources)."""

MATERIAL_SOURCES = {
    "plywood": "birch plywood, EN 1991-1-1 Table A.3 (density), EN 12369-2 order of E",
    "aluminium": "EN 1999-1-1 3.2.5",
    "steel": "EN 1993-1-1 3.2.6, EN 1991-1-1 Table A.4",
    "polycarbonate": "typical solid polycarbonate sheet data",
}
"""Where each preset's values come from, in a few words (for ``--help`` and the JSON)."""


def material_named(name: str) -> Material:
    """The preset ``name`` (a key of :data:`MATERIALS`, as ``Settings.structure.material``
    holds it); RigidfoldError naming it for another name."""
    if name not in MATERIALS:
        raise RigidfoldError(f"no material preset {name!r} (the presets: {', '.join(MATERIALS)})")
    return MATERIALS[name]


@dataclass(frozen=True)
class Panel:
    """The panels of a built design: their material and their thickness, metres (> 0)."""

    material: Material
    thickness: float

    def __post_init__(self) -> None:
        if not isinstance(self.material, Material):
            raise RigidfoldError(f"panel material must be a Material, got {self.material!r}")
        t = self.thickness
        if isinstance(t, bool) or not (isinstance(t, int | float) and math.isfinite(t) and t > 0):
            raise RigidfoldError(f"thickness must be a positive number of metres, got {t!r}")
        object.__setattr__(self, "thickness", float(t))


def presets_help() -> str:
    """One line listing the presets with their values and sources (for ``--help``)."""
    return "; ".join(f"{m.describe()}, {MATERIAL_SOURCES[name]}" for name, m in MATERIALS.items())
