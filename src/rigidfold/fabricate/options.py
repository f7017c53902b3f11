"""The options of the thick panels as the user gives them: ``rigidfold fabricate`` and
``rigidfold generate --thickness`` build one :class:`FabricateOptions`.

It holds every option of the command (the thickness, the side, the clearance angle in
degrees, the density, the stock sheet, the minimum thickness), each a field made by
:func:`rigidfold.flags.option` whose doc is also its flag's help, each default from
``Settings.fabricate``, checked once when it is made (:func:`rigidfold.fabricate.build.
fabrication_values`, :func:`~rigidfold.fabricate.build.check_sheet`); the command line reads
their texts (:mod:`rigidfold.cli.units`: ``18mm``, ``2440x1220``);
:meth:`FabricateOptions.fabricate` runs
:func:`rigidfold.fabricate.fabricate_panels` with them.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, fields

import numpy as np

from rigidfold.config import DEFAULTS, SIDES, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.build import (
    Fabrication,
    check_sheet,
    fabricate_panels,
    fabrication_values,
)
from rigidfold.fabricate.motion import PanelMotion
from rigidfold.fabricate.panels import Panels
from rigidfold.flags import option
from rigidfold.material import material_named

_SHEET = (DEFAULTS.fabricate.sheet_width, DEFAULTS.fabricate.sheet_height)
_MATERIAL = DEFAULTS.structure.material


@dataclass(frozen=True)
class FabricateOptions:
    """Thick panels of a design, as ``rigidfold fabricate`` takes them.

    Each field is made by :func:`rigidfold.flags.option` with what it means, also the help of
    its flag (:func:`rigidfold.cli.parser.add_options`: ``rigidfold fabricate``'s, and
    ``generate``'s with ``--thickness``): a new option is a new field here. ``thickness``
    and ``min_thickness`` are metres, ``sheet`` a ``(width, height)`` pair in millimetres
    (the command line reads ``18mm`` and ``2440x1220``); ``density`` None: the
    density of the panels' material (``rigidfold generate``: its ``--material``; else
    ``Settings.structure.material``'s); ``min_thickness`` None:
    ``Settings.fabricate.min_depth`` times the thickness.

    Every value is checked when the options are made (ValueError, one line, naming what
    was received).
    """

    thickness: float = option(
        MISSING,
        "panel thickness in metres, or with a unit: 18mm, 1.8cm",
        parse="thickness",
        metavar="T",
    )
    side: str = option(
        DEFAULTS.fabricate.side,
        "the side of the design surface the solids lie on: bottom (below it, the surface is "
        "their outer face) or top",
        choices=SIDES,
    )
    clearance_angle_deg: float = option(
        round(math.degrees(DEFAULTS.fabricate.clearance_angle), 9),
        "bevels leave this angle, degrees, to spare beyond each hinge's largest fold",
        name="--clearance-angle",
        parse=float,
        metavar="DEG",
    )
    density: float | None = option(
        None,
        "density of the panel material for the masses",
        parse="positive",
        metavar="KG/M3",
        shown=f"that of {_MATERIAL}, {material_named(_MATERIAL).density:g}",
    )
    sheet: tuple[float, float] = option(
        _SHEET,
        "stock sheet size in millimetres that the cut sheets are nested onto",
        parse="sheet",
        metavar="WxH",
        shown="{:g}x{:g}".format(*_SHEET),
    )
    min_thickness: float | None = option(
        None,
        "a panel whose solid is nowhere this deep once bevelled fails",
        parse="min-thickness",
        metavar="T",
        shown=f"{DEFAULTS.fabricate.min_depth:g} x the thickness",
    )

    def __post_init__(self) -> None:
        t = self.thickness
        if (
            isinstance(t, bool)
            or not isinstance(t, int | float | np.number)
            or not (math.isfinite(t) and t > 0)
        ):
            raise RigidfoldError(f"thickness must be a positive length in metres, got {t!r}")
        object.__setattr__(self, "thickness", float(t))
        if self.side not in SIDES:
            raise RigidfoldError(f"side must be one of {', '.join(SIDES)}, got {self.side!r}")
        angle = self.clearance_angle_deg
        if isinstance(angle, bool) or not isinstance(angle, int | float | np.number):
            raise RigidfoldError(f"clearance angle must be a number of degrees, got {angle!r}")
        object.__setattr__(self, "clearance_angle_deg", float(angle))
        self.values()  # the angle, the density and the minimum thickness in range
        for name in ("density", "min_thickness"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "sheet", check_sheet(self.sheet))  # within the limits

    def values(self, settings: Settings = DEFAULTS) -> tuple[float, float, float]:
        """(clearance angle in radians, minimum thickness in metres, density in kg/m^3),
        the unset ones from ``settings`` (:func:`~rigidfold.fabricate.build.
        fabrication_values`); ValueError for a value out of range."""
        return fabrication_values(
            self.thickness,
            clearance_angle=math.radians(self.clearance_angle_deg),
            min_thickness=self.min_thickness,
            density=self.density,
            settings=settings,
        )

    def fabricate(
        self,
        panels: Panels,
        motion: PanelMotion | None,
        *,
        density: float | None = None,
        motion_message: str = "",
        settings: Settings = DEFAULTS,
    ) -> Fabrication:
        """Thick panels of ``panels`` (made on :attr:`side`: ``Panels(pattern, coords2d,
        options.side)``) checked over ``motion``
        (:func:`rigidfold.fabricate.fabricate_panels`); ``density``: the one used where
        :attr:`density` is None (else the density of ``settings.structure.material``)."""
        return fabricate_panels(
            panels,
            motion,
            self.thickness,
            clearance_angle=math.radians(self.clearance_angle_deg),
            min_thickness=self.min_thickness,
            density=density if self.density is None else self.density,
            motion_message=motion_message,
            settings=settings,
        )

    def title(self, name: str) -> str:
        """The title of the files of ``name``'s thick panels."""
        return f"{name}: thick panels {self.thickness * 1e3:g} mm, {self.side} side"

    def to_dict(self) -> dict:
        """The options as JSON values (``sheet`` as a list); :meth:`from_dict` reads them."""
        return {f.name: getattr(self, f.name) for f in fields(self)} | {"sheet": list(self.sheet)}

    @classmethod
    def from_dict(cls, data: dict) -> FabricateOptions:
        """The options of :meth:`to_dict`; unknown keys are ignored, missing ones take
        their defaults."""
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in names})
