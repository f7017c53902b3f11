"""Studies of many generation runs: Dask execution, SQLite store, reports (Tables 5-8)."""

from rigidfold.study.runner import (
    PRESETS,
    STUDY_OPTIONS,
    StudyConfig,
    plan,
    preset,
    run_one,
    run_study,
)
from rigidfold.study.session import (
    STUDY_DEFAULTS,
    StudyInterrupted,
    StudyPlan,
    failure_summary,
    run_study_command,
)
from rigidfold.study.store import Key, RunRow, Store, StoreWriteError

__all__ = [
    "PRESETS",
    "STUDY_DEFAULTS",
    "STUDY_OPTIONS",
    "Key",
    "RunRow",
    "Store",
    "StoreWriteError",
    "StudyConfig",
    "StudyInterrupted",
    "StudyPlan",
    "failure_summary",
    "plan",
    "preset",
    "run_one",
    "run_study",
    "run_study_command",
]
