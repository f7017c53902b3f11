"""Run a study: many ``generate`` runs on Dask, results in a SQLite store.

Each run (surface seed, pattern, criterion) is one Dask task executed in a worker process;
the client process alone writes the database, one transaction per finished run. Runs already
in the database are skipped, so re-running the same command resumes a killed study. Dask
reschedules the task of a worker that dies; a run whose workers die every time (Dask's
``KilledWorker``: killed, out of memory, a crash in native code) is recorded as failed, like
a run that could not run, and the study goes on; so is a run that ends in an unexpected
exception (a defect, named with its type and message). Dask is imported only here.
"""

from __future__ import annotations

import math
import os
import socket
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rigidfold.config import DEFAULT_SEED, DEFAULTS, Check, Settings, check_seed
from rigidfold.errors import RigidfoldError
from rigidfold.generate import GenerateOptions
from rigidfold.generate.specs import parse_pattern
from rigidfold.selection import CRITERIA
from rigidfold.study.rows import ERROR_PREFIX, Key, RunRow
from rigidfold.study.store import Store

if TYPE_CHECKING:  # the pipeline is imported in the worker
    from rigidfold.pipeline import RunResult

PRESETS = {
    # Sections 6.5 and 6.6: the 11 x 11 grid with S, with and without the mirror planes
    "dome": [Key("dome", 0, "11", "s", True), Key("dome", 0, "11", "s", False)],
    "hp": [Key("hp", 0, "11", "s", True), Key("hp", 0, "11", "s", False)],
}


STUDY_OPTIONS = GenerateOptions(
    deploy_check=False, deform=False, check=Check.ALL, batch="off", projection="large"
)
"""The generate options of a study by default: the paper's Step 5 (no deployability check;
the final design's path is traced after the run), no Step 9, and the paper's one crease per
solve and solver (IPOPT alone on the paper's sizes, ``projection`` "large"), with the
deployability check too (``rigidfold study --deploy-check``)."""


@dataclass(frozen=True)
class StudyConfig:
    """What makes the numbers of two runs comparable; stored in the database
    (:meth:`as_dict`) and handed to the Dask workers as it is.

    options : the generate options every run shares (its criterion and seed are the run's
        :class:`~rigidfold.study.store.Key`'s). ``deform``: Steps 8-9 of the solutions
        ``check`` names (a study writes no diagram, so Step 8 runs only with Step 9);
        ``lookahead`` (False for databases written before it existed); ``deploy_check``
        (False, the paper's method, for Tables 5-8, by default and for databases written
        before it existed).
    settings : the tolerances.
    """

    options: GenerateOptions = STUDY_OPTIONS
    settings: Settings = field(default=DEFAULTS)

    def as_dict(self) -> dict:
        """The stored configuration (the keys every version has written, and ``check``)."""
        o = self.options
        return {
            "deform": o.deform,
            "target_dof": o.target_dof,
            "solver": o.solver,
            "settings": self.settings.flat(),
            "lookahead": o.lookahead,
            "deploy_check": o.deploy_check,
            "check": o.check,
        }


def plan(
    patterns: Sequence[str],
    criteria: Sequence[str],
    surfaces: int,
    first_seed: int = DEFAULT_SEED,
    *,
    settings: Settings = DEFAULTS,
) -> list[Key]:
    """The runs of a Bezier study, validated: seeds first_seed .. first_seed + surfaces - 1,
    on crease patterns given by spec (:func:`rigidfold.generate.specs.parse_pattern` with its
    defaults: the paper's names, ``grid:NXxNY`` on 3 m x 3 m, ``mesh:FILE``, ``FILE.fold``,
    ``FILE.svg`` fitted into 3 m x 3 m) and criteria.

    Seed-major order (every pattern and criterion of a surface before the next surface), so
    that a study stopped early holds complete surfaces. At most ``settings.limits.max_study_runs``
    runs (checked before the list is built).
    """
    for p in patterns:
        parse_pattern(p, settings=settings)
    for c in criteria:
        if c not in CRITERIA:
            raise RigidfoldError(f"unknown criterion {c!r} (choose from {', '.join(CRITERIA)})")
    if surfaces < 1:
        raise RigidfoldError(f"--surfaces must be >= 1, got {surfaces}")
    check_seed(first_seed, "--first-seed")
    check_seed(first_seed + surfaces - 1, "--first-seed + --surfaces - 1 (the last seed)")
    if not patterns or not criteria:
        raise RigidfoldError("at least one pattern and one criterion are needed")
    runs = surfaces * len(patterns) * len(criteria)
    if runs > settings.limits.max_study_runs:
        raise RigidfoldError(
            f"--surfaces {surfaces} makes {runs} runs ({surfaces} surfaces x {len(patterns)} "
            f"patterns x {len(criteria)} criteria), more than the limit of "
            f"{settings.limits.max_study_runs} (Settings.limits.max_study_runs)"
        )
    return [
        Key("bezier", seed, p, c)
        for seed in range(first_seed, first_seed + surfaces)
        for p in patterns
        for c in criteria
    ]


