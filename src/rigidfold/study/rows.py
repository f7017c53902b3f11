"""The records of a study database and its tables, derived from them.

A run's row is a :class:`RunRow` (its :class:`Key` first), a solve's row a
:class:`rigidfold.generate.Attempt` (``index`` stored as ``idx``, ``F`` as ``f``), both
after the run's key: the ``runs`` and ``attempts`` tables of :data:`SCHEMA` are made from
these records' fields and types (:func:`table`), not listed by hand, so a field added to a
record is a column of the next database made (and an older database lacks it: raise
:data:`rigidfold.study.store.STUDY_SCHEMA_VERSION`).
"""

from __future__ import annotations

import enum
import sqlite3
import types
import typing
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

from rigidfold.generate import Attempt, Stop

if TYPE_CHECKING:
    from rigidfold.rundir import RunSummary


@dataclass(frozen=True)
class Key:
    """Identifies one run: (study, seed, pattern, criterion, symmetric)."""

    study: str
    seed: int
    pattern: str
    criterion: str
    symmetric: bool = False

    def row(self) -> tuple:
        return (self.study, self.seed, self.pattern, self.criterion, int(self.symmetric))


KEY_COLUMNS = tuple(f.name for f in fields(Key))
"""The columns of a run's :class:`Key`, first in ``runs`` and ``attempts``."""

ATTEMPT_NAMES = {"index": "idx", "F": "f"}
"""The columns of the :class:`~rigidfold.generate.Attempt` fields whose names SQL does not
take (``index`` is a keyword, and ``F`` is ``f``, SQL's names being of any case)."""


def column_type(hint: object) -> tuple[str, bool, bool]:
    """(SQL type, whether it may be NULL, whether it holds JSON text) of a field of type
    ``hint``: a bool or int INTEGER, a float REAL, a str or an enum of str TEXT, anything
    else (a list, a tuple, a dict) JSON in TEXT; it may be NULL where the type admits None."""
    union = typing.get_origin(hint) in (typing.Union, types.UnionType)
    args = typing.get_args(hint) if union else (hint,)
    kinds = [a for a in args if a is not type(None)]
    base = kinds[0] if len(kinds) == 1 else object
    nullable = len(kinds) < len(args)
    if base is bool or base is int:
        return "INTEGER", nullable, False
    if base is float:
        return "REAL", nullable, False
    if isinstance(base, type) and (issubclass(base, str) or issubclass(base, enum.Enum)):
        return "TEXT", nullable, False
    return "TEXT", nullable, True


def table(
    name: str, record: type, key: tuple[str, ...], *, renamed: dict[str, str] | None = None
) -> str:
    """``CREATE TABLE`` of ``name``: the fields of :class:`Key` that the dataclass
    ``record`` lacks, then its fields (named as ``renamed`` says), typed by
    :func:`column_type`; a key column, and a text or JSON column whose field admits no None,
    NOT NULL (a number may be NULL: SQLite stores a NaN as NULL). Its primary key is
    ``key``."""
    renamed = renamed or {}
    own = [(renamed.get(f.name, f.name), f.name, record) for f in fields(record)]
    names = {column for column, _, _ in own}
    head = [(f.name, f.name, Key) for f in fields(Key) if f.name not in names]
    columns = []
    for column, field_name, owner in head + own:
        kind, nullable, _ = column_type(typing.get_type_hints(owner)[field_name])
        required = column in key or (kind == "TEXT" and not nullable)
        columns.append(f"{column} {kind}" + (" NOT NULL" if required else ""))
    lines = [*columns, f"PRIMARY KEY ({', '.join(key)})"]
    return f"CREATE TABLE IF NOT EXISTS {name} (\n    " + ",\n    ".join(lines) + "\n);\n"


ERROR_PREFIX = "error: "
"""Start of the ``status`` of a run that could not run (a configuration error)."""


