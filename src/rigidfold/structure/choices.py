"""The typed values of the structure check's options: the supports (:data:`SupportSpec`:
:class:`Auto`, :class:`Service` or :class:`Pins`), the vertices ``auto`` may choose
(:data:`Candidates`) and lists of indices (:func:`index_tuple`); the loads are
:data:`rigidfold.structure.loads.Load`.

The command line's texts (``--supports auto``, ``--clamped 0,6``) are read into them by
:mod:`rigidfold.cli.structure_specs`; each value's ``text`` gives the option back. Here they
are only checked for their types (ValueError, one line, naming what was received); the
indices against a design by :func:`rigidfold.structure.supports.index_array`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from rigidfold.errors import RigidfoldError

CHOSEN_SUPPORTS = ("auto", "service")
"""The words ``--supports`` takes besides a list of vertices."""

CANDIDATE_WORDS = ("boundary", "ground")
"""The words ``--support-candidates`` takes besides a list of vertices."""


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

Candidates = Literal["boundary", "ground"] | tuple[int, ...] | None
"""The vertices ``auto`` may choose: None or ``"boundary"`` (every boundary vertex),
``"ground"`` (the boundary vertices at the lowest height) or the vertices' indices."""


def index_tuple(values: object, what: str) -> tuple[int, ...]:
    """``values``, a sequence of integers (indices, not yet checked against a design), as a
    tuple of ints; ValueError naming ``what`` and the value for anything else."""
    if isinstance(values, str | bytes) or not isinstance(values, tuple | list | np.ndarray):
        raise RigidfoldError(f"{what} must be a tuple of integer indices, got {values!r}")
    if not all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in values):
        raise RigidfoldError(f"{what} must be integer indices, got {values!r}")
    return tuple(int(v) for v in values)


def check_candidates(value: object) -> Candidates:
    """``value`` as :data:`Candidates`; ValueError naming it for anything else."""
    if value is None or value in CANDIDATE_WORDS:
        return value  # type: ignore[return-value]
    if isinstance(value, str):
        raise RigidfoldError(
            f"support candidates must be {' or '.join(CANDIDATE_WORDS)} or a tuple of vertex "
            f"indices, got {value!r}"
        )
    return index_tuple(value, "support candidates")


def indices_text(values: tuple[int, ...]) -> str:
    """``(3, 7, 12)`` as the command line gives it, ``"3,7,12"`` (``""``: none)."""
    return ",".join(map(str, values))