def preset(name: str) -> list[Key]:
    """The runs of one preset, or of several given as ``"dome,hp"``.

    The asymmetric runs (315 variables, the longest) come first so that the symmetric ones
    fill the workers while they run.
    """
    names = [n.strip() for n in name.split(",") if n.strip()]
    for n in names or [name]:
        if n not in PRESETS:
            raise RigidfoldError(f"unknown preset {n!r} (choose from {', '.join(PRESETS)})")
    keys = [k for n in dict.fromkeys(names) for k in PRESETS[n]]
    return sorted(keys, key=lambda k: k.symmetric)


def run_one(key: Key, config: StudyConfig) -> tuple[Key, dict, list[dict]]:
    """Execute one run (in a worker): :func:`rigidfold.pipeline.run` with the study's checks
    (no motion: Steps 8-9 of the solutions ``config.options.check`` names if
    ``config.options.deform``, and the final design's path traced after the search), its
    row made from the result (:func:`run_row`).

    The run's row holds the ``runs`` columns, and ``error`` (the message) for a run that
    could not run; its status is then "error: <message>".
    """
    from rigidfold import __version__
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.pipeline import run
    from rigidfold.runtime.numerics import numeric_environment

    settings, options = config.settings, config.options
    t0 = time.perf_counter()
    row: dict = {
        "version": __version__,
        "worker": f"{socket.gethostname()}:{os.getpid()}",
        "numerics": numeric_environment().key,
    }
    try:
        case = case_from_specs(  # the stored key's texts, read as the command line's
            key.study,
            key.pattern,
            seed=key.seed if key.study == "bezier" else None,
            symmetric=key.symmetric,
            settings=settings,
        )
        result = run(case, options.replace(criterion=key.criterion, seed=key.seed), motion=False)
    except RigidfoldError as exc:  # a configuration that cannot run: recorded, not retried
        row.update(
            status=ERROR_PREFIX + str(exc), error=str(exc), time_total=time.perf_counter() - t0
        )
        return key, row, []
    row = run_row(key, result, **row, time_total=time.perf_counter() - t0)
    return key, row, [a.to_dict() | {"idx": a.index, "f": a.F} for a in result.generation.attempts]


def run_row(key: Key, result: RunResult, **given) -> dict:
    """The ``runs`` columns of the finished run ``key`` (:class:`rigidfold.pipeline.RunResult`):
    :meth:`RunRow.from_summary` of its summary, with the final design's path traced after
    the search where the search did not (whether it deploys, and its seconds in
    ``time_path``), and the figures of the solutions whose checks ran; ``given``: the other
    columns (``version``, ``worker``, ``numerics``, ``time_total``)."""
    from rigidfold.rundir import RunSummary

    records = [result.checked[step].record for step in sorted(result.checked)]
    summary = RunSummary.from_run(result.generation, records, stage_times={}, case={}, solutions=())
    path = result.final_path
    deploys = None if result.final is None or path is None else int(path.deploys)
    given["time_path"] = summary.time_s["path"] + result.final_path_time
    if deploys is not None:
        given["final_deploys"] = deploys
    return RunRow.from_summary(key, summary, **given).columns()


def lost_run(exc: Exception) -> dict:
    """The row of a run whose Dask workers all died while running it (``exc``: Dask's
    ``KilledWorker``), recorded as an error like a run that could not run: the status
    "error: <message>", and the last worker's address."""
    deaths = getattr(exc, "allowed_failures", None)
    times = "repeatedly" if deaths is None else f"{deaths + 1} time{'s' if deaths else ''}"
    message = (
        f"the Dask worker running it died {times} (KilledWorker: killed, out of memory, or a "
        "crash in native code)"
    )
    worker = getattr(getattr(exc, "last_worker", None), "address", None)
    return _failed_row(message, worker)


