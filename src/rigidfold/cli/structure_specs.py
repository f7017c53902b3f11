"""The structure check's options as the command line gives them, read once into the typed
values of :class:`rigidfold.structure.StructureOptions`.

``--supports auto|service|V,V,...`` (:func:`parse_supports`), ``--support-candidates
boundary|ground|V,V,...`` (:func:`parse_candidates`), ``--clamped`` and ``--actuators``
(:func:`parse_index_list`), ``--load KIND=VALUE`` with units (:func:`parse_load`),
``--limit L/N`` (:func:`parse_limit`) and ``--material`` (:func:`parse_material`);
:func:`read_structure_options` reads them all and makes the options, which check the typed
values. Each refuses what it cannot read with a RigidfoldError, one line naming what was
received (the command line prints it and exits 2).
"""

from __future__ import annotations

import difflib
import math
import re
from typing import Any

from rigidfold.cli.units import parse_material
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.material import Material
from rigidfold.structure.choices import (
    CANDIDATE_WORDS,
    CHOSEN_SUPPORTS,
    Auto,
    Candidates,
    Pins,
    Service,
    SupportSpec,
)
from rigidfold.structure.design import StructureOptions
from rigidfold.structure.loads import LOAD_KINDS, Load, Point, Pressure, SelfWeight, Uniform

__all__ = [
    "FORCE_UNITS",
    "PRESSURE_UNITS",
    "parse_candidates",
    "parse_index_list",
    "parse_limit",
    "parse_load",
    "parse_material",
    "parse_supports",
    "read_structure_options",
]


def read_structure_options(
    *,
    supports: str = "auto",
    loads: tuple[str, ...] | list[str] | None = (),
    limit: str | float = DEFAULTS.structure.limit,
    candidates: str | None = None,
    clamped: str = "",
    actuators: str = "",
    material: str | None = None,
    **typed: Any,
) -> StructureOptions:
    """The options of the command line's texts: ``supports`` ``"auto"``, ``"service"`` or
    ``"V,V,..."``; ``loads`` the ``--load`` texts (``"uniform=0.5kPa"``, a bare number in
    kPa; ``"point=12:0,0,-2kN"``, a bare number in newtons); ``limit`` ``"L/250"`` or 250;
    ``candidates`` ``"boundary"``, ``"ground"`` or ``"V,V,..."`` (None: boundary);
    ``clamped``, ``actuators`` ``"V,V,..."``; ``material`` a preset's name or
    ``"E,nu,density"`` (None: the default); the other fields as typed (``thickness`` in
    metres, ``hinge_stiffness``, ``modes``, the switches)."""
    if loads is None:
        loads = ()
    if isinstance(loads, str) or not isinstance(loads, tuple | list):
        raise RigidfoldError(f"loads must be a list of load texts, got {loads!r}")
    texts: dict[str, Any] = {
        "supports": parse_supports(supports),
        "loads": tuple(parse_load(text) for text in loads),
        "limit": parse_limit(limit),
    }
    if material is not None:  # parsed by argparse already, or a text
        texts["material"] = material if isinstance(material, Material) else parse_material(material)
    return StructureOptions(
        **texts,
        clamped=parse_index_list(clamped, "clamped vertices"),
        candidates=parse_candidates(candidates),
        actuators=parse_index_list(actuators, "actuators"),
        **typed,
    )


def parse_index_list(text: str, what: str) -> tuple[int, ...]:
    """The integers of ``"3,7,12"`` (``""``: none), not yet checked against a design;
    ValueError naming ``what`` and the text for anything else, an empty item included
    (``"0,,1"``, ``"0,1,"``: a number left out is a slip, not nothing)."""
    if not isinstance(text, str):
        raise RigidfoldError(f"{what} must be comma-separated integers, got {text!r}")
    if not text.strip():
        return ()
    items = [t.strip() for t in text.split(",")]
    if not all(items):
        raise RigidfoldError(
            f"{what} must be comma-separated integers, got {text!r}: item "
            f"{items.index('') + 1} is empty"
        )
    try:
        return tuple(int(t) for t in items)
    except ValueError:
        raise RigidfoldError(f"{what} must be comma-separated integers, got {text!r}") from None


