"""The argparse side of the command line: arguments made from the fields of options records,
one-line errors with the nearest name, and the text of a flag to its value.

:func:`add_options` adds a flag for every field of an options record that has a
:class:`rigidfold.flags.Flag` (made by :func:`rigidfold.flags.option`), its help the field's
documentation, its default the record's; :func:`options_of` makes the record of the parsed
arguments. So a documented field of a record is a flag of every command that takes it.
"""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import enum
import re
import unicodedata
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from rigidfold.cli.units import parser_of
from rigidfold.errors import RigidfoldError
from rigidfold.flags import Flag

EXIT_USAGE = 2


def add_options(
    parser: argparse.ArgumentParser,
    record: type,
    *,
    defaults: Any = None,
    only: Sequence[str] | None = None,
    exclude: Sequence[str] = (),
    prefix: str = "",
    shown: Mapping[str, str] | None = None,
) -> None:
    """A flag on ``parser`` for each field of the options record ``record`` that has one
    (those named in ``only``, where given, but not those in ``exclude``), with the defaults of
    ``defaults`` (default: the record's): another record, or a mapping of field names to the
    defaults that differ (None: the command fills the value in). A bool is a switch:
    ``--NAME`` turns it on, ``--no-NAME`` off where it is on by default, its help ``prefix``,
    its flag's ``switch`` ("turn on", "turn off") and the field's doc. Any other field takes a
    value, parsed by its flag's ``parse`` (each of a ``repeat`` flag's, into a list); a field
    without a default is required. Its help is ``prefix`` and the field's doc, ended by its
    default: ``shown[name]`` where given, else its flag's ``shown``, else the value unless
    None or a repeat flag's. A shown default that is not text or a number (a pair, a typed
    choice) is given to argparse as its shown text (``2440x1220``, ``auto``), which the
    flag's ``parse`` reads as the command line's. ``parse`` names a parser of
    :mod:`rigidfold.cli.units`; a field whose default is an enum's member is read as one of
    its values (the flag's ``choices``)."""
    for f in dataclasses.fields(record):
        flag: Flag | None = f.metadata.get("flag")
        if flag is None or (only is not None and f.name not in only) or f.name in exclude:
            continue
        if isinstance(defaults, Mapping):
            default = defaults.get(f.name, f.default)
        else:
            default = f.default if defaults is None else getattr(defaults, f.name)
        doc = prefix + f.metadata["doc"]
        dashed = f.name.replace("_", "-")
        if isinstance(default, bool):
            on = "--no-" if default else "--"
            switch = f"turn {'off' if default else 'on'}" if flag.switch is None else flag.switch
            parser.add_argument(
                flag.name or on + dashed,
                dest=f.name,
                action="store_false" if default else "store_true",
                default=default,
                help=prefix + (switch + " " if switch else "") + f.metadata["doc"],
            )
            continue
        required = default is dataclasses.MISSING
        said = (shown or {}).get(f.name, flag.shown)
        end = ""
        if said is not None and not required:
            end = f" (default: {said})"
        elif not (required or default is None or flag.repeat):
            end = " (default: %(default)s)"
        if said is not None and not (required or isinstance(default, str | int | float | None)):
            default = said  # the default's text, parsed as the flag's (argparse does)
        how: dict[str, Any] = {"required": True} if required else {"default": default}
        if flag.repeat:
            how |= {"action": "append", "default": None}  # None: the record's default
        if flag.parse is not None:
            how["type"] = argument_type(parser_of(flag.parse))
        elif isinstance(default, enum.Enum):
            how["type"] = _member(type(default))
        parser.add_argument(
            flag.name or "--" + dashed,
            dest=f.name,
            choices=flag.choices,
            metavar=flag.metavar,
            help=doc + end,
            **how,
        )


def options_of(
    record: type,
    args: argparse.Namespace,
    *,
    make: Callable[..., Any] | None = None,
    **given: Any,
) -> Any:
    """The options record ``record`` of the parsed ``args`` (the fields that have a flag
    there; None where the record's default is not: not given, the record's default) and
    ``given``, made by ``make`` (default: the record; a reader of the command line's texts
    where some are not yet typed, such as
    :func:`rigidfold.cli.structure_specs.read_structure_options`); checked by the record."""
    flagged = {
        f.name: getattr(args, f.name)
        for f in dataclasses.fields(record)
        if f.metadata.get("flag") is not None
        and hasattr(args, f.name)
        and (getattr(args, f.name) is not None or f.default is None)
    }
    return (record if make is None else make)(**flagged | given)


