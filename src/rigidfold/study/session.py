"""One ``rigidfold study`` command: open the store, run what is missing, record the command.

:func:`run_study_command` is the library side of ``rigidfold study``: it opens (or creates)
the database, refusing one of another configuration untouched, runs every planned run not
yet in it on Dask (:func:`rigidfold.study.runner.run_study`), and records the command in the
``invocations`` table whether it completed or was interrupted. :func:`failure_summary` is the
line that tells which runs of the command failed.
"""

from __future__ import annotations

import contextlib
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from rigidfold.config import DEFAULT_SEED
from rigidfold.selection import CRITERIA
from rigidfold.study.paper import TABLES_5_6
from rigidfold.study.runner import (
    CONNECT_TIMEOUT_S,
    StudyConfig,
    check_connect_timeout,
    check_workers,
    run_study,
)
from rigidfold.study.store import Key, Store, StoreWriteError


@dataclass(frozen=True)
class StudyPlan:
    """Defaults of a Bezier study: the runs of the paper's Tables 5-6 on two local workers.

    patterns, criteria : names; surfaces : Bezier seeds per (pattern, criterion), from
    ``first_seed``; workers : local Dask worker processes; connect_timeout : seconds that a
    Dask scheduler given by address has to answer.
    """

    patterns: tuple[str, ...] = tuple(sorted({pattern for pattern, _ in TABLES_5_6}))
    criteria: tuple[str, ...] = CRITERIA
    surfaces: int = 100
    first_seed: int = DEFAULT_SEED
    workers: int = 2
    connect_timeout: float = CONNECT_TIMEOUT_S


STUDY_DEFAULTS = StudyPlan()


class StudyInterrupted(KeyboardInterrupt):
    """A study stopped by the user; ``finished`` runs of the study are in the database."""

    def __init__(self, finished: int) -> None:
        super().__init__(finished)
        self.finished = finished


def run_study_command(
    keys: Sequence[Key],
    db: str | Path,
    config: StudyConfig,
    *,
    workers: int = STUDY_DEFAULTS.workers,
    scheduler: str | None = None,
    connect_timeout: float = STUDY_DEFAULTS.connect_timeout,
    argv: Sequence[str] = (),
    on_done: Callable[[bool, int, int], None] | None = None,
    allow_mixed_numerics: bool = False,
) -> dict:
    """Run the study ``keys`` into the database ``db``; returns :func:`run_study`'s counts
    (``failed``: the runs of this command that failed, recorded as errors in the database).

    on_done(failed, finished, total) after each stored run (``failed``: the run ended in an
    error, recorded in the database). A KeyboardInterrupt is recorded and re-raised as
    :class:`StudyInterrupted`. A database that cannot be written (a full disk) stops the
    study with :class:`~rigidfold.study.store.StoreWriteError` (a ValueError, one line),
    recorded when it can be: every run stored before is kept, and the same command resumes.
    The database is locked while the study runs (a second client is refused,
    :class:`~rigidfold.study.lock.StudyLock`). A database whose runs were computed with
    other numerics (:mod:`rigidfold.runtime.numerics`), and Dask workers that compute with other
    numerics than this process, are refused unless ``allow_mixed_numerics``.
    """
    # checked before the database is created: local workers within what the machine runs
    # (CPUs, open files), a finite timeout
    if scheduler is None:
        check_workers(workers)
    check_connect_timeout(connect_timeout)
    from rigidfold.runtime.numerics import numeric_environment

    numerics = numeric_environment().to_dict()
    # refuses another configuration, or runs of other numerics, untouched
    store = Store(
        db, config.as_dict(), numerics=numerics, allow_mixed_numerics=allow_mixed_numerics
    )
    try:
        return _run(
            store,
            keys,
            config,
            workers,
            scheduler,
            connect_timeout,
            argv,
            on_done,
            numerics["key"] if not allow_mixed_numerics else None,
        )
    finally:
        store.close()  # and release its lock


def _run(
    store: Store,
    keys: Sequence[Key],
    config: StudyConfig,
    workers: int,
    scheduler: str | None,
    connect_timeout: float,
    argv: Sequence[str],
    on_done: Callable[[bool, int, int], None] | None,
    numerics_key: str | None,
) -> dict:
    """:func:`run_study_command` on the open ``store`` (``numerics_key``: the numerics every
    worker must have; None: any)."""
    from rigidfold import __version__

    started = datetime.now(UTC).isoformat(timespec="seconds")
    t0 = time.perf_counter()
    planned = set(keys)
    before = len(store.done() & planned)

    def record(outcome: str, ran: int) -> None:
        store.add_invocation(
            started=started,
            argv=list(argv),
            workers=None if scheduler else workers,
            scheduler=scheduler,
            ran=ran,
            skipped=before,
            total=len(keys),
            wall_s=time.perf_counter() - t0,
            outcome=outcome,
            version=__version__,
        )

    def done(key: Key, row: dict, finished: int, total: int) -> None:
        if on_done:
            on_done(bool(row.get("error")), finished, total)

    try:
        result = run_study(
            keys,
            store,
            config,
            workers=workers,
            scheduler=scheduler,
            connect_timeout=connect_timeout,
            on_done=done,
            numerics_key=numerics_key,
        )
    except KeyboardInterrupt:
        finished = len(store.done() & planned)
        with contextlib.suppress(StoreWriteError):  # the runs are stored; the record is a note
            record("interrupted", finished - before)
        raise StudyInterrupted(finished) from None
    except StoreWriteError:  # a full disk: the study stops, the runs stored are kept
        with contextlib.suppress(StoreWriteError):
            record(
                "stopped: the database could not be written", len(store.done() & planned) - before
            )
        raise
    failed = len(result["failed"])
    record(f"completed, {failed} failed" if failed else "completed", result["ran"])
    return result


def failure_summary(failed: Sequence[tuple[Key, str]], ran: int, db: str | Path) -> str:
    """One line: how many of the ``ran`` runs of a command failed, and why (the messages
    with their counts, most frequent first; the first three)."""
    reasons = Counter(message for _, message in failed).most_common()
    shown = "; ".join(f"{n} x {message}" for message, n in reasons[:3])
    more = f"; and {len(reasons) - 3} other reasons" if len(reasons) > 3 else ""
    return (
        f"{len(failed)} of {ran} runs failed and are recorded as errors in {db} "
        f"(rigidfold study-report lists them): {shown}{more}"
    )
