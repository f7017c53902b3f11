"""The pipeline of a design run: the checks of a solution and of the final design as built
(:mod:`.checks`, :mod:`.built`), the verdict and exit code (:mod:`.verdict`), the run
directory written as the run goes (:mod:`.writer`), and one function per command of the
command line (:mod:`.workflows`). The files it writes are defined in
:mod:`rigidfold.rundir`.
"""

from rigidfold.pipeline.verdict import RunOutcome, RunVerdict, run_verdict
from rigidfold.pipeline.writer import (
    RunWriter,
    verification_frames,
    write_checked_shape,
    write_report,
)

__all__ = [
    "RunOutcome",
    "RunVerdict",
    "RunWriter",
    "run_verdict",
    "verification_frames",
    "write_checked_shape",
    "write_report",
]
