"""Files of a generation run, written as the run goes so an interrupt loses nothing.

``DIR/solutions/step_XX_dof_YY.fold`` for every accepted solution (its folded form plus a
``creasePattern`` frame with its development diagram, Step 8) and ``.svg`` beside it,
``DIR/log.json`` (every attempt) and ``DIR/summary.json`` (the paper's counters, the
development figures and stage times). Every file is written atomically (temporary file, then
rename), so each one on disk is always valid.
"""

from __future__ import annotations

import time
from pathlib import Path

from rigidfold.case import Case, prepare_output_dir, write_json
from rigidfold.develop import develop
from rigidfold.generate import Attempt, Generation, Solution
from rigidfold.io import crease_pattern_frame, write_fold, write_svg


class RunWriter:
    """Callbacks for :func:`rigidfold.generate.generate` that keep DIR up to date."""

    def __init__(self, out: str | Path, case: Case, options: dict) -> None:
        self.out = prepare_output_dir(out)
        self.solutions_dir = prepare_output_dir(self.out / "solutions")
        self.case, self.options = case, options
        self.files: list[Path] = []
        self.developments: list[dict] = []
        self.develop_time = 0.0

    def on_attempt(self, run: Generation, attempt: Attempt) -> None:
        write_json(self.out / "log.json", {"attempts": [a.to_dict() for a in run.attempts]})
        self.write_summary(run)

    def on_solution(self, run: Generation, solution: Solution) -> None:
        dof = solution.mechanism.dof
        t0 = time.perf_counter()
        diagram = develop(solution.result.pattern, settings=self.case.settings)
        self.develop_time += time.perf_counter() - t0
        figures = {
            "step": solution.step,
            "dof": dof,
            "D": diagram.D,
            "max_length_error": diagram.max_length_error,
            "flipped": diagram.flipped,
            "overlaps": diagram.overlaps,
            "status": diagram.status,
        }
        self.developments.append(figures)
        path = self.solutions_dir / f"step_{solution.step:02d}_dof_{dof:02d}.fold"
        write_svg(
            path.with_suffix(".svg"),
            solution.result.pattern,
            diagram.coords2d,
            title=f"step {solution.step}, DOF {dof}: development diagram",
        )
        write_fold(
            path,
            solution.result.pattern,
            frames=[crease_pattern_frame(diagram.coords2d)],
            title=f"rigidfold generate: step {solution.step}, DOF {dof}",
            metadata={
                **self.case.metadata(),
                **solution.result.summary(),
                "step": solution.step,
                "dof": dof,
                "criterion": self.options.get("criterion"),
                "development": figures,
            },
        )
        self.files.append(path)
        self.write_summary(run)

    def write_summary(self, run: Generation) -> None:
        summary = run.summary()
        summary["time_s"]["develop"] = self.develop_time
        Ds = [d["D"] for d in self.developments]
        write_json(
            self.out / "summary.json",
            {
                **summary,
                "development": {
                    "mean_D": sum(Ds) / len(Ds) if Ds else None,
                    "max_D": max(Ds) if Ds else None,
                    "flipped": sum(max(d["flipped"], 0) for d in self.developments),
                    "overlaps": sum(max(d["overlaps"], 0) for d in self.developments),
                    "per_solution": self.developments,
                },
                "options": self.options,
                "case": self.case.metadata(),
                "solutions": [str(p.relative_to(self.out)) for p in self.files],
            },
        )
