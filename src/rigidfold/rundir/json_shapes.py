"""The shapes of JSON data and their check, for the files of a run directory.

A shape says what a value must be: ``int`` a whole number, ``float`` a finite number,
``str`` text, ``bool`` true or false, an :class:`~rigidfold.outcomes.Outcome` enum one of its
values, ``object`` anything, a list ``[S]`` a list of S, a tuple a list of that many items
of those shapes, a :class:`Record` an object, :class:`Nullable` also null.
:func:`check_shape` checks a value against one, so that a damaged file is a one-line error
naming the file and the key; :func:`shape_of` makes the shape of a record's field from its
type, :func:`record_shape` that of a whole record (a dataclass or a TypedDict) from its
fields: :data:`rigidfold.rundir.schema.LOG_SHAPE` of an attempt, ``SUMMARY_SHAPE`` of
summary.json.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import types
import typing
from dataclasses import dataclass
from typing import Annotated

from rigidfold.errors import RigidfoldError
from rigidfold.outcomes import Outcome


@dataclass(frozen=True)
class Nullable:
    """A shape (see the module's text) that may also be JSON ``null``."""

    shape: object


@dataclass(frozen=True)
class Record:
    """A JSON object whose keys, when present (``required``: always), have these shapes;
    other keys may hold anything."""

    keys: dict
    required: tuple[str, ...] = ()


def check_shape(
    value, shape, file: str | os.PathLike, where: str = "", *, line: int | None = None
) -> None:
    """ValueError naming ``file`` (and its ``line``, for a file of JSON lines) and the key
    (``per_solution[0].development.D``) of the first part of ``value`` (JSON data) that does
    not have ``shape`` (the module's text says how shapes are written), and what it holds
    instead."""
    label = f"'{file}'" + ("" if line is None else f", line {line}")
    whole = "the document" if line is None else "the line"
    stack = [(value, shape, where)]
    while stack:
        value, given, where = stack.pop()
        shape = given.shape if isinstance(given, Nullable) else given
        if value is None and shape is not given:
            continue
        if not _has_shape(value, shape):
            key = f"{where!r}" if where else whole
            raise RigidfoldError(
                f"{label}: {key} is {received(value)}, expected {_expected(given)}"
            )
        if isinstance(shape, Record):
            missing = [k for k in shape.required if k not in value]
            if missing:
                key = f"{where!r}" if where else whole
                raise RigidfoldError(f"{label}: {key} has no {', '.join(map(repr, missing))}")
            stack += [
                (value[k], s, f"{where}.{k}" if where else k)
                for k, s in reversed(shape.keys.items())
                if k in value
            ]
        elif isinstance(shape, list):
            stack += [(v, shape[0], f"{where}[{i}]") for i, v in reversed(list(enumerate(value)))]
        elif isinstance(shape, tuple):
            stack += [
                (v, s, f"{where}[{i}]") for i, (v, s) in enumerate(zip(value, shape, strict=True))
            ]


def _has_shape(value, shape) -> bool:
    """Whether ``value`` is of the kind of ``shape`` (its items are checked apart)."""
    if shape is object:
        return True
    if isinstance(shape, type) and issubclass(shape, Outcome):
        return isinstance(value, str) and value in list(shape)
    if shape is bool:
        return isinstance(value, bool)
    if shape is int:  # within int64: numpy and matplotlib take it
        return isinstance(value, int) and not isinstance(value, bool) and abs(value) < 2**63
    if shape is float:
        if not isinstance(value, int | float) or isinstance(value, bool):
            return False
        try:
            return math.isfinite(value)
        except OverflowError:  # an integer beyond the floats
            return False
    if shape is str:
        return isinstance(value, str)
    if isinstance(shape, Record):
        return isinstance(value, dict)
    if isinstance(shape, tuple):
        return isinstance(value, list) and len(value) == len(shape)
    return isinstance(value, list)


def _expected(shape) -> str:
    if isinstance(shape, Nullable):
        return f"{_expected(shape.shape)} or null"
    words = {
        bool: "true or false",
        int: "a whole number (64 bits)",
        float: "a finite number",
        str: "text",
    }
    if isinstance(shape, type) and issubclass(shape, Outcome):
        return f"one of {', '.join(shape)}"
    if isinstance(shape, type):
        return words[shape]
    if isinstance(shape, Record):
        return "an object"
    if isinstance(shape, tuple):
        return f"a list of {len(shape)} items"
    return "a list"


def received(value) -> str:
    """``value`` as JSON text, cut to 40 characters."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 40 else text[:39] + "…"


Finite = Annotated[float, float]
"""The type of a field (or an item of one) that is a finite number, never null: of the shape
``float`` (:func:`shape_of`), where a plain ``float`` may be null (a NaN is written as
null). ``Annotated[T, shape]`` gives any type its shape this way."""


def shape_of(hint: object) -> object:
    """The shape (see the module's text) of the JSON that a field of type ``hint`` is
    written as: an int, str or bool itself, an :class:`~rigidfold.outcomes.Outcome` enum
    one of its values, a float a finite number or null (a NaN is written as null;
    :data:`Finite`: never null), a list or a tuple of one kind a list of its shape, a tuple
    of fixed length a list of that many items, a dict an object, a dataclass or a TypedDict
    the object of its fields (:func:`record_shape`), ``X | None`` also null,
    ``Annotated[X, shape]`` that shape, ``Annotated[dict | None, R]`` (R a TypedDict or a
    dataclass: what is read of the dict) the object of R's fields, also null; another type
    anything."""
    if typing.get_origin(hint) is Annotated:
        base, given = typing.get_args(hint)[:2]
        if _is_record(given):  # the record's object for the base type's dict
            record = record_shape(given)
            return Nullable(record) if isinstance(shape_of(base), Nullable) else record
        return given
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        kinds = [a for a in args if a is not type(None)]
        inner = shape_of(kinds[0]) if len(kinds) == 1 else object
        return inner if isinstance(inner, Nullable) or inner is object else Nullable(inner)
    if origin is tuple and args and Ellipsis not in args:
        return tuple(shape_of(a) for a in args)
    if origin in (list, tuple) and args:
        return [shape_of(args[0])]
    if hint is float:
        return Nullable(float)
    if hint is dict or origin is dict:
        return Record({})
    if hint in (int, str, bool) or (isinstance(hint, type) and issubclass(hint, Outcome)):
        return hint
    if _is_record(hint):
        return record_shape(typing.cast(type, hint))
    return object


def _is_record(hint: object) -> bool:
    """Whether ``hint`` is a dataclass or a TypedDict (a type, not an instance)."""
    return isinstance(hint, type) and (typing.is_typeddict(hint) or dataclasses.is_dataclass(hint))


def record_shape(record: type, *, null_is_default: bool = False) -> Record:
    """The shape of the JSON object that ``record``, a dataclass or a TypedDict, is written
    as: each field under its own name, of the shape of its type (:func:`shape_of`; say
    ``Annotated[T, shape]`` for another); required: a dataclass's fields
    without a default, a TypedDict's required keys. ``null_is_default``: a field with a
    default may also be null (the record's reader takes the default for it)."""
    hints = typing.get_type_hints(record, include_extras=True)
    if typing.is_typeddict(record):
        required = record.__required_keys__  # type: ignore[attr-defined]
        return Record(
            {k: shape_of(h) for k, h in hints.items()}, tuple(k for k in hints if k in required)
        )
    keys: dict = {}
    needed: list[str] = []
    missing = dataclasses.MISSING
    for f in dataclasses.fields(record):
        shape = shape_of(hints[f.name])
        if f.default is missing and f.default_factory is missing:
            needed.append(f.name)
        elif null_is_default and not isinstance(shape, Nullable) and shape is not object:
            shape = Nullable(shape)
        keys[f.name] = shape
    return Record(keys, tuple(needed))
