"""The attempt log of a run (issue 38, items 1 and 6): ``DIR/log.jsonl`` is appended to, a line
per attempt, never rewritten; backtracking appends an attempt again and the reader takes the
last line of each index; a torn last line is skipped; summary.json is written after a
rejected attempt at most every ``Settings.generation.summary_interval`` seconds, exact at
the end; run files and study databases of another schema version are refused in one line.

The run: the backtracking case of ``test_backtrack.py`` (pattern 1 on Bezier seed 102, S-hat,
look-ahead, ``deploy_max_candidates = 1``), seconds.
"""

from __future__ import annotations

import itertools
import json
import os
import shutil
import sqlite3

import pytest

from conftest import main_code
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import append_json_line
from rigidfold.pipeline import (
    AttemptEnded,
    RunWriter,
    SolutionAccepted,
    SolutionsRetracted,
    run,
)
from rigidfold.rundir import LOG_FILE, SCHEMA_VERSION, load_run, read_log
from rigidfold.study import Store, StudyConfig
from rigidfold.study.store import STUDY_SCHEMA_VERSION

SEED = 102
# the paper's solver, IPOPT alone, with which this case backtracks (GenerateOptions.projection)
OPTIONS = GenerateOptions(
    criterion="shat", seed=SEED, lookahead=True, deform=False, projection="large"
)


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    """The backtracking run, summary.json written only when it must be
    (``summary_interval`` beyond the run's length): (out, run, the log's bytes after each
    callback, the file's inode then, summary.json's writes, solutions and retractions
    seen)."""
    out = tmp_path_factory.mktemp("log")
    settings = DEFAULTS.with_(deploy_max_candidates=1, summary_interval=1e9)
    case = case_from_specs("bezier", "1", seed=SEED, settings=settings)
    writer = RunWriter(out, case, OPTIONS, report=False)
    snapshots: list[tuple[bytes, int]] = []
    writes = {"summary": 0, "solution": 0, "retract": 0}
    write_summary = writer.write_summary

    def counted(result) -> None:
        writes["summary"] += 1
        write_summary(result)

    writer.write_summary = counted  # type: ignore[method-assign]

    class Snapshots:  # after the writer: the log as each attempt, solution, retraction left it
        def on_event(self, event) -> None:
            if isinstance(event, SolutionAccepted):
                writes["solution"] += 1
            if isinstance(event, SolutionsRetracted):
                writes["retract"] += 1
            if isinstance(event, AttemptEnded | SolutionAccepted | SolutionsRetracted):
                path = out / LOG_FILE
                snapshots.append((path.read_bytes(), os.stat(path).st_ino))

    generation = run(case, OPTIONS, [writer, Snapshots()]).generation
    return out, generation, snapshots, writes


def test_the_log_is_appended_to_never_rewritten(logged):
    out, run, snapshots, _ = logged
    assert len(snapshots) > len(run.attempts) > 5
    for (before, inode), (after, later) in itertools.pairwise(snapshots):
        assert after.startswith(before) and inode == later  # the same file, only grown
    final = (out / LOG_FILE).read_bytes()
    assert final.startswith(snapshots[-1][0])
    lines = final.decode().splitlines()
    assert json.loads(lines[0]) == {"schema_version": SCHEMA_VERSION}
    # a line per attempt, and one more for each change of outcome (a retraction)
    assert len(lines) == 1 + len(run.attempts) + run.n_backtrack
    assert not list(out.glob(".log.jsonl*"))  # appended: no temporary file


def test_the_reader_takes_the_last_line_of_each_index(logged, tmp_path):
    out, run, _, _ = logged
    assert run.n_backtrack >= 1
    records = read_log(out / LOG_FILE)
    assert [a.index for a in records] == list(range(len(run.attempts)))
    assert [a.outcome for a in records] == [a.outcome.value for a in run.attempts]
    lines = [json.loads(line) for line in (out / LOG_FILE).read_text().splitlines()[1:]]
    dead = [a.index for a in run.attempts if a.outcome is AttemptOutcome.DEAD_END]
    for k in dead:  # accepted first, then dead_end, appended when it was retracted
        assert [line["outcome"] for line in lines if line["index"] == k] == [
            "accepted",
            "dead_end",
        ]
    assert load_run(out).attempts == records
    # accepted again (backtracking settles on a chain it had left): the last line counts
    log = tmp_path / LOG_FILE
    first = records[0].to_dict()
    rows = [
        {"schema_version": SCHEMA_VERSION},
        first,
        {**first, "index": 1},
        {**first, "index": 1, "outcome": "dead_end"},
        {**first, "index": 2, "outcome": "lock"},
        {**first, "index": 1, "outcome": "accepted"},
    ]
    log.write_text("".join(json.dumps(r) + "\n" for r in rows))
    assert [(a.index, a.outcome) for a in read_log(log)] == [
        (0, "accepted"),
        (1, "accepted"),
        (2, "lock"),
    ]


