"""The generate step: a validated case, surface + crease pattern + settings (:mod:`.case`;
the options that define it as the user gives them, :mod:`.case_options`), a run's options
(:mod:`.options`), its records (:mod:`.records`: attempts, solutions, the run), and Steps 2-7
of the method (:mod:`.steps`: solve, analyse, rank, fix; :mod:`.chains`: backtrack, restart,
the sets' end; :mod:`.final`: the final design of a run that falls short).

The records and the options are exported with the steps that make them.
"""

from rigidfold.generate.chains import with_fold_limit
from rigidfold.generate.final import best_so_far, known_to_deploy
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.records import (
    STOP_REASONS,
    Attempt,
    AttemptOutcome,
    Generation,
    Solution,
    Stop,
)
from rigidfold.generate.steps import generate

__all__ = [
    "STOP_REASONS",
    "Attempt",
    "AttemptOutcome",
    "GenerateOptions",
    "Generation",
    "Solution",
    "Stop",
    "best_so_far",
    "generate",
    "known_to_deploy",
    "with_fold_limit",
]
