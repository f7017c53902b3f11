"""The run directory of ``rigidfold generate``, written and read through one schema.

:class:`RunWriter` writes it as the run goes (:mod:`.writer`), under a lock with
``--overwrite`` handled (:mod:`.lock`); :func:`run_verdict` judges the finished run
(:mod:`.verdict`); :func:`load_run` reads it back (:mod:`.reader`) for the report. Every
file's content is a type of :mod:`.schema`: :class:`RunSummary` (summary.json),
:class:`rigidfold.generate.Attempt` (a line of log.jsonl, read by :func:`read_log`),
:class:`SolutionRecord` (a solution's checks; which failed:
:meth:`SolutionRecord.failed_stages`).
"""

from rigidfold.run.lock import LOCK_NAME, RUN_DIRS, RUN_FILES, clear_earlier_run, lock_run_dir
from rigidfold.run.reader import (
    Check,
    RunData,
    SolutionFile,
    ThickPanels,
    load_run,
    read_log,
    read_solids,
    read_solution,
    target_surface,
)
from rigidfold.run.schema import (
    LOG_FILE,
    SCHEMA_VERSION,
    RunSummary,
    SolutionRecord,
    Stage,
    aggregate,
)
from rigidfold.run.shapes import check_shape
from rigidfold.run.verdict import RunOutcome, RunVerdict, run_verdict
from rigidfold.run.writer import RunWriter, verification_frames, write_checked_shape, write_report

__all__ = [
    "LOCK_NAME",
    "LOG_FILE",
    "RUN_DIRS",
    "RUN_FILES",
    "SCHEMA_VERSION",
    "Check",
    "RunData",
    "RunOutcome",
    "RunSummary",
    "RunVerdict",
    "RunWriter",
    "SolutionFile",
    "SolutionRecord",
    "Stage",
    "ThickPanels",
    "aggregate",
    "check_shape",
    "clear_earlier_run",
    "load_run",
    "lock_run_dir",
    "read_log",
    "read_solids",
    "read_solution",
    "run_verdict",
    "target_surface",
    "verification_frames",
    "write_checked_shape",
    "write_report",
]
