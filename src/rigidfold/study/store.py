"""SQLite store of a study: one row per finished run, one row per solve of problem (6).

Only the client process writes, and each run is one transaction (its ``runs`` row and all its
``attempts`` rows), so a killed client or worker leaves either a whole run or nothing: a run
without a row is simply redone, and the primary keys forbid counting one twice. The file is
in WAL mode, so a report can read it while a study writes.

The ``meta`` table holds the study *configuration* (settings, solver, target DOF, whether
Steps 8-9 run). Opening a database with another configuration is refused before anything is
written: its numbers would not be comparable.

The database's ``PRAGMA user_version`` is :data:`STUDY_SCHEMA_VERSION`, set when it is
created; a database of another version (0: made before rigidfold recorded one) is refused
in one line naming both versions, not read through layers of old formats.

A run's ``stop`` column holds how it ended, the :class:`~rigidfold.generate.Stop` value (NULL
for a run that could not run), and ``status`` the words (``Generation.stop_reason``) or
"error: <message>"; :meth:`Store.runs` returns typed rows (:class:`RunRow`).
"""

from __future__ import annotations

import itertools
import json
import os
import sqlite3
from collections.abc import Iterator, Sequence
from pathlib import Path

from rigidfold.errors import RigidfoldError
from rigidfold.generate import Stop
from rigidfold.study.lock import StudyLock
from rigidfold.study.rows import (
    ATTEMPT_FIELDS,
    JSON_ATTEMPT_FIELDS,
    KEY_COLUMNS,
    RUN_FIELDS,
    SCHEMA,
    SCHEMA_COLUMNS,
    Key,
    RunRow,
)


def _stop_value(run: dict) -> str | None:
    """The ``stop`` column of a run to add: its ``stop`` as a Stop value (None: an error)."""
    stop = run.get("stop")
    return None if stop is None else Stop(stop).value


class StoreWriteError(RigidfoldError):
    """A study database could not be written (a full disk, a read-only file): the run or
    command being written is not stored, every run stored before is (one transaction each)."""


# settings that change nothing without the deployability check: not compared between two
# configurations without it (a study of the paper's Step 5 resumes whatever they are)
CHECK_ONLY_SETTINGS = frozenset({"backtrack_max", "fold_limits", "restart_after"})

UNUSED_PREFIXES = ("fabricate_",)
"""Settings a study never uses (it builds no thick panels), never compared: a study written
before one of them changed (``fabricate_clearance``, now ``fabricate_clearance_share`` and
``fabricate_clearance_min``) is resumed all the same."""


def config_differences(stored: dict, current: dict) -> list[str]:
    """Names of the configuration entries in which ``current`` differs from ``stored``.

    A setting that a later rigidfold added (absent from ``stored["settings"]``) counts as
    equal when ``current`` has it at its default; one that acts only with the deployability
    check (``CHECK_ONLY_SETTINGS``) is not compared where neither configuration has it, and
    one a study never uses (``UNUSED_PREFIXES``) never. So a study can be resumed by a newer
    version as long as nothing it measures has changed.
    """
    from rigidfold.config import DEFAULTS

    defaults = DEFAULTS.flat()
    checked = any(config.get("deploy_check") for config in (stored, current))
    inert = set() if checked else CHECK_ONLY_SETTINGS
    diff = []
    for key in sorted(set(stored) | set(current)):
        a, b = stored.get(key), current.get(key)
        if key == "settings" and isinstance(a, dict) and isinstance(b, dict):
            diff += [
                f"settings.{k}"
                for k in sorted(set(a) | set(b))
                if k not in inert
                and not k.startswith(UNUSED_PREFIXES)
                and (_as_json(a.get(k, defaults.get(k))) != _as_json(b.get(k)) or k not in b)
            ]
        elif a != b:
            diff.append(key)
    return diff


def _as_json(value) -> str:
    """A setting as stored (a tuple is a list there)."""
    return json.dumps(value, sort_keys=True)


def sqlite_uri(path: str | Path, mode: str) -> str:
    """The SQLite URI of the file ``path`` opened with ``mode`` (``ro``, ``rw``, ``rwc``): its
    absolute path percent-encoded, so that a name with ``#``, ``?`` or ``%`` (``run#2.sqlite``)
    names that file, not a shorter one with the rest read as the query or fragment."""
    from urllib.parse import quote

    absolute = os.path.abspath(os.fsencode(path))
    return f"file:{quote(absolute, safe='/')}?mode={mode}"


