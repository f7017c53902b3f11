"""The options of the thick panels as the user gives them: ``rigidfold fabricate`` and
``rigidfold generate --thickness`` build one :class:`FabricateOptions`.

It holds every option of the command (the thickness, the side, the clearance angle in
degrees, the density, the stock sheet, the minimum thickness), each default from
``Settings.fabricate``, checked once when it is made (:func:`rigidfold.fabricate.build.
fabrication_values`, :func:`~rigidfold.fabricate.build.parse_length`,
:func:`~rigidfold.fabricate.build.parse_sheet`); :meth:`FabricateOptions.fabricate` runs
:func:`rigidfold.fabricate.fabricate_panels` with them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from rigidfold.config import DEFAULTS, SIDES, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.build import (
    Fabrication,
    fabricate_panels,
    fabrication_values,
    parse_length,
    parse_sheet,
)
from rigidfold.fabricate.motion import PanelMotion
from rigidfold.fabricate.panels import Panels


@dataclass(frozen=True)
class FabricateOptions:
    """Thick panels of a design, as ``rigidfold fabricate`` takes them.

    thickness : metres (a number, or a length text: ``"18mm"``, ``"1.8cm"``, ``"0.018"``),
        kept as a float.
    side : one of ``SIDES``: the side of the design surface the solids lie on.
    clearance_angle_deg : degrees the bevels leave beyond each hinge's largest fold.
    density : kg/m^3 of the panels for their masses; None: the density of the panels'
        material (``rigidfold generate``: its ``--material``; else
        ``Settings.structure.material``, plywood's 700).
    sheet : (width, height) of the stock sheet in millimetres, or ``"2440x1220"``, kept as
        a pair.
    min_thickness : metres; a panel nowhere this deep once bevelled fails; None:
        ``Settings.fabricate.min_depth`` times the thickness.

    Every value is checked when the options are made (ValueError, one line, naming what
    was received).
    """

    thickness: float
    side: str = DEFAULTS.fabricate.side
    clearance_angle_deg: float = round(math.degrees(DEFAULTS.fabricate.clearance_angle), 9)
    density: float | None = None
    sheet: tuple[float, float] = (DEFAULTS.fabricate.sheet_width, DEFAULTS.fabricate.sheet_height)
    min_thickness: float | None = None

    def __post_init__(self) -> None:
        for name, what in (("thickness", "thickness"), ("min_thickness", "min-thickness")):
            value = getattr(self, name)
            if isinstance(value, str) or (name == "thickness" and value is not None):
                if isinstance(value, bool):
                    raise RigidfoldError(f"{what} must be a positive length, got {value!r}")
                object.__setattr__(self, name, parse_length(value, what))
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
        object.__setattr__(self, "sheet", parse_sheet(self.sheet))  # within the limits

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
