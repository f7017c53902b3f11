"""Tolerances and defaults, in one place.

Every numerical threshold and every default design parameter of rigidfold lives in
:class:`Settings`, a frozen record of groups (``settings.design.dz``,
``settings.solver.ipopt_tol``, ``settings.path.tol``, ...), each field documented where it
is defined. Library functions take a ``settings`` argument (default :data:`DEFAULTS`)
instead of scattering literals through the code; ``DEFAULTS.with_(dz=0.1)`` changes a
setting by its flat name (:meth:`Settings.flat` lists them all).

Modules: ``base`` (a documented field, a group), ``core`` (Steps 2-8), ``checks`` (the
checks of a design), ``inputs`` (reading, and bounds on any input), ``settings`` (the
record), ``seeds``, ``blas`` (one BLAS thread).
"""

from enum import StrEnum

from rigidfold.config.blas import one_blas_thread
from rigidfold.config.checks import (
    SIDES,
    DeformationSettings,
    DriveSettings,
    FabricateSettings,
    PathSettings,
    StructureSettings,
)
from rigidfold.config.core import (
    DOF_COUNTS,
    HESSIANS,
    THETA_WIDEN,
    DesignSettings,
    GenerationSettings,
    GeometrySettings,
    MechanismSettings,
    SolverSettings,
)
from rigidfold.config.inputs import InputSettings, LimitSettings
from rigidfold.config.seeds import DEFAULT_SEED, SEED_LIMIT, check_seed
from rigidfold.config.settings import DEFAULTS, FLAT_NAMES, GROUPS, Settings


class Check(StrEnum):
    """Which solutions of a generation run get the folding motion and Step 9 (``generate
    --check``): the final design only (the default), or every solution. A ``str``: files
    and databases hold the plain value."""

    FINAL = "final"
    ALL = "all"


CHECKS = tuple(c.value for c in Check)
"""The values of :class:`Check`, the default first (``generate --check``'s choices)."""

__all__ = [
    "CHECKS",
    "DEFAULTS",
    "DEFAULT_SEED",
    "DOF_COUNTS",
    "FLAT_NAMES",
    "GROUPS",
    "HESSIANS",
    "SEED_LIMIT",
    "SIDES",
    "THETA_WIDEN",
    "Check",
    "DeformationSettings",
    "DesignSettings",
    "DriveSettings",
    "FabricateSettings",
    "GenerationSettings",
    "GeometrySettings",
    "InputSettings",
    "LimitSettings",
    "MechanismSettings",
    "PathSettings",
    "Settings",
    "SolverSettings",
    "StructureSettings",
    "check_seed",
    "one_blas_thread",
]
