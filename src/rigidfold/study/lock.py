"""The lock that gives one ``rigidfold study`` command a study database to itself.

Two clients writing one database would run the same runs twice and race to create its
tables; so a client opening a database for writing first takes an exclusive ``flock`` on the
file ``DB.lock`` beside it, which holds the client's pid and host, and the second client is
refused with one line naming that pid. The lock file is named from the database file itself,
its path resolved (every symbolic link followed, as SQLite follows them), so two paths to one
database, a link and its target, take one lock. The kernel drops the lock when its process
dies (also on SIGKILL), so a lock left by a killed study is taken over by the next one.
Reports open the database read-only and take no lock.
"""

from __future__ import annotations

import fcntl
import os
import socket
from pathlib import Path

from rigidfold.errors import RigidfoldError


class StudyLock:
    """An exclusive lock on the study database ``db``, held until :meth:`release`: the file
    ``DB.lock`` beside the database file that ``db`` resolves to (``db`` may be a link)."""

    def __init__(self, db: str | Path) -> None:
        db = Path(db)
        real = Path(os.path.realpath(db))  # a link's target, also a target yet to be made
        self.path = real.with_name(real.name + ".lock")
        while True:
            try:
                fd = os.open(
                    self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644
                )
            except OSError as exc:
                raise RigidfoldError(
                    f"{str(db)!r}: cannot create its lock file {str(self.path)!r}: {exc.strerror}"
                ) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = os.read(fd, 200).decode(errors="replace").split()
                os.close(fd)
                who = f"pid {' on '.join(holder[:2])}" if holder else f"lock {str(self.path)!r}"
                raise RigidfoldError(
                    f"{str(db)!r} is in use by another rigidfold study ({who}); wait for it "
                    "or use another --db"
                ) from None
            if self._same_file(fd):  # else its holder removed it while we opened it: retry
                break
            os.close(fd)
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()} {socket.gethostname()}\n".encode())
        except OSError as exc:  # a full disk
            self.path.unlink(missing_ok=True)
            os.close(fd)
            raise RigidfoldError(
                f"{str(db)!r}: cannot write its lock file {str(self.path)!r}: {exc.strerror}"
            ) from None
        self._fd: int | None = fd

    def _same_file(self, fd: int) -> bool:
        try:
            return os.stat(self.path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            return False

    def release(self) -> None:
        """Remove the lock file and drop the lock (once; later calls do nothing)."""
        if self._fd is None:
            return
        self.path.unlink(missing_ok=True)
        os.close(self._fd)
        self._fd = None
