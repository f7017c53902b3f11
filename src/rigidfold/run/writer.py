"""Files of a generation run, written as the run goes so an interrupt loses nothing.

``DIR/solutions/step_XX_dof_YY.fold`` for every accepted solution (its folded form, a
``creasePattern`` frame with its development diagram (Step 8) and the folding motion as
``foldedForm`` frames, the support panel held still) and ``.svg`` beside it, ``DIR/log.jsonl``
(every attempt, a line appended for each: :class:`AttemptLog`) and ``DIR/summary.json`` (a
:class:`~rigidfold.run.RunSummary`, :meth:`RunWriter.summary`, written by its ``to_dict``:
the paper's counters, the development and deformation figures (Step 9), each solution's
:class:`~rigidfold.run.SolutionRecord`, the options, the verdict and stage times, the
:data:`~rigidfold.run.schema.SCHEMA_VERSION`). Every other file is written atomically
(temporary file, then rename), so each one on disk is always valid; the log is only ever
appended to, so a crash can tear only its last line, which its reader skips.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rigidfold.case import Case
from rigidfold.deform import Verification
from rigidfold.exports import export_design
from rigidfold.fabricate import Fabrication
from rigidfold.generate import (
    Attempt,
    AttemptOutcome,
    GenerateOptions,
    Generation,
    Solution,
    Stop,
    best_so_far,
)
from rigidfold.io import (
    FoldData,
    append_json_line,
    atomic_write,
    crease_pattern_frame,
    motion_frames,
    prepare_output_dir,
    refuse_replacing_inputs,
    round_trip_dict,
    write_document,
    write_fold,
    write_json,
    write_svg,
)
from rigidfold.mesh import CreasePattern
from rigidfold.run.built import check_built_options
from rigidfold.run.checks import Checked, check_final, check_solution, traced_motion
from rigidfold.run.lock import (
    FIGURES_DIR,
    FINAL_DIR,
    REPORT_FILE,
    RUN_FILES,
    TARGET_FILE,
    clear_earlier_run,
    lock_run_dir,
)
from rigidfold.run.schema import LOG_FILE, SCHEMA_VERSION, RunSummary, SolutionRecord
from rigidfold.run.verdict import RunVerdict, run_verdict
from rigidfold.structure import StructureCheck
from rigidfold.surfaces import SplineSurface


def verification_frames(pattern: CreasePattern, check: Verification) -> list[dict]:
    """FOLD ``file_frames`` of a checked shape ``pattern``: its development diagram
    (``creasePattern``), then its folding motion from flat to folded (``foldedForm``, each
    frame with its own fold angles) when it was traced."""
    frames = [crease_pattern_frame(check.development.coords2d)]
    motion = traced_motion(check)
    if motion is not None:
        frames += motion_frames(pattern, *motion)
    return frames


def write_checked_shape(
    path: Path,
    pattern: CreasePattern,
    check: Verification,
    *,
    title: str,
    metadata: dict,
    svg_title: str,
    source: FoldData | None = None,
) -> list[Path]:
    """Write a shape checked by Steps 8-9: ``path`` (FOLD) and the development diagram
    beside it as SVG. Returns [FOLD, SVG].

    Without ``source`` the FOLD is written from scratch: the folded form titled ``title``,
    its development diagram and motion frames (:func:`verification_frames`), ``metadata``
    and every figure of the check. With ``source`` (the FOLD file read, whose pattern is
    ``pattern``) it is that file's document, kept whole, plus rigidfold's frames
    (development diagram, motion, folded form) and keys
    (:func:`rigidfold.io.round_trip_dict`), and the SVG keeps the file's crease assignment.
    """
    coords2d = check.development.coords2d
    figures = {**metadata, **check.to_dict()}
    if source is None:
        letters = None
        fold = write_fold(
            path, pattern, frames=verification_frames(pattern, check), title=title, metadata=figures
        )
    else:
        letters = source.shape_assignment()
        document = round_trip_dict(
            source, coords2d, motion=traced_motion(check), title=title, metadata=figures
        )
        fold = write_document(path, document)
    svg = write_svg(
        path.with_suffix(".svg"), pattern, coords2d, title=svg_title, assignment=letters
    )
    return [fold, svg]


class AttemptLog:
    """The attempt log of a run, ``DIR/log.jsonl`` (:data:`~rigidfold.run.schema.LOG_FILE`),
    only ever appended to: a header line ``{"schema_version": N}``, then a line per attempt
    (:meth:`rigidfold.generate.Attempt.to_dict`), each flushed and synced as it is written
    (:func:`rigidfold.io.append_json_line`): O(1) per attempt however long the run.

    :meth:`sync` appends the attempts of a run not yet logged, and again those whose outcome
    changed since they were (backtracking: ``dead_end``, and ``accepted`` again), with the
    same ``index``; the reader (:func:`rigidfold.run.reader.read_log`) takes the last line
    of each index. The file is created (exclusively, no symbolic link followed) with the
    first line written.
    """

    _CHANGING = frozenset({AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END})
    """The outcomes that may change after an attempt was logged (backtracking)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.outcomes: list[AttemptOutcome] = []  # the outcome last logged, by index
        self.changing: set[int] = set()  # the indices whose outcome may still change
        self.created = False

    def sync(self, attempts: list[Attempt]) -> None:
        """Append the attempts not logged yet and those whose outcome changed."""
        for k in sorted(self.changing):
            if attempts[k].outcome is not self.outcomes[k]:
                self._append(attempts[k])
        for attempt in attempts[len(self.outcomes) :]:
            self._append(attempt)

    def start(self) -> None:
        """Create the log with its header, when it is not yet."""
        if not self.created:
            append_json_line(self.path, {"schema_version": SCHEMA_VERSION}, create=True)
            self.created = True

    def _append(self, attempt: Attempt) -> None:
        self.start()
        append_json_line(self.path, attempt.to_dict())
        k = attempt.index
        if k == len(self.outcomes):
            self.outcomes.append(attempt.outcome)
        else:
            self.outcomes[k] = attempt.outcome
        if attempt.outcome in self._CHANGING:
            self.changing.add(k)
        else:
            self.changing.discard(k)


