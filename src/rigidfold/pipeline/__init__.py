"""The pipeline of a design run: :func:`run` (:mod:`.run`) does the search, the checks of
each solution and of the final design as built (:mod:`.checks`, :mod:`.built`), the verdict
(:mod:`.verdict`), and tells its sinks as it goes (:mod:`.events`); it returns a
:class:`RunResult` (:mod:`.result`). The run directory is written by a sink
(:class:`RunWriter`, :mod:`.writer`), its report by :mod:`.report`; one function per other
command of the command line is in :mod:`.workflows`. The files it writes are defined in
:mod:`rigidfold.rundir`.
"""

from rigidfold.pipeline import events
from rigidfold.pipeline.events import *  # noqa: F403 (the event types and Sink: events.__all__)
from rigidfold.pipeline.report import write_report
from rigidfold.pipeline.result import RunResult
from rigidfold.pipeline.run import Interrupted, run
from rigidfold.pipeline.verdict import RunOutcome, RunVerdict, run_verdict
from rigidfold.pipeline.writer import RunWriter, verification_frames, write_checked_shape

__all__ = [
    *events.__all__,
    "Interrupted",
    "RunOutcome",
    "RunResult",
    "RunVerdict",
    "RunWriter",
    "run",
    "run_verdict",
    "verification_frames",
    "write_checked_shape",
    "write_report",
]