def parse_supports(text: str) -> SupportSpec:
    """``auto``, ``service`` or ``V,V,...`` (``""``: no pins) as its typed value; ValueError
    (one line, with the closest word for a misspelling) for anything else."""
    if not isinstance(text, str):
        raise RigidfoldError(
            f"supports must be auto, service or comma-separated vertex indices, got {text!r}"
        )
    word = text.strip().lower()
    if word == "auto":
        return Auto()
    if word == "service":
        return Service()
    if any(c.isalpha() for c in text):
        close = difflib.get_close_matches(word, CHOSEN_SUPPORTS, n=1)
        raise RigidfoldError(
            "supports must be auto, service or comma-separated vertex indices, got "
            f"{text!r}" + (f" (did you mean {close[0]}?)" if close else "")
        )
    values = parse_index_list(text, "supports")
    bad = [v for v in values if v < 0]
    if bad:
        raise RigidfoldError(f"supports: {bad[0]} is not a vertex index (got {text!r})")
    return Pins(values)


def parse_candidates(text: str | None) -> Candidates:
    """``--support-candidates``: None (boundary), ``"boundary"``, ``"ground"`` (any case) or
    ``"V,V,..."``; ValueError naming the text for anything else."""
    if text is None:
        return None
    if isinstance(text, str) and text.strip().lower() in CANDIDATE_WORDS:
        return "ground" if text.strip().lower() == "ground" else "boundary"
    return parse_index_list(text, "support candidates")


def parse_limit(text: str | float) -> float:
    """``"L/250"`` (or ``250``) as the divisor 250.0; ValueError naming what was received."""
    if isinstance(text, int | float) and not isinstance(text, bool):
        value = float(text)
    else:
        match = re.fullmatch(r"\s*(?:[lL]\s*/\s*)?([0-9.eE+-]+)\s*", str(text))
        try:
            value = float(match.group(1)) if match else float("nan")
        except ValueError:
            value = float("nan")
    if not (math.isfinite(value) and value > 0):
        raise RigidfoldError(
            f"the deflection limit must be L/N with N > 0 (e.g. L/250), got {text!r}"
        )
    return value


PRESSURE_UNITS = {"Pa": 1e-3, "kPa": 1.0, "kN/m2": 1.0, "MPa": 1e3}
"""A uniform load's or pressure's units in kPa (any case; ``kN/m^2`` too); a bare number is
kPa."""

FORCE_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}
"""A point load's units in newtons (any case); a bare number is newtons."""

_UNIT = re.compile(r"\s*([-+0-9.eE]+(?:[eE][-+]?\d+)?)\s*([a-zA-Z][a-zA-Z/^0-9]*)?\s*")


def parse_load(text: str) -> Load:
    """``uniform=Q``, ``pressure=Q`` (kPa, or with a unit: ``0.5kPa``, ``500Pa``) or
    ``point=V:FX,FY,FZ`` (newtons, or ``2kN``) (see the module's text); ValueError naming
    what was received for anything else."""
    if isinstance(text, str) and text.strip().lower() in ("self_weight", "self-weight"):
        return SelfWeight()
    if not isinstance(text, str) or "=" not in text:
        raise RigidfoldError(
            f"a load is uniform=KPA, pressure=KPA or point=V:FX,FY,FZ, got {text!r}"
        )
    kind, _, value = (s.strip() for s in text.partition("="))
    kind = kind.lower()
    if kind in ("uniform", "pressure"):
        kpa = _number(value, text, PRESSURE_UNITS)
        return Uniform(kpa) if kind == "uniform" else Pressure(kpa)
    if kind in ("self_weight", "self-weight"):
        if value:
            raise RigidfoldError(f"self-weight takes no value, got {text!r}")
        return SelfWeight()
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
        fx, fy, fz = (_number(p, text, FORCE_UNITS) for p in parts)
        return Point(v, (fx, fy, fz))
    raise RigidfoldError(
        f"unknown load kind {kind!r} in {text!r} (choose from {', '.join(LOAD_KINDS)})"
    )


def _number(value: str, text: str, units: dict[str, float]) -> float:
    """``value``, a number with an optional unit of ``units``, in the units' base."""
    match = _UNIT.fullmatch(value)
    known = {u.lower(): f for u, f in units.items()} | {"kn/m^2": units.get("kN/m2", 1.0)}
    unit = (match.group(2) or "").lower() if match else ""
    if match and unit and unit not in known:
        raise RigidfoldError(
            f"unknown unit {match.group(2)!r} in the load {text!r} (use "
            f"{', '.join(units)}, or a bare number)"
        )
    try:
        x = float(match.group(1)) * known.get(unit, 1.0) if match else math.nan
    except (ValueError, OverflowError):
        x = math.nan
    if not math.isfinite(x):
        raise RigidfoldError(f"a load's value must be a finite number, got {text!r}")
    return x