def test_summary_json_is_written_when_it_changes_and_exact_at_the_end(logged):
    out, run, _, writes = logged
    # at each solution and retraction, and at the end (the first attempt is a solution)
    assert writes["summary"] == writes["solution"] + writes["retract"] + 1
    assert writes["summary"] < len(run.attempts) + writes["solution"]  # not every attempt
    summary = json.loads((out / "summary.json").read_text())
    assert summary["schema_version"] == SCHEMA_VERSION
    exact = run.to_dict()
    for key in ("n_solves", "n_lock", "n_exceed", "n_path", "n_backtrack", "n_rigid", "stop"):
        assert summary[key] == exact[key], key


def test_summary_interval_0_writes_summary_json_after_every_attempt(tmp_path):
    settings = DEFAULTS.with_(deploy_max_candidates=1, summary_interval=0)
    case = case_from_specs("bezier", "1", seed=SEED, settings=settings)
    seen = []

    class Exact:  # after the writer: summary.json as each rejected attempt left it
        def on_event(self, event) -> None:
            if isinstance(event, AttemptEnded) and (
                event.attempt.outcome is not AttemptOutcome.ACCEPTED
            ):
                summary = json.loads((tmp_path / "summary.json").read_text())
                attempts = summary["n_solves"] + summary["n_repeats"]
                seen.append(attempts == len(event.result.generation.attempts))

    writer = RunWriter(tmp_path, case, OPTIONS, report=False)
    generation = run(case, OPTIONS, [writer, Exact()]).generation
    assert seen and all(seen)  # exact after every rejected attempt
    assert generation.n_backtrack >= 1


def test_summary_interval_is_checked():
    assert DEFAULTS.generation.summary_interval > 0
    assert DEFAULTS.with_(summary_interval=0).generation.summary_interval == 0
    for bad in (-1, float("nan"), float("inf"), "2"):
        with pytest.raises(ValueError, match="summary_interval must be a finite number >= 0"):
            DEFAULTS.with_(summary_interval=bad)


def test_a_torn_last_line_is_skipped(logged, tmp_path, capsys):
    out = logged[0]
    copy = shutil.copytree(out, tmp_path / "run")
    log = copy / LOG_FILE
    whole = read_log(log)
    line = json.dumps({**whole[-1].to_dict(), "index": len(whole)}).encode()
    for cut in (1, 20, len(line) - 1):  # a crash mid-write: the line without its end
        log.write_bytes((out / LOG_FILE).read_bytes() + line[:cut])
        assert read_log(log) == whole
    assert main_code(["report", str(copy)]) == 0
    # a whole line without its newline (cut just before it) is a line
    log.write_bytes((out / LOG_FILE).read_bytes() + line)
    assert len(read_log(log)) == len(whole) + 1
    # a broken line before others is damage, not a tear: one line naming it
    lines = (out / LOG_FILE).read_bytes().splitlines(keepends=True)
    log.write_bytes(b"".join([*lines[:2], line[:20] + b"\n", *lines[2:]]))
    with pytest.raises(RigidfoldError, match=rf"{LOG_FILE}', line 3: not JSON"):
        read_log(log)
    # only a header: a run stopped before its first attempt ended
    log.write_bytes(lines[0])
    assert read_log(log) == ()
    capsys.readouterr()