def crashed_run(exc: Exception) -> dict:
    """The row of a run that ended in an unexpected exception ``exc`` (a defect of rigidfold
    or of a library it calls, not bad input, which :func:`run_one` records itself): recorded
    as an error with the exception's type and message, so that the study goes on and its
    summary names the failure instead of ending in a traceback."""
    text = str(exc).strip().splitlines()
    message = (
        f"unexpected {type(exc).__name__}"
        + (f": {text[0]}" if text else "")
        + " (a defect: please report it with the run's key)"
    )
    return _failed_row(message)


def _failed_row(message: str, worker: str | None = None) -> dict:
    """The row of a run that failed in the client's view: status "error: <message>"."""
    from rigidfold import __version__

    return {
        "status": ERROR_PREFIX + message,
        "error": message,
        "version": __version__,
        "worker": worker,
    }


CONNECT_TIMEOUT_S = 20.0
"""Seconds that a Dask scheduler given by address has to answer (``--connect-timeout``)."""

MIN_WORKER_LIMIT = 2
"""Local workers always allowed, even on a machine with fewer CPUs (the default, 2)."""

FILES_PER_WORKER = 16
"""Open files that the client process holds per local Dask worker (measured: about 9: the
worker's and its nanny's connections and pipes), with a margin."""

FILES_RESERVED = 256
"""Open files kept for the client itself (the database, its lock, Python, Dask's scheduler)."""


def usable_cpus() -> int:
    """The CPUs this process may run on (its CPU affinity; ``os.cpu_count()`` where the
    platform has none)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def open_file_limit() -> int | None:
    """This process's soft limit of open files (RLIMIT_NOFILE); None: unlimited or unknown."""
    try:
        import resource
    except ImportError:
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
    return None if soft == resource.RLIM_INFINITY or soft < 0 else soft