def argument_type(parse: Callable[[str], Any]) -> Callable[[str], Any]:
    """``parse`` as an argparse type: its RigidfoldError is argparse's one-line error
    ("argument --seed: must be ...")."""
    if parse in (int, float, str):
        return parse

    def convert(text: str) -> Any:
        try:
            return parse(text)
        except RigidfoldError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    return convert


def _member(kind: type[enum.Enum]) -> Callable[[str], Any]:
    """argparse type of a field whose values are an enum's: the member of the text's value,
    other text as it is (for argparse's "invalid choice" of the flag's choices)."""
    values = {m.value: m for m in kind}

    def convert(text: str) -> Any:
        return values.get(text, text)

    return convert


def directory(text: str) -> str:
    """An output directory: any name but the empty one (which would mean the current
    directory)."""
    if not text:
        raise argparse.ArgumentTypeError("an empty directory name; name the directory, e.g. .")
    return text


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) and exit code 2; a misspelt choice,
    command or option gets the nearest one ("did you mean 'generate'?", "did you mean
    --target-dof?"). Remembers its long options and its commands for that."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.long_options: list[str] = []  # before argparse adds --help
        self.commands: dict[str, Parser] = {}
        super().__init__(*args, **kwargs)

    def add_argument(self, *names: str, **kwargs: Any) -> Any:
        self.long_options += [n for n in names if n.startswith("--")]
        return super().add_argument(*names, **kwargs)

    def add_command(self, sub: Any, name: str, **text: str) -> Parser:
        """The parser of the command ``name``, added to ``sub`` (of add_subparsers)."""
        parser = sub.add_parser(name, **text)
        self.commands[name] = parser
        return parser

    def either(self, *arguments: tuple[tuple[str, ...], dict]) -> None:
        """Options of which at most one may be given: ``((names...), add_argument's
        keywords)`` each."""
        group = self.add_mutually_exclusive_group()
        for names, kwargs in arguments:
            self.long_options += [n for n in names if n.startswith("--")]
            group.add_argument(*names, **kwargs)

    def error(self, message: str):
        choice = _INVALID_CHOICE.search(message)
        if choice is not None:
            near = nearest(choice[1], re.findall(r"'([^']*)'", choice[2]))
            message += f" (did you mean '{near}'?)" if near else ""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {one_line(message)}\n")

    def refuse_unknown_options(self, argv: Sequence[str]) -> None:
        """Refuse, through the command's parser, the first ``--option`` of ``argv`` that
        the command does not know (nor abbreviates), naming the nearest option it has; before
        argparse's own checks, so that a misspelt required option is called misspelt rather
        than missing."""
        at = next((k for k, a in enumerate(argv) if not a.startswith("-")), None)
        sub = self.commands.get(argv[at]) if at is not None else None
        if at is None or sub is None:
            return
        known = sub.long_options
        for arg in argv[at + 1 :]:  # those before the command are the program's (--verbose)
            if arg == "--":
                return
            name = arg.partition("=")[0]
            if not name.startswith("--") or any(o.startswith(name) for o in known):
                continue
            near = nearest(name, known)
            sub.error(
                f"unrecognized arguments: {arg}" + (f" (did you mean {near}?)" if near else "")
            )


_INVALID_CHOICE = re.compile(r"invalid choice: '(.*)' \(choose from (.*)\)$")


def nearest(word: str, names: Sequence[str]) -> str | None:
    """The name of ``names`` nearest to a misspelt ``word``; None when none is near."""
    near = difflib.get_close_matches(word, names, n=1, cutoff=0.6)
    return near[0] if near else None


_ESCAPES = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def one_line(text: str) -> str:
    """``text`` with its control characters escaped as Python writes them in strings (a
    newline as ``\\n``, ESC as ``\\x1b``, U+2028 as ``\\u2028``), so that a message that
    carries a file name or a value read from a file prints as one line and cannot move the
    cursor, clear the screen or retitle the terminal. Backslashes are kept as they are."""
    out = []
    for ch in text:
        if unicodedata.category(ch) in ("Cc", "Zl", "Zp"):
            ch = _ESCAPES.get(ch) or ascii(ch)[1:-1]
        out.append(ch)
    return "".join(out)


def attached_values(argv: Sequence[str]) -> list[str]:
    """``argv`` with ``--expr VALUE`` written ``--expr=VALUE``, so that an expression that
    starts with '-' (``--expr -x*y``) is read as the value, not as an option."""
    out: list[str] = []
    args = iter(argv)
    for arg in args:
        if arg == "--":
            out += [arg, *args]
            break
        value = next(args, None) if arg == "--expr" else None
        out.append(arg if value is None else f"{arg}={value}")
    return out
