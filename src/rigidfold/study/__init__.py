"""Studies of many generation runs: Dask execution, SQLite store, reports (Tables 5-8)."""

from rigidfold.study.runner import PRESETS, StudyConfig, plan, preset, run_one, run_study
from rigidfold.study.store import Key, Store, open_readonly

__all__ = [
    "PRESETS",
    "Key",
    "Store",
    "StudyConfig",
    "open_readonly",
    "plan",
    "preset",
    "run_one",
    "run_study",
]