def max_workers() -> tuple[int, str]:
    """The most local Dask workers this machine runs, and what bounds it: the CPUs this
    process may use (:func:`usable_cpus`, at least :data:`MIN_WORKER_LIMIT`), and the open
    files the client needs for them (:data:`FILES_PER_WORKER` each, beyond
    :data:`FILES_RESERVED`, within :func:`open_file_limit`)."""
    cpus = usable_cpus()
    limit = max(cpus, MIN_WORKER_LIMIT)
    reason = f"the {cpus} CPU{'s' if cpus != 1 else ''} this process may use"
    files = open_file_limit()
    if files is not None:
        by_files = max((files - FILES_RESERVED) // FILES_PER_WORKER, 1)
        if by_files < limit:
            limit = by_files
            reason = f"the open-file limit of {files} (ulimit -n), {FILES_PER_WORKER} per worker"
    return limit, reason


def check_workers(workers: int) -> None:
    """ValueError unless ``workers`` local Dask workers are at least 1 and at most
    :func:`max_workers`, naming the limit."""
    if isinstance(workers, bool) or not isinstance(workers, int):
        raise RigidfoldError(f"--workers must be a whole number, got {workers!r}")
    if workers < 1:
        raise RigidfoldError(f"--workers must be >= 1, got {workers}")
    limit, reason = max_workers()
    if workers > limit:
        raise RigidfoldError(
            f"--workers {workers} is more than this machine runs: at most {limit} local "
            f"workers ({reason}); use --scheduler for a larger cluster"
        )


def check_connect_timeout(timeout: float) -> None:
    """ValueError unless ``timeout`` (``--connect-timeout``) is a finite number > 0."""
    if isinstance(timeout, bool) or not isinstance(timeout, int | float):
        raise RigidfoldError(f"--connect-timeout must be a number of seconds, got {timeout!r}")
    if not (math.isfinite(timeout) and timeout > 0):
        raise RigidfoldError(
            f"--connect-timeout must be a finite number of seconds > 0, got {timeout:g}"
        )


def connect(scheduler: str, timeout: float):
    """A ``dask.distributed.Client`` of the scheduler at ``scheduler``; ValueError naming the
    address when nothing there completes Dask's handshake within ``timeout`` seconds.

    distributed bounds the TCP connection by its timeout but not the handshake read after it,
    so a service that accepts and stays silent (an HTTP server) would hang ``Client`` for
    ever: the handshake is first made here under an asyncio timeout, then the Client made.
    """
    import asyncio

    from dask.distributed import Client
    from distributed.comm import connect as dask_connect

    async def handshake() -> None:
        comm = await asyncio.wait_for(dask_connect(scheduler, timeout=timeout), timeout)
        await comm.close()

    try:
        asyncio.run(handshake())
        return Client(scheduler, timeout=timeout)
    except (OSError, ValueError) as exc:  # TimeoutError is an OSError
        reason = str(exc) or "no Dask handshake (is it a Dask scheduler?)"
        raise RigidfoldError(
            f"cannot reach the Dask scheduler at {scheduler!r} within {timeout:g} s: {reason}"
        ) from None


def worker_numerics() -> str:
    """The key of a Dask worker's numeric environment (run on every worker)."""
    from rigidfold.runtime.numerics import numeric_environment

    return numeric_environment().key


def check_worker_numerics(keys: dict[str, str], expected: str) -> None:
    """ValueError naming the first worker of ``keys`` (address -> numerics key) whose key is
    not ``expected``."""
    for address, key in sorted(keys.items()):
        if key != expected:
            raise RigidfoldError(
                f"Dask worker {address} computes with numerics {key!r}, this process with "
                f"{expected!r}: start the workers with `python -m rigidfold.pinned "
                "dask worker ...` on machines with the same library versions, or pass "
                "--allow-mixed-numerics"
            )


def run_study(
    keys: Sequence[Key],
    store: Store,
    config: StudyConfig,
    *,
    workers: int = 2,
    scheduler: str | None = None,
    connect_timeout: float = CONNECT_TIMEOUT_S,
    on_done: Callable[[Key, dict, int, int], None] | None = None,
    numerics_key: str | None = None,
) -> dict:
    """Run every key not yet in ``store``; returns counts, the wall time, the part of it
    spent starting (or connecting to) the Dask cluster (``startup_s``) and the runs of this
    call that failed (``failed``: (Key, message) each, in the order they ended).

    On ``workers`` local processes (at most :func:`max_workers`), or on the cluster of the
    Dask ``scheduler`` (an address), which must answer within ``connect_timeout`` seconds, a
    finite number (:func:`connect`). A run fails when
    it cannot run (a ValueError, :func:`run_one`) or when its Dask workers die every time it
    is tried (:func:`lost_run`); either is stored with its message and the others go on.

    on_done(key, run_row, finished, total) is called in the client after each stored run.
    ``numerics_key``: the numeric environment every worker must compute with
    (:attr:`rigidfold.runtime.numerics.NumericEnvironment.key`); a worker with another is refused
    (ValueError naming it) before any run starts. Local workers inherit this process's.
    """
    import logging

    from dask.distributed import Client, LocalCluster, as_completed
    from distributed import KilledWorker

    if scheduler is None:
        check_workers(workers)
    check_connect_timeout(connect_timeout)
    done = store.done()
    todo = [k for k in keys if k not in done]
    total, finished = len(keys), len(keys) - len(todo)
    t0 = time.perf_counter()
    failed: list[tuple[Key, str]] = []
    if not todo:
        return {
            "total": total,
            "ran": 0,
            "skipped": finished,
            "wall_s": 0.0,
            "startup_s": 0.0,
            "failed": failed,
        }
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            # the scheduler's HTTP server (health checks) on a free local port: its default,
            # 8787, warns when another cluster on the machine holds it
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
            silence_logs=logging.ERROR,
        )
        client = Client(cluster)
    else:
        client = connect(scheduler, connect_timeout)
    startup = time.perf_counter() - t0
    try:
        if numerics_key is not None:
            check_worker_numerics(client.run(worker_numerics), numerics_key)
        named = {f"run-{i}-{k.row()}": k for i, k in enumerate(todo)}
        futures = [
            client.submit(run_one, k, config, pure=False, key=name) for name, k in named.items()
        ]
        for future in as_completed(futures):
            try:
                key, row, attempts = future.result()
            except KilledWorker as exc:
                key, row, attempts = named[future.key], lost_run(exc), []
            except Exception as exc:  # a defect in one run: recorded, the others go on
                key, row, attempts = named[future.key], crashed_run(exc), []
            store.add(key, row, attempts)
            if row.get("error"):
                failed.append((key, row["error"]))
            finished += 1
            if on_done:
                on_done(key, row, finished, total)
            future.release()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return {
        "total": total,
        "ran": len(todo),
        "skipped": total - len(todo),
        "wall_s": time.perf_counter() - t0,
        "startup_s": startup,
        "failed": failed,
    }
