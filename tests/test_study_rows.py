"""The tables of a study database are made from its records (issue 38): a field of
:class:`RunRow` or :class:`rigidfold.generate.Attempt` is a column, none is listed by hand."""

from __future__ import annotations

import sqlite3
from dataclasses import fields

from rigidfold.generate import Attempt
from rigidfold.study.rows import (
    ATTEMPT_FIELDS,
    ATTEMPT_NAMES,
    JSON_ATTEMPT_FIELDS,
    KEY_COLUMNS,
    RUN_FIELDS,
    SCHEMA,
    Key,
    RunRow,
    column_type,
)


def test_the_columns_are_the_records_fields():
    assert KEY_COLUMNS == tuple(f.name for f in fields(Key))
    assert KEY_COLUMNS + RUN_FIELDS == tuple(f.name for f in fields(RunRow))
    assert ATTEMPT_FIELDS == tuple(ATTEMPT_NAMES.get(f.name, f.name) for f in fields(Attempt))
    assert set(JSON_ATTEMPT_FIELDS) == {
        "fixed_added", "locked", "skipped_locks", "predicted_locks", "locked_predicted",
        "locked_left", "locked_fold_deg", "carried", "path", "second_order",
    }  # fmt: skip


def test_column_types_follow_the_field_types():
    assert column_type(int) == ("INTEGER", False, False)
    assert column_type(bool | None) == ("INTEGER", True, False)
    assert column_type(float | None) == ("REAL", True, False)
    assert column_type(list[int]) == ("TEXT", False, True)
    assert column_type(dict | None) == ("TEXT", True, True)
    con = sqlite3.connect(":memory:")
    con.executescript(SCHEMA)
    runs = {r[1]: (r[2], bool(r[3])) for r in con.execute("PRAGMA table_info(runs)")}
    assert runs["stop"] == ("TEXT", False) and runs["status"] == ("TEXT", True)
    assert runs["seed"] == ("INTEGER", True) and runs["mean_f"] == ("REAL", False)
    attempts = {r[1]: (r[2], bool(r[3])) for r in con.execute("PRAGMA table_info(attempts)")}
    assert attempts["idx"] == ("INTEGER", True) and attempts["f"] == ("REAL", False)
    assert attempts["outcome"] == ("TEXT", True) and attempts["rigid_forecast"][0] == "INTEGER"
    con.close()
