"""The typed values of the structure check's options that the command line gives as text:
the supports (:data:`SupportSpec`: :class:`Auto`, :class:`Service` or :class:`Pins`) and the
deflection limit (:class:`Limit`); the loads are :data:`rigidfold.structure.loads.Load`.

:func:`parse_supports` and :meth:`Limit.parse` read ``--supports`` and ``--limit`` once
(ValueError, one line, naming what was received); each value's ``text`` gives the option
back.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.structure.check import parse_limit
from rigidfold.structure.supports import index_list

CHOSEN_SUPPORTS = ("auto", "service")
"""The words ``--supports`` takes besides a list of vertices."""


@dataclass(frozen=True)
class Auto:
    """The fewest candidate vertices pinned that make the design first-order rigid."""

    @property
    def text(self) -> str:
        return "auto"


@dataclass(frozen=True)
class Service:
    """``Auto``'s pins, then more where the design deflects most until the deflection limit
    is met (:mod:`rigidfold.structure.service`)."""

    @property
    def text(self) -> str:
        return "service"


@dataclass(frozen=True)
class Pins:
    """Pinned vertices, ``vertices`` a sorted tuple of distinct indices >= 0 (none: only
    clamped vertices hold the design)."""

    vertices: tuple[int, ...] = field(default=())

    def __post_init__(self) -> None:
        values = self.vertices
        if isinstance(values, str) or not all(
            isinstance(v, int | np.integer) and not isinstance(v, bool) for v in values
        ):
            raise RigidfoldError(f"pins must be vertex indices, got {values!r}")
        if any(v < 0 for v in values):
            raise RigidfoldError(f"pins must be vertex indices >= 0, got {list(values)}")
        object.__setattr__(self, "vertices", tuple(sorted({int(v) for v in values})))

    @property
    def text(self) -> str:
        return ",".join(map(str, self.vertices))


SupportSpec = Auto | Service | Pins
"""How the supports come: chosen (:class:`Auto`, :class:`Service`) or given
(:class:`Pins`)."""

SUPPORT_TYPES = (Auto, Service, Pins)


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
    values = index_list(text, "supports")
    bad = [v for v in values if v < 0]
    if bad:
        raise RigidfoldError(f"supports: {bad[0]} is not a vertex index (got {text!r})")
    return Pins(tuple(values))


@dataclass(frozen=True)
class Limit:
    """The serviceability limit: the largest displacement at most span / ``divisor``."""

    divisor: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "divisor", parse_limit(self.divisor))

    @classmethod
    def parse(cls, text: str | float) -> Limit:
        """``"L/250"`` (or ``250``); ValueError naming what was received."""
        return cls(parse_limit(text))

    @property
    def text(self) -> str:
        return f"L/{self.divisor:g}"
