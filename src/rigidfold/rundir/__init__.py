"""The run directory of ``rigidfold generate`` as files: their names and the directory's
lock with ``--overwrite`` (:mod:`.layout`), the shapes of JSON data (:mod:`.json_shapes`),
one schema for every file (:mod:`.schema`), and the run read back (:mod:`.reader`, for the
report). :mod:`rigidfold.pipeline` writes it. Every file's content is a type of
:mod:`.schema`: :class:`RunSummary` (summary.json),
:class:`rigidfold.generate.Attempt` (a line of log.jsonl, read by :func:`read_log`),
:class:`SolutionRecord` (a solution's checks; which failed:
:meth:`SolutionRecord.failed_stages`).
"""

from rigidfold.rundir.json_shapes import check_shape
from rigidfold.rundir.layout import (
    LOCK_NAME,
    RUN_DIRS,
    RUN_FILES,
    EarlierRun,
    clear_earlier_run,
    earlier_run,
    lock_run_dir,
)
from rigidfold.rundir.reader import (
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
from rigidfold.rundir.schema import (
    LOG_FILE,
    SCHEMA_VERSION,
    RunSummary,
    SolutionRecord,
    Stage,
    aggregate,
)

__all__ = [
    "LOCK_NAME",
    "LOG_FILE",
    "RUN_DIRS",
    "RUN_FILES",
    "SCHEMA_VERSION",
    "Check",
    "EarlierRun",
    "RunData",
    "RunSummary",
    "SolutionFile",
    "SolutionRecord",
    "Stage",
    "ThickPanels",
    "aggregate",
    "check_shape",
    "clear_earlier_run",
    "earlier_run",
    "load_run",
    "lock_run_dir",
    "read_log",
    "read_solids",
    "read_solution",
    "target_surface",
]
