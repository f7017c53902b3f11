"""Progress on stderr for long commands: a rich bar on a terminal, plain lines otherwise.

:class:`GenerateProgress` follows a generation run (DOF removed so far, locks, exceeds, the
cost of the last step, ETA);
:class:`StudyProgress` follows a study (runs done, failures, rate, ETA). Both are silent when
disabled, and import rich only when they first draw.
"""

from __future__ import annotations

import math
import sys
import time
from typing import TYPE_CHECKING

from rigidfold.pipeline.events import AttemptEnded, Event, SolutionAccepted, SolutionsRetracted

if TYPE_CHECKING:  # rich is imported only when a bar is first drawn
    from rich.progress import Progress, TaskID


def _rich_bar(label: str, *columns: str, eta: bool = False) -> Progress:
    """A started rich Progress on stderr: label, bar, n/total, description, elapsed [, ETA]."""
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    parts = [TextColumn(f"[bold]{label}"), BarColumn(), MofNCompleteColumn()]
    parts.append(TextColumn("{task.description}"))
    if eta:
        parts += [TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn()]
    bar = Progress(*parts, console=Console(stderr=True), transient=False)
    bar.start()
    return bar


class GenerateProgress:
    """Progress of a generation run over the DOF to remove: a sink of
    :func:`rigidfold.pipeline.run` (:meth:`on_event`: :meth:`update` after every attempt,
    solution and retraction).

    It shows the DOF, the locks and exceeds so far, the cost of the last attempt (solve and
    mechanism analysis, seconds) and an ETA from the mean time per DOF removed. On a terminal
    it is a rich bar; otherwise (a batch job, a log file) a plain line with the same figures,
    at most every ``log_every`` seconds and at the end.

    The ETA is the mean time per DOF removed times the DOF left, unless the run has spent
    longer than that at its current shape (its candidates keep failing): then it says how
    many candidates that shape has cost and gives no ETA rather than a wrong one.

    run : rigidfold.generate.Generation (``initial_dof``, ``n_reduce``, ``lowest_dof``,
    ``n_lock``, ``n_exceed``, ``n_path``, ``n_rigid``, ``n_backtrack`` are read; the DOF
    removed falls back when backtracking retracts a solution); attempt :
    rigidfold.generate.Attempt or None (``solve_time``, ``analysis_time``, ``path_time``:
    the folding path traced for the deployability check).
    """

    def __init__(self, *, enabled: bool, target: int, log_every: float = 30.0) -> None:
        self.enabled, self.target = enabled, target
        self.bar: Progress | None = None
        self.task: TaskID | None = None
        self.plain = not sys.stderr.isatty()
        self.log_every, self.t0 = log_every, time.monotonic()
        self.last = -math.inf
        # solve, analysis and path tracing of the last attempt
        self.costs: tuple[float, float, float] | None = None
        self.shape_since = self.t0  # when the current shape was reached
        self.tried = 0  # candidates tried at it
        self.removed = 0

    def counts(self, run) -> tuple[int, int, str]:
        """(DOF removed, DOF to remove, "DOF d  lock l  exceed e  path p [back b]") of a
        run."""
        total = max(run.initial_dof - self.target, 0)
        dof = run.initial_dof if run.lowest_dof is None else run.lowest_dof  # before a solution
        return (
            min(run.n_reduce, total),
            total,
            f"DOF {dof}  lock {run.n_lock}  exceed {run.n_exceed}  path {run.n_path}"
            + (f"  rigid {run.n_rigid}" if getattr(run, "n_rigid", 0) else "")
            + (f"  back {run.n_backtrack}" if getattr(run, "n_backtrack", 0) else ""),
        )

    def describe(self, run, elapsed: float) -> tuple[int, int, str]:
        """(DOF removed, DOF to remove, the figures) of a run after ``elapsed`` seconds."""
        done, total, text = self.counts(run)
        if self.costs is not None:
            text += (
                f"  last step: solve {self.costs[0]:.2f} s, analysis {self.costs[1]:.2f} s, "
                f"path {self.costs[2]:.2f} s"
            )
        eta = f"{(total - done) * elapsed / done / 60:.1f} min" if done else "?"
        stuck = time.monotonic() - self.shape_since
        if done and stuck > elapsed / done:  # longer at this shape than a DOF takes
            eta = f"? ({self.tried} candidates tried at this DOF in {stuck / 60:.1f} min)"
        return done, total, f"{text}  elapsed {elapsed / 60:.1f} min  ETA {eta}"

    def on_event(self, event: Event) -> None:
        """Follow the run's attempts, solutions and retractions."""
        match event:
            case AttemptEnded(result, attempt):
                self.update(result.generation, attempt)
            case SolutionAccepted(result) | SolutionsRetracted(result):
                self.update(result.generation)

    def update(self, run, attempt=None) -> None:
        if not self.enabled or run.initial_dof is None:
            return
        if attempt is not None:
            self.costs = (attempt.solve_time, attempt.analysis_time, attempt.path_time)
            self.tried += 1
        elif run.n_reduce != self.removed:  # a new shape (or one taken back)
            self.removed, self.tried, self.shape_since = run.n_reduce, 0, time.monotonic()
        if self.plain:
            now = time.monotonic()
            done, total, text = self.describe(run, now - self.t0)
            if now - self.last >= self.log_every or done >= total:
                self.last = now
                print(f"generate {done}/{total}  {text}", file=sys.stderr, flush=True)
            return
        done, total, text = self.counts(run)  # elapsed and ETA in rich's columns: it fits
        if self.costs is not None:
            text += f"  step {self.costs[0]:.2f}+{self.costs[1]:.2f}+{self.costs[2]:.2f} s"
        if self.tried > 1:  # rich's ETA knows only the DOF removed
            text += f"  {self.tried} candidates tried at this DOF"
        if self.bar is None:
            self.bar = _rich_bar("generate", eta=True)
            self.task = self.bar.add_task("", total=total)
        assert self.task is not None  # added with the bar
        self.bar.update(self.task, completed=done, description=text)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


