"""The user's text to typed values: every parser of the command line's values but the
structure check's (:mod:`rigidfold.cli.structure_specs`).

Lengths with a unit (``18mm``) to metres, materials (a preset's name or ``E,nu,density``) to a
:class:`~rigidfold.material.Material`, seeds, counts and fractions, index lists
(``--fixed 3,7``), stock sheet sizes (``2440x1220``), export format lists and the drive's
specs (``--base panel:P``, ``--cable V,W``, ``--point-mass V:KG``). Each raises a
:class:`~rigidfold.errors.RigidfoldError` (one line, naming what was received), which
:func:`rigidfold.cli.parser.argument_type` turns into argparse's error.

A field of an options record names its parser here by a key of :data:`PARSERS` (its flag's
``parse``, :func:`rigidfold.flags.option`): the library keeps typed values, the command line
reads them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

from rigidfold.config import DEFAULTS, Settings, check_seed
from rigidfold.errors import RigidfoldError
from rigidfold.exports import check_formats
from rigidfold.material import MATERIALS, Material

# ---- numbers ---------------------------------------------------------------------------


def count(text: str) -> int:
    """An integer >= 0."""
    value = _integer(text)
    if value < 0:
        raise RigidfoldError(f"must be an integer >= 0, got {text!r}")
    return value


def seed(text: str) -> int:
    """A seed: an integer from 0 to below 2**63."""
    return check_seed(_integer(text))


def positive(text: str) -> float:
    """A finite number > 0."""
    value = _number(text)
    if not (math.isfinite(value) and value > 0):
        raise RigidfoldError(f"must be a positive number, got {text!r}")
    return value


def fraction(text: str) -> float:
    """A number from 0 to below 1."""
    value = _number(text)
    if not 0 <= value < 1:
        raise RigidfoldError(f"must be a number from 0 to below 1, got {text!r}")
    return value


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise RigidfoldError(f"invalid int value: {text!r}") from None


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def angles(text: str) -> tuple[float, ...]:
    """Comma-separated angles in degrees, each in (0, 180); "0": none."""
    if text.strip() == "0":
        return ()
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise RigidfoldError(
            f"must be angles in degrees separated by commas, got {text!r}"
        ) from None
    if not all(0 < a < 180 for a in values):
        raise RigidfoldError(f"each angle must lie in (0, 180) degrees, got {text!r}")
    return values


# ---- lengths, sheets, materials --------------------------------------------------------

_UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}


def parse_length(text: str, what: str = "thickness") -> float:
    """A length in metres from ``"0.018"``, ``"18mm"``, ``"1.8cm"`` or ``"0.018m"``. Raises
    RigidfoldError naming ``what`` and the text for anything else, or a length that is not
    positive and finite."""
    raw = str(text).strip().lower()
    scale = 1.0
    for unit in ("mm", "cm", "m"):
        if raw.endswith(unit):
            raw, scale = raw[: -len(unit)].strip(), _UNITS[unit]
            break
    try:
        value = float(raw) * scale
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise RigidfoldError(
            f"{what} must be a positive length in metres or with a unit (18mm, 1.8cm, "
            f"0.018), got {text!r}"
        )
    return value


def parse_sheet(text: str, *, settings: Settings = DEFAULTS) -> tuple[float, float]:
    """(width, height) in mm from ``"2440x1220"``, each at most
    ``settings.limits.max_sheet_size`` (:func:`rigidfold.fabricate.build.check_sheet`).
    Raises RigidfoldError naming what was received."""
    from rigidfold.fabricate.build import check_sheet

    try:
        w, h = (float(x) for x in str(text).lower().replace(" ", "").split("x"))
    except ValueError:
        w = h = math.nan
    if not all(math.isfinite(x) and x > 0 for x in (w, h)):
        raise RigidfoldError(f"sheet must be WIDTHxHEIGHT in millimetres (2440x1220), got {text!r}")
    return check_sheet((w, h), settings=settings, shown=text)


def parse_material(text: str) -> Material:
    """A preset's name (:data:`~rigidfold.material.MATERIALS`, case and blanks ignored;
    ``aluminum`` is ``aluminium``) or ``"E,nu,density"`` in SI units (Pa, -, kg/m^3).
    RigidfoldError (one line, naming what was received) for anything else."""
    key = text.strip().lower()
    if key in MATERIALS:
        return MATERIALS[key]
    if key == "aluminum":
        return MATERIALS["aluminium"]
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 3:
        raise RigidfoldError(
            f"material must be one of {', '.join(MATERIALS)} or 'E,nu,density' in SI units "
            f"(e.g. 10e9,0.3,700), got {text!r}"
        )
    try:
        E, nu, density = (float(p) for p in parts)
    except ValueError:
        raise RigidfoldError(
            f"material 'E,nu,density' must be three numbers, got {text!r}"
        ) from None
    return Material(E, nu, density)


# ---- index lists and format lists ------------------------------------------------------


def parse_fixed(text: str) -> tuple[int, ...]:
    """``"I,J,..."``: the indices of crease lines (``optimize --fixed``), blanks skipped;
    checked against a pattern by :func:`rigidfold.generate.case.fixed_mask`."""
    indices = []
    for token in text.split(","):
        token = token.strip()
        if not token:
            continue
        try:
            indices.append(int(token))
        except ValueError:
            raise RigidfoldError(
                f"--fixed expects comma-separated edge indices, got {token!r}"
            ) from None
    return tuple(indices)


def parse_formats(text: str) -> tuple[str, ...]:
    """``"obj,dxf"`` (case and blanks ignored): the export formats asked for, checked, in
    :data:`~rigidfold.exports.EXPORT_FORMATS` order without repeats
    (:func:`rigidfold.exports.check_formats`)."""
    return check_formats([name.strip().lower() for name in text.split(",")])


# ---- the drive's specs -----------------------------------------------------------------


def parse_base(text: str) -> int | str:
    """``"auto"``, ``"panel:P"`` or ``"P"`` (a panel's index, >= 0): the drive's base
    (:data:`rigidfold.drive.Base`)."""
    from rigidfold.drive.options import AUTO

    raw = text.strip().lower()
    if raw == AUTO:
        return AUTO
    try:
        value = int(raw.removeprefix("panel:").strip())
    except ValueError:
        raise RigidfoldError(f"base must be auto or panel:P, got {text!r}") from None
    if value < 0:
        raise RigidfoldError(f"base must be auto or panel:P with P >= 0, got {text!r}")
    return value


def parse_cable(text: str) -> tuple[int, int]:
    """``"V,W"`` (or ``"V-W"``): a cable between two different vertices ``(V, W)``."""
    parts = [p.strip() for p in text.replace("-", ",").split(",")]
    try:
        if len(parts) != 2:
            raise ValueError
        v, w = (int(p) for p in parts)
    except ValueError:
        raise RigidfoldError(f"a cable is V,W (two vertices), got {text!r}") from None
    if v < 0 or w < 0 or v == w:
        raise RigidfoldError(f"a cable joins two different vertices >= 0, got {text!r}")
    return v, w


def parse_point_mass(text: str) -> tuple[int, float]:
    """``"V:KG"``: a point mass ``(vertex, kg)``, kg finite and >= 0."""
    vertex, sep, kg = text.partition(":")
    if not sep:
        raise RigidfoldError(f"a point mass is V:KG, got {text!r}")
    try:
        v, m = int(vertex.strip()), float(kg.strip())
    except ValueError:
        raise RigidfoldError(f"a point mass is V:KG, got {text!r}") from None
    if v < 0 or not (math.isfinite(m) and m >= 0):
        raise RigidfoldError(f"a point mass is V:KG with V >= 0 and KG >= 0, got {text!r}")
    return v, m


def _drive_number(what: str, unit: str, *, positive: bool = False) -> Callable[[str], float]:
    """A number of the drive's options: finite and >= 0 (``positive``: > 0)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise RigidfoldError(f"{what} must be a number ({unit}), got {text!r}") from None
        if not (math.isfinite(value) and value >= 0):
            raise RigidfoldError(f"{what} must be a finite number >= 0 ({unit}), got {value!r}")
        if positive and value <= 0:
            raise RigidfoldError(f"{what} must be positive ({unit}), got {text!r}")
        return value

    return parse


def parse_ground(text: str) -> float:
    """The drive's ground: a finite height in metres."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise RigidfoldError(f"ground must be a height in metres, got {text!r}") from None
    if not math.isfinite(value):
        raise RigidfoldError(f"ground must be a finite height in metres, got {text!r}")
    return value


PARSERS: dict[str, Callable[[str], Any]] = {
    "count": count,
    "seed": seed,
    "positive": positive,
    "fraction": fraction,
    "angles": angles,
    "thickness": partial(parse_length, what="thickness"),
    "min-thickness": partial(parse_length, what="min-thickness"),
    "sheet": parse_sheet,
    "material": parse_material,
    "base": parse_base,
    "cable": parse_cable,
    "point-mass": parse_point_mass,
    "ground": parse_ground,
    "density": _drive_number("density", "kg/m^3", positive=True),
    "hinge-stiffness": _drive_number("hinge stiffness", "N m/rad per m"),
    "friction": _drive_number("friction", "N m per m"),
    "hardware": _drive_number("hardware", "kg/m"),
    "max-torque": _drive_number("max torque", "N m", positive=True),
    "max-tension": _drive_number("max tension", "N", positive=True),
}
"""The parsers an options record's flag names (``Flag.parse``, a key here), by key."""


def parser_of(parse: str | Callable[[str], Any]) -> Callable[[str], Any]:
    """The parser a flag names: a key of :data:`PARSERS`, or a callable (``int``, ``float``)."""
    if not isinstance(parse, str):
        return parse
    if parse not in PARSERS:
        raise KeyError(f"no parser of the command line named {parse!r} (rigidfold.cli.units)")
    return PARSERS[parse]
