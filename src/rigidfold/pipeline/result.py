"""The result of a design run (:func:`rigidfold.pipeline.run`): one frozen record of what the
run computed, which its events carry as it goes and which it returns at its end.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from rigidfold.drive import DriveResult
from rigidfold.fabricate import Fabrication
from rigidfold.generate import GenerateOptions, Generation, Solution, Stop
from rigidfold.generate.case import Case
from rigidfold.mechanism.path import FoldingPath
from rigidfold.pipeline.checks import Built, Checked
from rigidfold.pipeline.verdict import RunVerdict
from rigidfold.rundir.layout import solution_file
from rigidfold.rundir.schema import SolutionRecord
from rigidfold.structure import StructureCheck


@dataclass(frozen=True, eq=False)
class RunResult:
    """A design run as it stands (in an event) or as it ended (returned by
    :func:`rigidfold.pipeline.run`).

    case, options : what was run. generation : the search (:class:`rigidfold.generate.Generation`,
    its counters, attempts and solutions; the live object while the run goes).
    records : each solution's :class:`~rigidfold.rundir.SolutionRecord`, in the order of
    ``generation.solutions`` (the checks that ran on it, or its fit alone).
    checked : step -> :class:`~rigidfold.pipeline.checks.Checked`, the solutions whose checks
    ran (Steps 8-9, the motion). stage_times : seconds of the checks per stage (develop,
    deform, motion; over every check run, retracted solutions' too).
    verdict : :class:`~rigidfold.pipeline.verdict.RunVerdict`, None while the run goes.
    built : the final design as built (thick panels, structure, drive), None where not asked.
    exports : the final design's exports, relative to the run's directory.
    final_path : the final design's folding path: the search's, or the one traced once after
    it; None where none was needed or the final design's motion check traced its own.
    final_path_time : seconds of that trace after the search (0 where none ran).
    write_error : why the run's files could not all be written (its verdict says so).
    """

    case: Case
    options: GenerateOptions
    generation: Generation
    records: tuple[SolutionRecord, ...] = ()
    checked: Mapping[int, Checked] = field(default_factory=dict)
    stage_times: Mapping[str, float] = field(default_factory=dict)
    verdict: RunVerdict | None = None
    built: Built | None = None
    exports: tuple[Path, ...] = ()
    final_path: FoldingPath | None = None
    final_path_time: float = 0.0
    write_error: str | None = None

    @property
    def final(self) -> Solution | None:
        """The final design (:attr:`rigidfold.generate.Generation.final`), None without one."""
        return self.generation.final

    @property
    def interrupted(self) -> bool:
        """Whether the run was stopped by Ctrl-C or SIGTERM."""
        return self.generation.stop is Stop.INTERRUPTED

    @property
    def solution_files(self) -> tuple[Path, ...]:
        """The solutions' FOLD files, relative to the run's directory, in order
        (:func:`rigidfold.rundir.layout.solution_file`)."""
        return tuple(solution_file(r.step, r.dof) for r in self.records)  # type: ignore[arg-type]

    @property
    def final_checked(self) -> Checked | None:
        """The final design's checks (Steps 8-9, the motion), None where they did not run."""
        final = self.final
        return None if final is None else self.checked.get(final.step)

    @property
    def final_record(self) -> SolutionRecord | None:
        """The final design's record: the one the verdict names, or the last solution's."""
        if not self.records:
            return None
        final = self.final
        return self.records[-1 if final is None else final.step]

    @property
    def final_verdicts(self) -> str | None:
        """The final design's verdicts of the large-deformation analysis and the folding
        motion in one line, and why they differ when they do
        (:class:`rigidfold.deform.Verdicts`); None without a solution, or when one of the two
        did not run."""
        record = self.final_record
        verdicts = None if record is None else record.verdicts
        return None if verdicts is None else verdicts["line"]

    @property
    def fabrication(self) -> Fabrication | None:
        return None if self.built is None else self.built.fabrication

    @property
    def structure(self) -> StructureCheck | None:
        return None if self.built is None else self.built.structure

    @property
    def drive(self) -> DriveResult | None:
        return None if self.built is None else self.built.drive

    def to_dict(self) -> dict:
        """The run's counters and times (:meth:`rigidfold.generate.Generation.to_dict`, the
        checks' stage times added to ``time_s``), the verdict, the solutions' files and
        records, the exports, the final design's path and the write error; JSON values."""
        out = self.generation.to_dict()
        out["time_s"] = {**out["time_s"], **self.stage_times}
        return {
            **out,
            "verdict": None if self.verdict is None else self.verdict.to_dict(),
            "solutions": [p.as_posix() for p in self.solution_files],
            "per_solution": [r.to_dict(history=False) for r in self.records],
            "checked_steps": sorted(self.checked),
            "exports": [p.as_posix() for p in self.exports],
            "final_path": None if self.final_path is None else self.final_path.to_dict(),
            "final_path_time_s": self.final_path_time,
            "write_error": self.write_error,
        }
