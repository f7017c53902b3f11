"""A field of an options record, with its documentation and how the command line gives it.

An options record (:class:`rigidfold.generate.GenerateOptions`,
:class:`rigidfold.generate.case_options.CaseOptions`) is a frozen dataclass whose fields are made by
:func:`option`: the default, what the value means (``field.metadata["doc"]``, which is also
the command-line help) and, unless ``flag=False``, a :class:`Flag` (``field.metadata
["flag"]``) from which :mod:`rigidfold.cli.parser` makes the argument: so a documented field
is all it takes to add an option to the library and a flag to the commands that take the
record.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any


@dataclasses.dataclass(frozen=True)
class Flag:
    """How the command line gives a field.

    name : the flag (default: ``--`` and the field's name with dashes; a bool whose default
        is True is turned off by ``--no-`` and that name).
    parse : how the command line reads the text: the name of one of its parsers (a key of
        ``rigidfold.cli.units.PARSERS``: ``"thickness"``, ``"material"``, ``"seed"``, ...),
        or ``int`` / ``float``; default: the text. The record itself holds typed values.
        A field whose default is a member of an ``enum.Enum`` is read as one of its values.
    metavar, choices : as argparse's.
    shown : the default as the help says it, where that is not the value itself: for a
        default of None what None means, else the default as text (``""`` is ``"none"``);
        one that is not text or a number, as text that ``parse`` reads back (a pair
        ``(2440.0, 1220.0)`` is ``"2440x1220"``).
    switch : a bool's help before its doc, where that is not "turn on" (or "turn off" for a
        bool on by default): ``"leave out"``, or ``""`` for a doc that reads as the help.
    repeat : the flag may be given more than once, its values a list (none by default).
    """

    name: str | None = None
    parse: str | Callable[[str], Any] | None = None
    metavar: str | None = None
    choices: tuple[str, ...] | None = None
    shown: str | None = None
    switch: str | None = None
    repeat: bool = False


def option(default: Any, doc: str, *, flag: bool = True, **how: Any) -> Any:
    """A field of an options record: its default (``dataclasses.MISSING``: none, a required
    field and flag), what it means (a phrase that reads as the command-line help too: a bool's
    says what it turns on) and, unless ``flag=False``, how the command line gives it
    (:class:`Flag`'s ``name``, ``parse``, ``metavar``, ``choices``, ``shown``, ``switch``,
    ``repeat``)."""
    return dataclasses.field(
        default=default, metadata={"doc": doc, "flag": Flag(**how) if flag else None}
    )


def docs(record: type) -> dict[str, str]:
    """What every field of an options record means, by field name."""
    return {f.name: f.metadata.get("doc", "") for f in dataclasses.fields(record)}
