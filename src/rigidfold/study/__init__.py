"""Studies of many generation runs: Dask execution, SQLite store, reports (Tables 5-8)."""

from rigidfold.study.runner import PRESETS, StudyConfig, plan, preset, run_one, run_study
from rigidfold.study.store import Key, Store, run_stop

__all__ = [
    "PRESETS",
    "Key",
    "Store",
    "StudyConfig",
    "plan",
    "preset",
    "run_one",
    "run_stop",
    "run_study",
]