@dataclass(frozen=True)
class RunRow:
    """One stored run: a row of ``runs``, whose columns are this record's fields
    (:data:`SCHEMA`).

    study, seed, pattern, criterion, symmetric : its :class:`Key`; stop : how it ended
    (None: it could not run, ``status`` then "error: <message>"); status : the words; the
    paper's counters (``n_reduce``, ``n_lock``, ``n_exceed``), ``n_path``, ``n_rigid``,
    ``n_backtrack``, the lowest DOF reached (``lowest_dof``), the final design's
    ``final_dof`` and ``final_deploys`` (1, 0 or None), ``mean_f_accepted``, the Step 8-9
    figures (``mean_d``, ``mean_dl_mm``, ``mean_drho_fix_deg``, ``reached_plane``), the
    times in seconds (``time_*``), and where it was computed (``version``, ``worker``,
    ``numerics``: the numeric environment's key); a figure the run (or its version) did not
    record is None. The counters and figures of the run's summary have its names
    (:data:`SUMMARY_COLUMNS`, :meth:`from_summary`).
    """

    study: str
    seed: int
    pattern: str
    criterion: str
    symmetric: bool
    status: str
    n_reduce: int | None = None
    n_lock: int | None = None
    n_exceed: int | None = None
    mean_f_accepted: float | None = None
    initial_dof: int | None = None
    final_dof: int | None = None
    n_solutions: int | None = None
    n_solves: int | None = None
    mean_d: float | None = None
    mean_dl_mm: float | None = None
    mean_drho_fix_deg: float | None = None
    reached_plane: int | None = None
    time_build: float | None = None
    time_solve: float | None = None
    time_analysis: float | None = None
    time_selection: float | None = None
    time_develop: float | None = None
    time_deform: float | None = None
    time_total: float | None = None
    version: str = ""
    worker: str | None = None
    numerics: str | None = None
    n_path: int | None = None
    final_deploys: int | None = None
    time_path: float | None = None
    stop: Stop | None = None
    n_backtrack: int | None = None
    n_rigid: int | None = None
    lowest_dof: int | None = None

    @property
    def key(self) -> Key:
        return Key(self.study, self.seed, self.pattern, self.criterion, bool(self.symmetric))

    @property
    def error(self) -> str | None:
        """The message of a run that could not run, None for the others."""
        return self.status.removeprefix(ERROR_PREFIX) if self.stop is None else None

    @classmethod
    def from_summary(cls, key: Key, summary: RunSummary, **given: Any) -> RunRow:
        """The row of the run ``key`` whose summary is ``summary``
        (:class:`rigidfold.rundir.RunSummary`): its status the stop reason, the columns of
        :data:`SUMMARY_COLUMNS` the summary's fields of the same name, the generation's
        times (``time_build``, ... ``time_path``) its ``time_s``, and where solutions were
        checked (``summary.per_solution``) the Step 8-9 figures of them
        (:func:`rigidfold.rundir.aggregate`) and their times; ``given``: the other columns
        (``version``, ``worker``, ``numerics``, ``time_total``)."""
        data = summary.to_dict()
        row: dict[str, Any] = {name: data[name] for name in SUMMARY_COLUMNS}
        row["stop"] = Stop(summary.stop)
        row["status"] = summary.stop_reason
        if summary.final_deploys is not None:
            row["final_deploys"] = int(summary.final_deploys)
        row |= {f"time_{k}": summary.time_s[k] for k in GENERATION_TIMES}
        records = summary.per_solution
        if records:
            row |= {
                "mean_d": data["development"]["mean_D"],
                "mean_dl_mm": data["deformation"]["mean_dl_mm"],
                "mean_drho_fix_deg": data["deformation"]["mean_drho_fix_deg"],
                "reached_plane": int(data["deformation"]["reached_plane"] == len(records)),
                "time_develop": sum(r.time_s.get("develop", 0.0) for r in records),
                "time_deform": sum(r.time_s.get("deform", 0.0) for r in records),
            }
        return cls(**{f.name: getattr(key, f.name) for f in fields(Key)} | row | given)

    def columns(self) -> dict:
        """The row's ``runs`` columns besides its key, by name (what
        :meth:`rigidfold.study.store.Store.add` stores)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in KEY_COLUMNS}

    @classmethod
    def from_columns(cls, values: dict) -> RunRow:
        """The row of the ``runs`` columns ``values``."""
        names = {f.name for f in fields(cls)}
        known = {k: v for k, v in values.items() if k in names}
        stop = known.pop("stop", None)
        known["symmetric"] = bool(known["symmetric"])
        return cls(stop=None if stop is None else Stop(stop), **known)


SUMMARY_COLUMNS = (
    "initial_dof",
    "final_dof",
    "lowest_dof",
    "n_reduce",
    "n_lock",
    "n_exceed",
    "n_path",
    "n_backtrack",
    "n_rigid",
    "final_deploys",
    "n_solutions",
    "n_solves",
    "mean_f_accepted",
)
"""The columns of ``runs`` that are :class:`rigidfold.rundir.RunSummary` fields (and keys of
summary.json and of :meth:`rigidfold.generate.Generation.to_dict`) of the same name: the
counters, the DOFs and the mean F, one name from the run to the database."""

GENERATION_TIMES = ("build", "solve", "analysis", "selection", "path")
"""The generation's times in a summary's ``time_s`` that are the columns ``time_<name>``."""

SCHEMA = (
    """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS invocations (  -- one row per `rigidfold study` command that ended
    started TEXT NOT NULL,        -- UTC, ISO 8601
    argv TEXT NOT NULL,           -- the command line (JSON list)
    workers INTEGER, scheduler TEXT,
    ran INTEGER NOT NULL, skipped INTEGER NOT NULL, total INTEGER NOT NULL,
    wall_s REAL NOT NULL, outcome TEXT NOT NULL, version TEXT NOT NULL
);
"""
    + table("runs", RunRow, KEY_COLUMNS)
    + table("attempts", Attempt, (*KEY_COLUMNS, "idx"), renamed=ATTEMPT_NAMES)
)
"""The tables of a study database: ``meta`` (its configuration and numerics),
``invocations`` (one row per command), ``runs`` (a :class:`RunRow` each) and ``attempts``
(a :class:`~rigidfold.generate.Attempt` each, after its run's key)."""


def schema_columns() -> dict[str, dict[str, str]]:
    """The columns of every table of :data:`SCHEMA` and their declared types, by table."""
    con = sqlite3.connect(":memory:")
    con.executescript(SCHEMA)
    tables = [r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")]
    columns = {t: {r[1]: r[2] for r in con.execute(f"PRAGMA table_info({t})")} for t in tables}
    con.close()
    return columns


SCHEMA_COLUMNS = schema_columns()
RUN_FIELDS = tuple(c for c in SCHEMA_COLUMNS["runs"] if c not in KEY_COLUMNS)
"""The columns of ``runs`` besides the key: the fields of :class:`RunRow`."""
ATTEMPT_FIELDS = tuple(c for c in SCHEMA_COLUMNS["attempts"] if c not in KEY_COLUMNS)
"""The columns of ``attempts`` besides the key: the fields of
:class:`~rigidfold.generate.Attempt` (:data:`ATTEMPT_NAMES`)."""
JSON_ATTEMPT_FIELDS = tuple(
    ATTEMPT_NAMES.get(f.name, f.name)
    for f in fields(Attempt)
    if column_type(typing.get_type_hints(Attempt)[f.name])[2]
)
"""Attempt fields stored as JSON text (decoded by :meth:`Store.attempt_runs`)."""