class RunWriter:
    """Callbacks for :func:`rigidfold.generate.generate` that keep DIR up to date: the
    checks are the pipeline's (:mod:`rigidfold.run.checks`, the study's too), the writer
    writes their results.

    The development diagram (Step 8) runs on every solution as it comes; the folding motion
    and, with ``options.deform``, the large-deformation check (Step 9) run on the solutions
    ``options.check`` names (:data:`rigidfold.config.CHECKS`): the final design only, once
    the run has ended (its FOLD file is then written again with them), or every solution as
    it comes. ``overwrite``: replace the files of an earlier run in ``out``
    (:func:`clear_earlier_run`), which are refused otherwise. ``options.target_dof`` is the
    target the verdict (:meth:`finish`) judges by. With ``options.fabricate`` and
    ``options.structure`` the final design's thick panels and structure are checked too
    (:func:`rigidfold.run.checks.check_final`; ``DIR/final/thick/``,
    ``DIR/final/structure/``), their
    figures in its record; ``fabrication`` and ``structure`` hold the results.
    """

    def __init__(
        self,
        out: str | Path,
        case: Case,
        options: GenerateOptions,
        *,
        overwrite: bool = False,
    ) -> None:
        refuse_replacing_inputs(case.inputs, [Path(out) / name for name in RUN_FILES])
        check_built_options(case.pattern, options)
        self.out = prepare_output_dir(out)
        self.lock = lock_run_dir(self.out)
        try:
            clear_earlier_run(self.out, overwrite=overwrite, inputs=case.inputs)
            self.solutions_dir = prepare_output_dir(self.out / "solutions", within=self.out)
            self.target_file: str | None = None  # a mesh target's spline, for the report
            if isinstance(case.surface, SplineSurface):
                write_json(self.out / TARGET_FILE, case.surface.grid())
                self.target_file = TARGET_FILE
        except ValueError:
            self.release()
            raise
        self.case, self.options = case, options
        self.solutions: list[Solution] = []
        self.checked: dict[int, Checked] = {}  # step -> its checks (development, motion)
        self.files: list[Path] = []
        self.records: list[SolutionRecord] = []
        self.stage_times = {"develop": 0.0, "deform": 0.0, "motion": 0.0}
        self.verdict: RunVerdict | None = None
        self.final: tuple[CreasePattern, np.ndarray] | None = None
        self.final_step: int | None = None
        self.exports: list[Path] = []
        self.fabrication: Fabrication | None = None
        self.structure: StructureCheck | None = None
        self.log = AttemptLog(self.out / LOG_FILE)
        self.summary_written = -float("inf")  # time.monotonic() of the last summary.json

    @property
    def final_verdicts(self) -> str | None:
        """The final design's verdicts of the large-deformation analysis and the folding motion
        in one line, and why they differ when they do (:class:`rigidfold.deform.Verdicts`);
        None without a solution, or when one of the two did not run."""
        if not self.records:
            return None
        step = -1 if self.final_step is None else self.final_step
        verdicts = self.records[step].verdicts
        return None if verdicts is None else verdicts["line"]

    def interrupted(self, run: Generation | None) -> None:
        """Write summary.json of a run stopped by Ctrl-C or SIGTERM: ``run`` (None when it
        was stopped before its first attempt ended) with the stop INTERRUPTED, its best
        design so far named (:func:`rigidfold.generate.best_so_far`: no path is traced, no
        check is run and nothing is exported) and its verdict (fell short); the log gets the
        attempts it has not yet (appended, never rewritten)."""
        if run is None:
            run = Generation()
        run.stop, run.stop_detail = Stop.INTERRUPTED, ""
        best_so_far(run)
        final = run.final
        if final is not None and final.step < len(self.files):
            self.final_step = final.step
        self.verdict = run_verdict(
            run,
            self.records,
            [p.relative_to(self.out) for p in self.files],
            self.options.target_dof,
        )
        self.log.start()
        self.log.sync(run.attempts)
        self.write_summary(run)

    def release(self) -> None:
        """Remove the run's lock on DIR (:func:`lock_run_dir`); call once the run has ended."""
        self.lock.unlink(missing_ok=True)

    def on_attempt(self, run: Generation, attempt: Attempt) -> None:
        """Append the attempt to the log; summary.json is written again when
        ``Settings.generation.summary_interval`` seconds have passed since it last was (a
        solution, a retraction and the end write it every time)."""
        self.log.sync(run.attempts)
        if attempt.outcome is AttemptOutcome.ACCEPTED:
            return  # its solution (:meth:`on_solution`) writes summary.json next
        interval = self.case.settings.generation.summary_interval
        if time.monotonic() - self.summary_written >= interval:
            self.write_summary(run)

    def on_solution(self, run: Generation, solution: Solution) -> None:
        full = self.options.check == "all"
        self.solutions.append(solution)
        self.records.append(SolutionRecord(solution.step, solution.mechanism.dof))
        deform = full and self.options.deform
        self.files.append(self._write_solution(solution, deform=deform, motion=full))
        self.log.sync(run.attempts)  # backtracking may have accepted its attempt again
        self.write_summary(run)

    def on_retract(self, run: Generation, taken: tuple[Solution, ...]) -> None:
        """Backtracking or a restart retracted the last solutions (``taken``, the last
        first): their FOLD and SVG files leave ``solutions/`` and their records summary.json
        (the run stays a chain, and the next solution takes the first one's step); their
        attempts are appended to the log again, with the outcome DEAD_END; summary.json is
        written once."""
        for solution in taken:
            assert self.solutions and self.solutions[-1] is solution, "not the last solution"
            self.solutions.pop()
            self.records.pop()
            self.checked.pop(solution.step, None)
            fold = self.files.pop()
            for path in (fold, fold.with_suffix(".svg")):
                path.unlink(missing_ok=True)
        self.log.sync(run.attempts)
        self.write_summary(run)

    def _write_solution(self, solution: Solution, *, deform: bool, motion: bool) -> Path:
        """Check one solution (:func:`rigidfold.run.checks.check_solution`: Step 8; the
        motion and Step 9 as asked) and write its FOLD and SVG files; its record replaces
        ``records[solution.step]``. Returns the FOLD path."""
        checked = check_solution(solution, self.case, self.options, motion=motion, deform=deform)
        for stage, t in checked.record.time_s.items():
            self.stage_times[stage] += t
        self.records[solution.step] = checked.record
        self.checked[solution.step] = checked
        dof = solution.mechanism.dof
        path = self.solutions_dir / f"step_{solution.step:02d}_dof_{dof:02d}.fold"
        write_checked_shape(
            path,
            solution.result.pattern,
            checked.verification,
            title=f"rigidfold generate: step {solution.step}, DOF {dof}",
            svg_title=f"step {solution.step}, DOF {dof}: development diagram",
            metadata={
                **self.case.metadata(),
                **solution.result.to_dict(),
                "step": solution.step,
                "dof": dof,
                "criterion": self.options.criterion,
                "lookahead": self.options.lookahead,
            },
        )
        return path

    def finish(self, run: Generation) -> RunVerdict:
        """The verdict on the finished run (:func:`run_verdict`), written into summary.json,
        and the final design (:attr:`rigidfold.generate.Generation.final`) exported to
        ``DIR/final/`` in every format of :func:`rigidfold.exports.export_design`, named
        after its solution file. With ``check="final"`` the final design's folding motion and
        Step 9 run first and its files are written again with them; its thick panels and
        structure are checked as the options ask (:func:`rigidfold.run.checks.check_final`)."""
        final = run.final
        if final is not None:
            self.final_step = final.step
            if self.options.check == "final":
                self.solutions[final.step] = final  # its path may have been traced since
                self._write_solution(final, deform=self.options.deform, motion=True)
            checked = self.checked[final.step]
            self.final = (final.result.pattern, checked.coords2d)
            if self.options.fabricate is not None or self.options.structure is not None:
                name = self.files[final.step].stem
                built = check_final(checked, final, self.options, self.out, name)
                self.records[final.step] = built.record
                self.fabrication, self.structure = built.fabrication, built.structure
        self.verdict = run_verdict(
            run,
            self.records,
            [p.relative_to(self.out) for p in self.files],
            self.options.target_dof,
        )
        if self.final is not None:
            pattern, coords2d = self.final
            stem = self.files[-1 if final is None else final.step].stem
            final_dir = prepare_output_dir(self.out / FINAL_DIR, within=self.out)  # no link
            self.exports = export_design(
                pattern, coords2d, final_dir, name=stem, title=f"rigidfold: {stem}"
            )
        self.log.sync(run.attempts)
        self.write_summary(run)
        return self.verdict

    def summary(self, run: Generation) -> RunSummary:
        """summary.json's record of the run as it stands now."""
        return RunSummary.from_run(
            run,
            self.records,
            stage_times=self.stage_times,
            options=self.options.to_dict() | {"symmetric": bool(self.case.planes)},
            case=self.case.metadata(),
            solutions=tuple(str(p.relative_to(self.out)) for p in self.files),
            verdict=None if self.verdict is None else self.verdict.to_dict(),
            exports=tuple(str(p.relative_to(self.out)) for p in self.exports),
            target_surface=self.target_file,
        )

    def write_summary(self, run: Generation) -> None:
        """Write summary.json (atomically) as the run stands now (:meth:`summary`)."""
        write_json(self.out / "summary.json", self.summary(run).to_dict())
        self.summary_written = time.monotonic()


def write_report(
    directory: Path, html: str, figures: Sequence[tuple[str, bytes]]
) -> tuple[Path, tuple[Path, ...]]:
    """The report of the run in ``directory``: each (name, PNG) of ``figures`` as
    ``DIR/figures/NAME`` and the page ``html`` as ``DIR/report.html``, each written
    atomically. Returns (the page, the figures)."""
    figure_dir = prepare_output_dir(directory / FIGURES_DIR, within=directory)
    written = tuple(atomic_write(figure_dir / name, png) for name, png in figures)
    return atomic_write(directory / REPORT_FILE, html), written