STUDY_SCHEMA_VERSION = 3
"""The version of the tables of :data:`SCHEMA`, the database's ``PRAGMA user_version``; raise
it with any change to them that an older rigidfold cannot read (3: the column ``mean_f`` of
``runs`` is ``mean_f_accepted``, the name of summary.json's key)."""

READONLY_COPY_TRIES = 3
"""Times a database opened read-only is copied into memory before it is read in place
instead (:meth:`Store._connect_readonly`): a copy is kept only if nothing wrote meanwhile."""


class Store:
    """A study database. ``config`` is checked against (or written to) the ``meta`` table.

    Opening for writing takes the database's :class:`~rigidfold.study.lock.StudyLock` (a
    second client is refused) and checks an existing file read-only first (:meth:`_check`):
    a damaged or foreign file, or one of another configuration, is refused untouched.
    ``readonly=True`` opens an existing database for reporting: it never creates one nor
    writes to it, nor makes its ``-wal`` and ``-shm`` files where no study is writing it
    (:meth:`_connect_readonly`: it reads from a read-only file system too), and takes no
    ``config`` and no lock.

    ``numerics`` (:meth:`rigidfold.runtime.numerics.NumericEnvironment.to_dict` of the process that
    will add runs) is stored with the first runs; a database whose runs were computed with
    another numeric environment (another ``key``), or before rigidfold recorded it, is
    refused untouched unless ``allow_mixed_numerics``.
    """

    def __init__(
        self,
        path: str | Path,
        config: dict | None = None,
        *,
        readonly: bool = False,
        numerics: dict | None = None,
        allow_mixed_numerics: bool = False,
    ) -> None:
        self.path = Path(path)
        self._lock: StudyLock | None = None
        self._numerics = numerics
        self._allow_mixed = allow_mixed_numerics
        if readonly:
            if config is not None or numerics is not None:
                raise RigidfoldError("a study database opened read-only takes no configuration")
            if not self.path.is_file():
                raise RigidfoldError(f"no study database at {str(self.path)!r}")
            self.db = self._connect_readonly()
            self._check(self.db)
            return
        if self.path.is_dir():
            raise RigidfoldError(f"database path {str(self.path)!r} is a directory")
        parent = self.path.parent if str(self.path.parent) else Path(".")
        if not parent.is_dir():
            raise RigidfoldError(
                f"cannot create study database {str(self.path)!r}: no such directory"
            )
        self._lock = StudyLock(self.path)
        try:
            if self.path.exists() and self.path.stat().st_size > 0:
                ro = self._connect_readonly()
                try:
                    self._check(ro, config)
                finally:
                    ro.close()
            self._open_writable(config)
        except BaseException:
            self._lock.release()
            raise

    def _connect_readonly(self) -> sqlite3.Connection:
        """A read-only connection to the database that makes no file beside it.

        When no write-ahead log holds data (no ``-wal`` file, or an empty one) and there is
        no rollback journal, the file holds the whole database: it is copied into memory
        through an ``immutable`` connection (no lock taken, no ``-wal`` or ``-shm`` made,
        also on a read-only file system), and the copy is kept if the file did not change
        while it was copied (else tried again). Otherwise (a study writing it now, or one
        killed with runs in its ``-wal``) it is opened ``mode=ro``, which reads the
        ``-wal`` through the ``-shm`` beside it (making that one when it is missing).
        Raises ValueError: :meth:`_open_error`.
        """
        for _ in range(READONLY_COPY_TRIES):
            before = self._state()
            wal, journal = before[1:]
            if (wal is not None and wal[1] > 0) or journal is not None:
                break
            try:
                source = sqlite3.connect(
                    sqlite_uri(self.path, "ro") + "&immutable=1", uri=True, timeout=30
                )
                try:
                    copy = sqlite3.connect(":memory:")
                    source.backup(copy)
                finally:
                    source.close()
            except sqlite3.Error as exc:
                raise self._open_error(exc) from None
            if self._state() == before:
                return copy
            copy.close()  # written meanwhile: copy again, or read it in place
        try:
            con = sqlite3.connect(sqlite_uri(self.path, "ro"), uri=True, timeout=30)
            con.execute("PRAGMA schema_version")  # opens the file (and its -wal) now
        except sqlite3.Error as exc:
            raise self._open_error(exc) from None
        return con

    def _state(self) -> tuple:
        """(inode, size, mtime) of the database, its ``-wal`` and its ``-journal`` (None for
        a missing one): what changes when the database is written."""
        state: list[tuple[int, int, int] | None] = []
        for suffix in ("", "-wal", "-journal"):
            try:
                st = os.stat(f"{self.path}{suffix}")
            except FileNotFoundError:
                state.append(None)
                continue
            except OSError as exc:
                raise RigidfoldError(f"{str(self.path)!r}: cannot open: {exc.strerror}") from None
            state.append((st.st_ino, st.st_size, st.st_mtime_ns))
        return tuple(state)

    def _open_error(self, exc: sqlite3.Error) -> ValueError:
        """The one-line error of a database that could not be opened read-only: one it may
        not read, one whose ``-wal`` holds runs but whose directory is read-only (SQLite
        cannot make the ``-shm`` it needs), else a damaged file."""
        name = str(self.path)
        if getattr(exc, "sqlite_errorname", "") != "SQLITE_CANTOPEN":
            return RigidfoldError(f"{name!r}: damaged SQLite file: {exc}")
        if not os.access(self.path, os.R_OK):
            return RigidfoldError(f"{name!r}: cannot open: no permission to read it")
        if not os.access(self.path.parent if str(self.path.parent) else ".", os.W_OK):
            return RigidfoldError(
                f"{name!r}: cannot read its write-ahead log ({self.path.name}-wal) in a "
                f"read-only directory: SQLite needs to create {self.path.name}-shm beside it; "
                "copy the database with its -wal file to a writable directory"
            )
        return RigidfoldError(f"{name!r}: cannot open: {exc}")

    def _open_writable(self, config: dict | None) -> None:
        try:
            self.db = sqlite3.connect(self.path, timeout=30)
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")
            self.db.executescript(SCHEMA)
            # a new database takes this version; an existing one was checked to have it
            self.db.execute(f"PRAGMA user_version = {STUDY_SCHEMA_VERSION}")
            if config is not None:
                self.db.execute(
                    "INSERT OR IGNORE INTO meta VALUES ('config', ?)",
                    (json.dumps(config, sort_keys=True),),
                )
            if self._numerics is not None:  # the numerics of the first runs are kept
                n_runs = self.db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
                verb = "IGNORE" if n_runs else "REPLACE"
                self.db.execute(
                    f"INSERT OR {verb} INTO meta VALUES ('numerics', ?)",
                    (json.dumps(self._numerics, sort_keys=True),),
                )
            self.db.commit()
        except sqlite3.Error as exc:
            raise RigidfoldError(f"cannot open study database {str(self.path)!r}: {exc}") from None

    def _check(self, con: sqlite3.Connection, config: dict | None = None) -> None:
        """Refuse, reading ``con`` only, a damaged SQLite file, one without the tables and
        columns of :data:`SCHEMA`, one with text in a number column or a ``meta`` config that
        is not a JSON object, one of another :data:`STUDY_SCHEMA_VERSION` (``user_version``;
        0, a database made before it was recorded, once its tables are found); and, given
        ``config``, one with no or another configuration."""
        name = str(self.path)
        try:
            verdict = con.execute("PRAGMA quick_check").fetchone()[0]
            if verdict != "ok":
                first = [line for line in verdict.splitlines() if not line.startswith("***")]
                raise RigidfoldError(f"{name!r}: damaged SQLite file: {(first or [verdict])[0]}")
            version = con.execute("PRAGMA user_version").fetchone()[0]
            if version != 0:  # another version's tables may differ: before they are read
                self._check_version(version)
            for table, columns in SCHEMA_COLUMNS.items():
                have = {row[1] for row in con.execute(f"PRAGMA table_info({table})")}
                if not have:
                    raise RigidfoldError(
                        f"{name!r}: not a rigidfold study database: no table {table!r}"
                    )
                for column, kind in columns.items():
                    if column not in have:
                        raise RigidfoldError(
                            f"{name!r}: not a rigidfold study database: table {table!r} "
                            f"lacks column {column!r}"
                        )
                    if column in have and kind in ("INTEGER", "REAL"):
                        bad = con.execute(
                            f"SELECT {column} FROM {table} "
                            f"WHERE typeof({column}) NOT IN ('integer', 'real', 'null') LIMIT 1"
                        ).fetchone()
                        if bad is not None:
                            raise RigidfoldError(
                                f"{name!r}: not a rigidfold study database: {table}.{column} "
                                f"holds {bad[0]!r}, not a number"
                            )
            self._check_version(version)  # a rigidfold study database made before versions
            row = con.execute("SELECT value FROM meta WHERE key='config'").fetchone()
        except sqlite3.Error as exc:
            raise RigidfoldError(f"{name!r}: damaged SQLite file: {exc}") from None
        try:
            stored = None if row is None else json.loads(row[0])
        except (TypeError, json.JSONDecodeError):
            stored = "?"
        if row is not None and not isinstance(stored, dict):
            raise RigidfoldError(
                f"{name!r}: not a rigidfold study database: its config is not a JSON object"
            )
        if config is None:
            return
        if stored is None:
            raise RigidfoldError(f"{name!r}: not a rigidfold study database (no config)")
        diff = config_differences(stored, json.loads(json.dumps(config)))
        if diff:
            raise RigidfoldError(
                f"{name!r} holds a study with another configuration "
                f"(differs in: {', '.join(diff)}); use another --db"
            )
        if self._numerics is not None and not self._allow_mixed:
            self._check_numerics(con, self._numerics)

    def _check_version(self, version: int) -> None:
        """Refuse a database whose ``user_version`` is not :data:`STUDY_SCHEMA_VERSION`."""
        if version != STUDY_SCHEMA_VERSION:
            made = " (made before rigidfold recorded one)" if version == 0 else ""
            raise RigidfoldError(
                f"{str(self.path)!r} is a study database of schema version {version}{made}; "
                f"this rigidfold reads version {STUDY_SCHEMA_VERSION}"
            )

    def _check_numerics(self, con: sqlite3.Connection, current: dict) -> None:
        """Refuse a database whose runs were computed with other numerics than ``current``."""
        name = str(self.path)
        try:
            row = con.execute("SELECT value FROM meta WHERE key='numerics'").fetchone()
            n_runs = con.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
        except sqlite3.Error as exc:
            raise RigidfoldError(f"{name!r}: damaged SQLite file: {exc}") from None
        try:
            stored = None if row is None else json.loads(row[0])
        except (TypeError, json.JSONDecodeError):
            stored = None
        stored_key = stored.get("key") if isinstance(stored, dict) else None
        if stored_key == current.get("key") or n_runs == 0:
            return
        was = (
            f"numerics {stored_key!r}"
            if stored_key
            else "numerics that were not recorded (an earlier rigidfold)"
        )
        raise RigidfoldError(
            f"{name!r} holds runs computed with {was}, this machine computes with "
            f"{current.get('key')!r}: mixing them makes the study depend on the machines; "
            "use another --db, or pass --allow-mixed-numerics"
        )

    def numerics(self) -> dict | None:
        """The numeric environment stored with the first runs (None: not recorded)."""
        row = self.db.execute("SELECT value FROM meta WHERE key='numerics'").fetchone()
        try:
            return None if row is None else json.loads(row[0])
        except (TypeError, json.JSONDecodeError):
            return None

    def config(self) -> dict | None:
        row = self.db.execute("SELECT value FROM meta WHERE key='config'").fetchone()
        return None if row is None else json.loads(row[0])

    def done(self) -> set[Key]:
        """Keys of every finished run."""
        rows = self.db.execute("SELECT study, seed, pattern, criterion, symmetric FROM runs")
        return {Key(s, int(seed), p, c, bool(sym)) for s, seed, p, c, sym in rows}

    def add(self, key: Key, run: dict, attempts: list[dict]) -> None:
        """Write one run and its attempts in one transaction; refuses (ValueError) a run
        already in the database, which is left as it was. A write that fails (a full disk)
        rolls the transaction back and raises :class:`StoreWriteError`
        (:meth:`_write_error`): the runs stored before are kept."""
        try:
            self._add(key, run, attempts)
        except sqlite3.Error as exc:
            raise self._write_error(exc) from None

    def _add(self, key: Key, run: dict, attempts: list[dict]) -> None:
        with self.db:
            names = KEY_COLUMNS + RUN_FIELDS
            added = self.db.execute(
                f"INSERT OR IGNORE INTO runs ({', '.join(names)}) "
                f"VALUES ({', '.join('?' * len(names))})",
                key.row()
                + tuple(_stop_value(run) if f == "stop" else run.get(f) for f in RUN_FIELDS),
            ).rowcount
            if not added:
                raise RigidfoldError(f"{str(self.path)!r} already holds the run {key.row()}")
            names = KEY_COLUMNS + ATTEMPT_FIELDS
            self.db.executemany(
                f"INSERT INTO attempts ({', '.join(names)}) VALUES ({', '.join('?' * len(names))})",
                [
                    key.row()
                    + tuple(
                        json.dumps(a.get(f)) if f in JSON_ATTEMPT_FIELDS else a.get(f)
                        for f in ATTEMPT_FIELDS
                    )
                    for a in attempts
                ],
            )

    def add_invocation(self, **row) -> None:
        """Record one ``rigidfold study`` command: started, argv, workers, scheduler, ran,
        skipped, total, wall_s, outcome ("completed" or "interrupted"), version."""
        names = (
            "started", "argv", "workers", "scheduler", "ran", "skipped", "total", "wall_s",
            "outcome", "version",
        )  # fmt: skip
        try:
            with self.db:
                self.db.execute(
                    f"INSERT INTO invocations ({', '.join(names)}) VALUES "
                    f"({', '.join('?' * len(names))})",
                    tuple(json.dumps(row[n]) if n == "argv" else row[n] for n in names),
                )
        except sqlite3.Error as exc:
            raise self._write_error(exc) from None

    def _write_error(self, exc: sqlite3.Error) -> StoreWriteError:
        """The one-line error of a write that failed (its transaction rolled back): what
        SQLite said, how many runs the database keeps, and what to do."""
        try:
            n = int(self.db.execute("SELECT COUNT(*) FROM runs").fetchone()[0])
            kept = f"the {n} run stored before is" if n == 1 else f"the {n} runs stored before are"
        except sqlite3.Error:
            kept = "the runs stored before are"
        full = getattr(exc, "sqlite_errorname", "") == "SQLITE_FULL"
        return StoreWriteError(
            f"cannot write to the study database {str(self.path)!r}: "
            f"{' '.join(str(exc).split())}; {kept} kept: "
            + ("free disk space" if full else "make it writable")
            + ", then run the same command to resume"
        )

    def invocations(self) -> list[dict]:
        """Every recorded command, oldest first."""
        cur = self.db.execute("SELECT * FROM invocations ORDER BY started")
        names = [d[0] for d in cur.description]
        rows = [dict(zip(names, row, strict=True)) for row in cur]
        for r in rows:
            r["argv"] = json.loads(r["argv"])
        return rows

    def runs(self, study: str | None = None) -> list[RunRow]:
        """Every run (:class:`RunRow`), ordered by key."""
        cur = self.db.execute(
            "SELECT * FROM runs"
            + (" WHERE study = ?" if study else "")
            + " ORDER BY study, pattern, criterion, symmetric, seed",
            (study,) if study else (),
        )
        names = [d[0] for d in cur.description]
        return [RunRow.from_columns(dict(zip(names, row, strict=True))) for row in cur]

    def count_attempts(self) -> int:
        return int(self.db.execute("SELECT COUNT(*) FROM attempts").fetchone()[0])

    def solve_means(
        self, study: str, pattern: str, criterion: str
    ) -> tuple[float | None, float | None]:
        """Mean IPOPT iterations and mean seconds per solve of (6) over the attempts of
        (study, pattern, criterion); None for both when it has none."""
        return self.db.execute(
            "SELECT AVG(iterations), AVG(solve_time) FROM attempts "
            "WHERE study = ? AND pattern = ? AND criterion = ?",
            (study, pattern, criterion),
        ).fetchone()

    def attempt_runs(
        self, study: str, columns: Sequence[str], *, outcome: str | None = None
    ) -> Iterator[tuple[tuple[str, str], int, list[tuple]]]:
        """The attempts of every run of ``study`` in solve order, from one query.

        Yields ``((pattern, criterion), seed, rows)`` per run, ``rows`` holding ``columns``
        (names of :data:`ATTEMPT_FIELDS`) of each attempt, only those with ``outcome`` (an
        :class:`~rigidfold.generate.AttemptOutcome` value) when given. JSON columns
        (:data:`JSON_ATTEMPT_FIELDS`) come decoded.
        """
        unknown = [c for c in columns if c not in ATTEMPT_FIELDS]
        if unknown:
            raise RigidfoldError(
                f"unknown attempt columns {unknown} (choose from {ATTEMPT_FIELDS})"
            )
        decode = [c in JSON_ATTEMPT_FIELDS for c in columns]
        cur = self.db.execute(
            f"SELECT pattern, criterion, seed, {', '.join(columns)} FROM attempts "
            "WHERE study = ?"
            + (" AND outcome = ?" if outcome is not None else "")
            + " ORDER BY pattern, criterion, seed, idx",
            (study,) if outcome is None else (study, outcome),
        )
        for (pattern, crit, seed), rows in itertools.groupby(cur, key=lambda r: r[:3]):
            yield (
                (pattern, crit),
                seed,
                [
                    tuple(
                        json.loads(v) if json_ and v is not None else v
                        for v, json_ in zip(r[3:], decode, strict=True)
                    )
                    for r in rows
                ],
            )

    def close(self) -> None:
        """Close the database and release its lock (of a store opened for writing)."""
        self.db.close()
        if self._lock is not None:
            self._lock.release()
