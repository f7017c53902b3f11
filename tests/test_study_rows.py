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
    assert runs["seed"] == ("INTEGER", True) and runs["mean_f_accepted"] == ("REAL", False)
    attempts = {r[1]: (r[2], bool(r[3])) for r in con.execute("PRAGMA table_info(attempts)")}
    assert attempts["idx"] == ("INTEGER", True) and attempts["f"] == ("REAL", False)
    assert attempts["outcome"] == ("TEXT", True) and attempts["rigid_forecast"][0] == "INTEGER"
    con.close()


def test_a_row_is_made_from_the_runs_summary():
    """RunRow.from_summary: the counters, DOFs and mean F under the summary's own names
    (SUMMARY_COLUMNS, each a field of both records), the generation's times, the Step 8-9
    figures of the checked solutions; the rest given."""
    from rigidfold.generate import Generation, Stop
    from rigidfold.rundir import RunSummary, SolutionRecord
    from rigidfold.study.rows import SUMMARY_COLUMNS

    summary_fields = {f.name for f in fields(RunSummary)}
    assert set(SUMMARY_COLUMNS) <= summary_fields & {f.name for f in fields(RunRow)}
    run = Generation(initial_dof=5, n_lock=2, n_exceed=1, n_path=3, n_backtrack=1, n_rigid=0)
    run.stop, run.build_time = Stop.NO_CANDIDATE, 0.25
    record = SolutionRecord(
        3,
        2,
        development={"status": "converged", "D": 1e-9, "flipped": 0, "overlaps": 0},
        deformation={"status": "reached_plane", "reached_plane": True, "mean_dl_mm": 0.5},
        time_s={"develop": 1.0, "deform": 2.0},
    )
    summary = RunSummary.from_run(run, [record], stage_times={}, case={}, solutions=())
    key = Key("bezier", 4, "1", "s")
    row = RunRow.from_summary(key, summary, version="t", numerics="k", time_total=9.0)
    data = summary.to_dict()
    assert row.key == key and row.stop is Stop.NO_CANDIDATE
    assert row.status == "no candidate crease succeeds"
    assert {c: getattr(row, c) for c in SUMMARY_COLUMNS} == {c: data[c] for c in SUMMARY_COLUMNS}
    assert (row.n_lock, row.n_exceed, row.n_path, row.initial_dof) == (2, 1, 3, 5)
    assert (row.time_build, row.time_total, row.numerics) == (0.25, 9.0, "k")
    assert (row.mean_d, row.mean_dl_mm, row.reached_plane) == (1e-9, 0.5, 1)
    assert (row.time_develop, row.time_deform) == (1.0, 2.0)
    assert set(row.columns()) == set(RUN_FIELDS)
    bare = RunRow.from_summary(key, RunSummary.from_run(Generation(), [], stage_times={},
                                                        case={}, solutions=()))  # fmt: skip
    assert bare.mean_d is None and bare.time_develop is None and bare.final_deploys is None
