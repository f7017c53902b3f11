"""What a design run (:func:`rigidfold.pipeline.run`) tells its sinks, as it goes.

A sink is one class with one method, ``on_event(event)`` (:class:`Sink`): it receives every
event below, in the order the run makes them, and does what it does (write the run's
directory, a study's row, a progress bar) with the ones it needs; ``match event:`` on the
event types reads well. Each event is frozen and carries the run as it stands
(:class:`~rigidfold.pipeline.result.RunResult`: the search, the records, the checks).

=======================  ============================================================
:class:`AttemptEnded`    a solve of the search ended (any outcome)
:class:`SolutionAccepted`  a solution was accepted, checked when ``options.check`` asks
:class:`SolutionsRetracted`  backtracking or a restart took the last solutions back
:class:`FinalChecked`    the final design was checked once the search ended
:class:`RunEnded`        the run ended: verdict, as-built checks and exports done
:class:`RunInterrupted`  Ctrl-C or SIGTERM stopped the run, wherever it landed
:class:`RunFailed`       the run ended but a sink could not write all its files
=======================  ============================================================

A sink that raises :class:`~rigidfold.errors.RigidfoldError` before the search has ended
stops the run with it (bad input, or a file that cannot be written); after it, the run
ends with :class:`RunFailed`, its verdict naming the error. A sink with a ``run_dir``
attribute (a :class:`pathlib.Path`, the run directory writer's) is where the final design's
as-built checks and exports write their files.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from rigidfold.generate import Attempt, Solution
from rigidfold.pipeline.checks import Checked
from rigidfold.pipeline.result import RunResult


@runtime_checkable
class Sink(Protocol):
    """Receives a run's events (:data:`Event`), one call each, in order."""

    def on_event(self, event: Event) -> None: ...


__all__ = [
    "AttemptEnded",
    "Event",
    "FinalChecked",
    "RunEnded",
    "RunFailed",
    "RunInterrupted",
    "Sink",
    "SolutionAccepted",
    "SolutionsRetracted",
]


@dataclass(frozen=True, eq=False)
class AttemptEnded:
    """A solve of the search ended: ``attempt`` (its outcome, times), the last of
    ``result.generation.attempts``."""

    result: RunResult
    attempt: Attempt


@dataclass(frozen=True, eq=False)
class SolutionAccepted:
    """``solution`` was accepted: ``checked`` its checks (Step 8, the motion, Step 9) where
    ``options.check`` asked them as it came, else None; ``result.records[-1]`` its record.
    The run keeps the record once every sink has handled the event."""

    result: RunResult
    solution: Solution
    checked: Checked | None

    @property
    def record(self):
        """The solution's :class:`~rigidfold.rundir.SolutionRecord`."""
        return self.result.records[-1]


@dataclass(frozen=True, eq=False)
class SolutionsRetracted:
    """Backtracking or a restart took back the last solutions, ``taken`` (the last first);
    ``result.records`` is without them already."""

    result: RunResult
    taken: tuple[Solution, ...]


@dataclass(frozen=True, eq=False)
class FinalChecked:
    """The final design ``solution`` was checked once the search ended (``--check final``,
    or a final design not checked as it came): ``checked``. ``result`` is the run before its
    record is updated."""

    result: RunResult
    solution: Solution
    checked: Checked


@dataclass(frozen=True, eq=False)
class RunEnded:
    """The run ended: ``result`` with its verdict, the final design's checks as built and
    its exports."""

    result: RunResult


@dataclass(frozen=True, eq=False)
class RunInterrupted:
    """Ctrl-C or SIGTERM stopped the run: ``result`` with the stop INTERRUPTED and its
    verdict, which names the best design known to deploy or none. Signals are held while
    sinks handle it."""

    result: RunResult


@dataclass(frozen=True, eq=False)
class RunFailed:
    """The run ended but its files could not all be written: ``result.write_error`` says
    why, its verdict falls short naming it."""

    result: RunResult


Event = (
    AttemptEnded
    | SolutionAccepted
    | SolutionsRetracted
    | FinalChecked
    | RunEnded
    | RunInterrupted
    | RunFailed
)
"""Every event of a run."""
