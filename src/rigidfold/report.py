"""Files of a generation run, written as the run goes so an interrupt loses nothing.

``DIR/solutions/step_XX_dof_YY.fold`` for every accepted solution, ``DIR/log.json`` (every
attempt) and ``DIR/summary.json`` (the paper's counters and stage times). Every file is
written atomically (temporary file, then rename), so each one on disk is always valid.
"""

from __future__ import annotations

from pathlib import Path

from rigidfold.case import Case, prepare_output_dir, write_json
from rigidfold.generate import Attempt, Generation, Solution
from rigidfold.io import write_fold


class RunWriter:
    """Callbacks for :func:`rigidfold.generate.generate` that keep DIR up to date."""

    def __init__(self, out: str | Path, case: Case, options: dict) -> None:
        self.out = prepare_output_dir(out)
        self.solutions_dir = prepare_output_dir(self.out / "solutions")
        self.case, self.options = case, options
        self.files: list[Path] = []

    def on_attempt(self, run: Generation, attempt: Attempt) -> None:
        write_json(self.out / "log.json", {"attempts": [a.to_dict() for a in run.attempts]})
        self.write_summary(run)

    def on_solution(self, run: Generation, solution: Solution) -> None:
        dof = solution.mechanism.dof
        path = self.solutions_dir / f"step_{solution.step:02d}_dof_{dof:02d}.fold"
        write_fold(
            path,
            solution.result.pattern,
            title=f"rigidfold generate: step {solution.step}, DOF {dof}",
            metadata={
                **self.case.metadata(),
                **solution.result.summary(),
                "step": solution.step,
                "dof": dof,
                "criterion": self.options.get("criterion"),
            },
        )
        self.files.append(path)
        self.write_summary(run)

    def write_summary(self, run: Generation) -> None:
        write_json(
            self.out / "summary.json",
            {
                **run.summary(),
                "options": self.options,
                "case": self.case.metadata(),
                "solutions": [str(p.relative_to(self.out)) for p in self.files],
            },
        )
