"""The shapes of JSON data and their check, for the files of a run directory.

A shape says what a value must be: ``int`` a whole number, ``float`` a finite number,
``str`` text, ``bool`` true or false, an :class:`~rigidfold.outcomes.Outcome` enum one of its
values, ``object`` anything, a list ``[S]`` a list of S, a tuple a list of that many items
of those shapes, a :class:`Record` an object, :class:`Nullable` also null.
:func:`check_shape` checks a value against one, so that a damaged file is a one-line error
naming the file and the key; :func:`shape_of` makes the shape of a record's field from its
type (:data:`rigidfold.rundir.schema.LOG_SHAPE`).
"""

from __future__ import annotations

import json
import math
import os
import types
import typing
from dataclasses import dataclass

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


def shape_of(hint: object) -> object:
    """The shape (see the module's text) of the JSON that a field of type ``hint`` is
    written as: an int, str or bool itself, an :class:`~rigidfold.outcomes.Outcome` enum
    one of its values, a float a finite number or null (a NaN is written as null), a list
    or a tuple of one kind a list of its shape, a dict an object, ``X | None`` also null;
    another type anything."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        kinds = [a for a in args if a is not type(None)]
        inner = shape_of(kinds[0]) if len(kinds) == 1 else object
        return inner if isinstance(inner, Nullable) or inner is object else Nullable(inner)
    if origin in (list, tuple) and args:
        return [shape_of(args[0])]
    if hint is float:
        return Nullable(float)
    if hint is dict or origin is dict:
        return Record({})
    if hint in (int, str, bool) or (isinstance(hint, type) and issubclass(hint, Outcome)):
        return hint
    return object
