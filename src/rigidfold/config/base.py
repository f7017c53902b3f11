"""The building blocks of :class:`rigidfold.config.Settings`: a documented field, the
frozen group it lives in, and the checks a group runs on its fields.

A group is a frozen dataclass of scalars. Each field is made by :func:`setting`, which
keeps its documentation beside its default (``field.metadata["doc"]``) and its *flat name*
(``field.metadata["flat"]``): the one name by which the field is known outside its group,
in ``Settings.with_(name=value)``, in error messages and in the configuration a study
stores. A field's flat name is the group's ``PREFIX`` followed by its name unless the field
gives its own.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from typing import Any, ClassVar, Self

from rigidfold.errors import RigidfoldError


def setting(default: Any, doc: str, *, flat: str | None = None) -> Any:
    """A field of a settings group: its default, what it means (units, where it acts) and,
    where it differs from the group's ``PREFIX`` + its name, its flat name."""
    return dataclasses.field(default=default, metadata={"doc": doc, "flat": flat})


class Group:
    """Base of the settings groups (frozen dataclasses of :func:`setting` fields)."""

    PREFIX: ClassVar[str] = ""
    """Prepended to a field's name to give its flat name (``"path_"``: ``path.tol`` is
    ``path_tol``)."""

    @classmethod
    def flat_names(cls) -> Iterator[tuple[str, str]]:
        """``(flat name, field name)`` of every field, in the order they are defined."""
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            yield f.metadata.get("flat") or cls.PREFIX + f.name, f.name

    @classmethod
    def docs(cls) -> dict[str, str]:
        """What every field means, by field name."""
        return {f.name: f.metadata.get("doc", "") for f in dataclasses.fields(cls)}  # type: ignore[arg-type]

    def with_(self, **changes: Any) -> Self:
        """A copy with some fields (by their names in the group) changed, checked again."""
        return dataclasses.replace(self, **changes)  # type: ignore[type-var]

    # ---- checks run by the groups' __post_init__; messages name the flat name ----

    def _flat(self, name: str) -> str:
        return dict((n, f) for f, n in self.flat_names())[name]

    def _positive(self, *names: str) -> None:
        """Each field a finite number > 0."""
        for name in names:
            value = getattr(self, name)
            if not (_number(value) and math.isfinite(value) and value > 0):
                raise RigidfoldError(f"{self._flat(name)} must be a positive number, got {value!r}")

    def _non_negative(self, *names: str) -> None:
        """Each field a finite number >= 0."""
        for name in names:
            value = getattr(self, name)
            if not (_number(value) and math.isfinite(value) and value >= 0):
                raise RigidfoldError(
                    f"{self._flat(name)} must be a finite number >= 0, got {value!r}"
                )

    def _fraction(self, *names: str, below_one: bool = False) -> None:
        """Each field a number from 0 to 1 (to below 1 with ``below_one``)."""
        for name in names:
            value = getattr(self, name)
            if not (_number(value) and 0 <= value and (value < 1 if below_one else value <= 1)):
                upper = "below 1" if below_one else "1"
                raise RigidfoldError(
                    f"{self._flat(name)} must be a fraction from 0 to {upper}, got {value!r}"
                )

    def _integer(self, **least: int) -> None:
        """Each named field an integer (not a bool) at least its given value."""
        for name, low in least.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise RigidfoldError(
                    f"{self._flat(name)} must be an integer >= {low}, got {value!r}"
                )

    def _boolean(self, *names: str) -> None:
        """Each field True or False."""
        for name in names:
            value = getattr(self, name)
            if not isinstance(value, bool):
                raise RigidfoldError(f"{self._flat(name)} must be true or false, got {value!r}")

    def _choice(self, name: str, choices: tuple[str, ...]) -> None:
        """The field one of ``choices``."""
        value = getattr(self, name)
        if value not in choices:
            raise RigidfoldError(
                f"{self._flat(name)} must be one of {', '.join(choices)}, got {value!r}"
            )


def _number(value: object) -> bool:
    return isinstance(value, float | int) and not isinstance(value, bool)
