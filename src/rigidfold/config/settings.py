"""Every tolerance and default of rigidfold, in one place: :class:`Settings`, a frozen
record of the groups of :mod:`rigidfold.config.core`, :mod:`~rigidfold.config.checks` and
:mod:`~rigidfold.config.inputs`.

Library functions take a ``settings`` argument (default :data:`DEFAULTS`) and read a value
by its group: ``settings.design.dz``, ``settings.path.tol``. A changed copy is made by the
*flat names* (the group's prefix and the field's name, listed by :meth:`Settings.flat`)::

    tight = DEFAULTS.with_(dz=0.1, path_tol=1e-12)      # Settings, checked again
    tight.design.dz, tight.path.tol                     # 0.1, 1e-12

The flat view (:meth:`Settings.flat`) is also what a study stores as its configuration,
so that a study database resumes on a version whose groups are arranged differently.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, fields, replace
from typing import Any

from rigidfold.config.base import Group
from rigidfold.config.checks import (
    DeformationSettings,
    DriveSettings,
    FabricateSettings,
    PathSettings,
    StructureSettings,
)
from rigidfold.config.core import (
    DesignSettings,
    GenerationSettings,
    GeometrySettings,
    MechanismSettings,
    SolverSettings,
)
from rigidfold.config.inputs import InputSettings, LimitSettings
from rigidfold.errors import RigidfoldError


@dataclass(frozen=True)
class Settings:
    """Design parameters of problem (6) and the numerical tolerances of rigidfold, in
    groups. Each field of a group is documented where it is defined (its ``doc``:
    :meth:`Settings.docs`)."""

    design: DesignSettings = field(default_factory=DesignSettings)
    """Problem (6): dz, sector-angle bounds, rho_max, F's tolerance (paper, Section 6.1)."""
    generation: GenerationSettings = field(default_factory=GenerationSettings)
    """Steps 4-7: hinge stiffnesses, lock prediction, look-ahead, deployability check."""
    solver: SolverSettings = field(default_factory=SolverSettings)
    """IPOPT, the projection onto F = 0, SLSQP, problem (13), constraint elimination."""
    geometry: GeometrySettings = field(default_factory=GeometrySettings)
    """Degenerate triangles, corners, flat creases, symmetry, overlaps, plans."""
    mechanism: MechanismSettings = field(default_factory=MechanismSettings)
    """The mechanism analysis: ranks, the sparse method, locks."""
    path: PathSettings = field(default_factory=PathSettings)
    """The rigid-folding path traced from a design to flat."""
    deformation: DeformationSettings = field(default_factory=DeformationSettings)
    """Step 9's frame of tubes, its analysis, and the folding motion."""
    structure: StructureSettings = field(default_factory=StructureSettings)
    """The structure under load: panels, supports, analysis, stability."""
    fabricate: FabricateSettings = field(default_factory=FabricateSettings)
    """Thick panels: bevels, clearances, the motion check, cut sheets."""
    drive: DriveSettings = field(default_factory=DriveSettings)
    """The drive of the deployment: masses, hinges, dead points, the OpenSees check."""
    inputs: InputSettings = field(default_factory=InputSettings)
    """Reading SVG drawings, ``mesh:`` footprints and target meshes."""
    limits: LimitSettings = field(default_factory=LimitSettings)
    """Bounds on the size of any input."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if type(value) is not GROUPS[f.name]:
                raise RigidfoldError(
                    f"Settings.{f.name} must be a {GROUPS[f.name].__name__}, "
                    f"got {type(value).__name__}"
                )

    def __getattr__(self, name: str) -> Any:
        # only reached for a name that is not a group: say where a flat name lives now
        if name in FLAT_NAMES:
            group, attr = FLAT_NAMES[name]
            raise AttributeError(
                f"Settings has no attribute {name!r}: the setting is settings.{group}.{attr}"
            )
        raise AttributeError(f"Settings has no attribute {name!r}")

    def with_(self, **changes: Any) -> Settings:
        """A copy with some settings changed, each by its flat name (``dz=0.1``,
        ``path_tol=1e-12``) or a whole group (``design=DesignSettings(...)``); checked
        again. An unknown name raises TypeError naming the closest ones."""
        groups: dict[str, Any] = {k: v for k, v in changes.items() if k in GROUPS}
        by_group: dict[str, dict[str, Any]] = {}
        for name, value in changes.items():
            if name in GROUPS:
                continue
            if name not in FLAT_NAMES:
                close = difflib.get_close_matches(name, FLAT_NAMES, n=3)
                hint = f" (did you mean {', '.join(close)}?)" if close else ""
                raise TypeError(f"Settings has no setting {name!r}{hint}")
            group, attr = FLAT_NAMES[name]
            by_group.setdefault(group, {})[attr] = value
        for group, attrs in by_group.items():
            groups[group] = replace(groups.get(group, getattr(self, group)), **attrs)
        return replace(self, **groups)

    def flat(self) -> dict[str, Any]:
        """Every setting by its flat name, in the order of the groups: the configuration a
        study stores and compares (``rigidfold.study.store.config_differences``)."""
        return {name: getattr(getattr(self, g), a) for name, (g, a) in FLAT_NAMES.items()}

    @classmethod
    def docs(cls) -> dict[str, str]:
        """What every setting means, by its flat name."""
        docs = {g: group.docs() for g, group in GROUPS.items()}
        return {name: docs[g][a] for name, (g, a) in FLAT_NAMES.items()}

    @classmethod
    def from_degrees(
        cls,
        *,
        theta_min_deg: float | None = None,
        theta_max_deg: float | None = None,
        rho_max_deg: float | None = None,
        **kwargs: Any,
    ) -> Settings:
        """Build settings with angles given in degrees (as on the command line) and any other
        setting by its flat name; an angle that is None keeps its default (exactly, not
        through a round trip in degrees)."""
        angles = {"theta_min": theta_min_deg, "theta_max": theta_max_deg}
        for name, degrees in angles.items():
            if degrees is not None:
                kwargs[name] = math.radians(degrees)
        rho_max = None if rho_max_deg is None else math.radians(rho_max_deg)
        return cls().with_(rho_max=rho_max, **kwargs)


GROUPS: dict[str, type[Group]] = {f.name: f.default_factory for f in fields(Settings)}  # type: ignore[misc]
"""The groups of :class:`Settings`, by attribute name."""

FLAT_NAMES: dict[str, tuple[str, str]] = {
    flat: (group, name) for group, cls in GROUPS.items() for flat, name in cls.flat_names()
}
"""``flat name -> (group, field)`` of every setting."""

if len(FLAT_NAMES) != sum(1 for cls in GROUPS.values() for _ in cls.flat_names()):
    raise RuntimeError("two settings share a flat name")  # a programming error, at import

DEFAULTS = Settings()
"""The paper's parameters (Section 6.1) and rigidfold's default tolerances."""