def _refused(capsys, directory) -> str:
    assert main_code(["report", str(directory)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    return line


def test_run_files_of_another_schema_version_are_refused_in_one_line(logged, tmp_path, capsys):
    out, _, _, _ = logged
    copy = shutil.copytree(out, tmp_path / "run")
    summary = json.loads((copy / "summary.json").read_text())
    for version, said in ((9, "9"), (0, "0")):
        # another version's summary may lack what this one needs: the version is named
        (copy / "summary.json").write_text(json.dumps({"schema_version": version}))
        assert _refused(capsys, copy) == (
            f"rigidfold: error: '{copy / 'summary.json'}' was written by run schema version "
            f"{said}; this rigidfold reads version {SCHEMA_VERSION}"
        )
    del summary["schema_version"]  # written before rigidfold recorded the version
    (copy / "summary.json").write_text(json.dumps(summary))
    assert _refused(capsys, copy).endswith(
        "summary.json' was written by run schema version 0 (none recorded); this rigidfold "
        f"reads version {SCHEMA_VERSION}"
    )
    (copy / "summary.json").write_text(json.dumps(summary | {"schema_version": SCHEMA_VERSION}))
    lines = (copy / LOG_FILE).read_text().splitlines(keepends=True)
    (copy / LOG_FILE).write_text("".join(['{"schema_version": 3}\n', *lines[1:]]))
    assert _refused(capsys, copy) == (
        f"rigidfold: error: '{copy / LOG_FILE}' was written by run schema version 3; this "
        f"rigidfold reads version {SCHEMA_VERSION}"
    )
    (copy / LOG_FILE).unlink()  # a run of an earlier rigidfold wrote log.json instead
    (copy / "log.json").write_text('{"attempts": []}')
    assert _refused(capsys, copy).endswith("is not a rigidfold generate run: it has no log.jsonl")
    # an earlier run's log.json is an earlier run's file: refused (removed with --overwrite)
    args = ["generate", "--surface", "bezier", "--pattern", "1", "--out", str(copy)]
    assert main_code(args) == 2
    assert "holds an earlier run (summary.json, log.json, solutions" in capsys.readouterr().err


def test_the_log_is_appended_safely(tmp_path):
    log = tmp_path / "a.jsonl"
    append_json_line(log, {"a": 1}, create=True)
    append_json_line(log, {"b": [float("nan")]})
    assert log.read_text() == '{"a":1}\n{"b":[null]}\n'
    with pytest.raises(RigidfoldError, match=r"cannot write .*a\.jsonl'"):
        append_json_line(log, {}, create=True)  # a new log is made, never an old one reused
    outside = tmp_path / "outside.txt"
    outside.write_text("keep")
    (tmp_path / "link.jsonl").symlink_to(outside)
    for create in (False, True):
        with pytest.raises(RigidfoldError, match=r"cannot write .*link\.jsonl'"):
            append_json_line(tmp_path / "link.jsonl", {"a": 1}, create=create)
    assert outside.read_text() == "keep"
    with pytest.raises(RigidfoldError, match=r"cannot write .*missing\.jsonl'"):
        append_json_line(tmp_path / "missing.jsonl", {"a": 1})
    with pytest.raises(RigidfoldError, match="holds a set, which is not JSON data"):
        append_json_line(log, {"a": {1}})
    assert log.read_text() == '{"a":1}\n{"b":[null]}\n'


def test_a_study_database_of_another_version_is_refused_in_one_line(tmp_path, capsys):
    db = tmp_path / "s.sqlite"
    config = StudyConfig().as_dict()
    Store(db, config).close()
    with sqlite3.connect(db) as con:
        assert con.execute("PRAGMA user_version").fetchone()[0] == STUDY_SCHEMA_VERSION
    Store(db, config).close()  # its own version opens
    Store(db, readonly=True).close()
    for version, made in (
        (STUDY_SCHEMA_VERSION + 1, ""),
        (0, " (made before rigidfold recorded one)"),
    ):
        con = sqlite3.connect(db)
        con.execute(f"PRAGMA user_version = {version}")
        con.close()
        before = db.read_bytes()
        words = (
            f"{str(db)!r} is a study database of schema version {version}{made}; this "
            f"rigidfold reads version {STUDY_SCHEMA_VERSION}"
        )
        for readonly in (False, True):
            with pytest.raises(RigidfoldError) as err:
                Store(db, readonly=True) if readonly else Store(db, config)
            assert str(err.value) == words
        assert main_code(["study-report", str(db)]) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line == f"rigidfold: error: {words}"
        assert db.read_bytes() == before  # refused untouched


def test_a_target_rebuilt_beyond_the_floats_is_not_used(logged, tmp_path):
    """Found by the seeded fuzz of summary.json once the log's lines changed its draws: a
    control height of 1e308 overflowed in the report (a RuntimeWarning, exit 1)."""
    copy = shutil.copytree(logged[0], tmp_path / "run")
    summary = json.loads((copy / "summary.json").read_text())
    summary["case"]["surface"]["control_heights"][0][0] = 1e308
    (copy / "summary.json").write_text(json.dumps(summary))
    run = load_run(copy)
    assert run.surface is None
    assert run.surface_note == "the target surface could not be rebuilt: its heights are too large"