class StudyProgress:
    """One bar for a study: runs done / total, failures, rate, ETA (stderr).

    When stderr is not a terminal (a batch job, ``nohup``, a log file) a live bar would show
    nothing until the end, so a plain line with the same figures is printed instead, at most
    every ``log_every`` seconds and for the last run.
    """

    def __init__(self, *, enabled: bool, log_every: float = 60.0) -> None:
        self.enabled, self.failures = enabled, 0
        self.bar: Progress | None = None
        self.task: TaskID | None = None
        self.plain = not sys.stderr.isatty()
        self.log_every, self.t0 = log_every, time.monotonic()
        self.last = -math.inf
        self.first: int | None = None

    def _line(self, finished: int, total: int) -> None:
        now = time.monotonic()
        if self.first is None:  # runs already in the database before this command
            self.first = finished - 1
        if now - self.last < self.log_every and finished < total:
            return
        self.last = now
        done, elapsed = finished - self.first, now - self.t0
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = f"{(total - finished) / rate / 60:.0f} min" if rate > 0 else "?"
        print(
            f"study {finished}/{total}  failures {self.failures}  {rate * 60:.1f} runs/min  "
            f"elapsed {elapsed / 60:.1f} min  ETA {eta}",
            file=sys.stderr,
            flush=True,
        )

    def update(self, failed: bool, finished: int, total: int) -> None:
        """One more run ended (``failed``: with an error); ``finished`` of ``total`` done."""
        self.failures += bool(failed)
        if not self.enabled:
            return
        if self.plain:
            self._line(finished, total)
            return
        if self.bar is None:
            self.bar = _rich_bar("study", eta=True)
            self.task = self.bar.add_task("", total=total, completed=finished - 1)
        assert self.task is not None  # added with the bar
        rate = self.bar.tasks[0].speed
        self.bar.update(
            self.task,
            completed=finished,
            description=f"failures {self.failures}"
            + (f"  {rate * 60:.1f} runs/min" if rate else ""),
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None
