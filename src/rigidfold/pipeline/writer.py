"""Files of a generation run, written as the run goes so an interrupt loses nothing.

``DIR/solutions/step_XX_dof_YY.fold`` for every accepted solution (its folded form and its
figures; for the final design, and every solution with ``--check all``, a ``creasePattern``
frame with its development diagram (Step 8) and the folding motion as ``foldedForm`` frames,
the support panel held still, and the diagram as ``.svg`` beside it), ``DIR/log.jsonl``
(every attempt, a line appended for each: :class:`AttemptLog`) and ``DIR/summary.json`` (a
:class:`~rigidfold.rundir.RunSummary`, :meth:`RunWriter.summary`, written by its ``to_dict``:
the paper's counters, the development and deformation figures (Step 9), each solution's
:class:`~rigidfold.rundir.SolutionRecord`, the options, the verdict and stage times, the
:data:`~rigidfold.rundir.schema.SCHEMA_VERSION`). Every other file is written atomically
(temporary file, then rename), so each one on disk is always valid; the log is only ever
appended to, so a crash can tear only its last line, which its reader skips.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rigidfold.deform import Verification
from rigidfold.drive import DriveResult
from rigidfold.errors import RigidfoldError
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
from rigidfold.generate.case import Case
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
from rigidfold.pipeline.built import check_built_options
from rigidfold.pipeline.checks import (
    Checked,
    check_final,
    check_solution,
    solution_record,
    traced_motion,
)
from rigidfold.pipeline.verdict import RunOutcome, RunVerdict, run_verdict
from rigidfold.rundir.layout import (
    FIGURES_DIR,
    FINAL_DIR,
    REPORT_FILE,
    RUN_FILES,
    TARGET_FILE,
    clear_earlier_run,
    lock_run_dir,
)
from rigidfold.rundir.schema import LOG_FILE, SCHEMA_VERSION, RunSummary, SolutionRecord
from rigidfold.runtime.interrupts import held_interrupts, kept_interrupts
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
    """The attempt log of a run, ``DIR/log.jsonl`` (:data:`~rigidfold.rundir.schema.LOG_FILE`),
    only ever appended to: a header line ``{"schema_version": N}``, then a line per attempt
    (:meth:`rigidfold.generate.Attempt.to_dict`), each flushed and synced as it is written
    (:func:`rigidfold.io.append_json_line`): O(1) per attempt however long the run.

    :meth:`sync` appends the attempts of a run not yet logged, and again those whose outcome
    changed since they were (backtracking: ``dead_end``, and ``accepted`` again), with the
    same ``index``; the reader (:func:`rigidfold.rundir.reader.read_log`) takes the last line
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
        """Create the log with its header, when it is not yet. The file and the note that it
        is made go together (held from a signal): a signal as it was created left the note
        unset, and the interrupted run's summary then failed on "log.jsonl: File exists"."""
        if not self.created:
            with held_interrupts():
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
    checks are the pipeline's (:mod:`rigidfold.pipeline.checks`, the study's too), the writer
    writes their results.

    The development diagram (Step 8), the folding motion and, with ``options.deform``, the
    large-deformation check (Step 9) run on the solutions ``options.check`` names
    (:data:`rigidfold.config.CHECKS`): the final design only, once the run has ended (its
    FOLD file, written without them as it came, is then written with them, and its SVG), or
    every solution as it comes. Writing stays off the search's path: a solution that is not
    checked costs its FOLD file only. An interrupt anywhere ends with :meth:`interrupted`.
    ``overwrite``: replace the files of an earlier run in ``out``
    (:func:`clear_earlier_run`), which are refused otherwise. ``options.target_dof`` is the
    target the verdict (:meth:`finish`) judges by. With ``options.fabricate`` and
    ``options.structure`` the final design's thick panels and structure are checked too
    (:func:`rigidfold.pipeline.checks.check_final`; ``DIR/final/thick/``,
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
        with held_interrupts():  # the lock and the note of it go together
            self.lock = lock_run_dir(self.out)
        try:
            clear_earlier_run(self.out, overwrite=overwrite, inputs=case.inputs)
            self.solutions_dir = prepare_output_dir(self.out / "solutions", within=self.out)
            self.target_file: str | None = None  # a mesh target's spline, for the report
            if isinstance(case.surface, SplineSurface):
                write_json(self.out / TARGET_FILE, case.surface.grid())
                self.target_file = TARGET_FILE
        except BaseException:  # a user error, or Ctrl-C while the directory is prepared
            self.release()
            raise
        self.case, self.options = case, options
        self.run: Generation | None = None  # the run, once an attempt or solution was written
        self.completed = False  # every file of the run is written, its report too
        self.ended = False  # summary.json says it was interrupted, or its files failed
        self.write_error: str | None = None  # why the run's files could not all be written
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
        self.drive: DriveResult | None = None
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

    def interrupted(self, run: Generation | None = None) -> None:
        """Write summary.json of a run stopped by Ctrl-C or SIGTERM, wherever the signal
        landed (in a solve, a diagram, a trace, the final checks, the exports, the report):
        ``run`` (by default the last one the writer saw; None when it was stopped before its
        first attempt ended) with the stop INTERRUPTED, and its verdict
        (:func:`run_verdict`), which names the best design known to deploy, or says that
        none is known (no path is traced, no check is run and nothing is exported); the log
        gets the attempts it has not yet (appended, never rewritten). Further signals are
        held while it writes; a second call does nothing."""
        if self.ended or self.completed:
            return
        with held_interrupts(reraise=False):
            run = run or self.run or Generation()
            run.stop, run.stop_detail = Stop.INTERRUPTED, ""
            best_so_far(run)
            self.verdict = run_verdict(
                run,
                self.records,
                [p.relative_to(self.out) for p in self.files],
                self.options.target_dof,
            )
            final = self.verdict.final_design
            self.final_step = (
                None
                if final is None
                else [p.relative_to(self.out) for p in self.files].index(final)
            )
            self.log.start()
            self.log.sync(run.attempts)
            self.write_summary(run)
            self.ended = True

    def failed(self, error: RigidfoldError) -> None:
        """Write summary.json of a run that ended but whose files could not all be written
        (the final design's, its exports, the report: a full disk, the file size limit):
        its verdict falls short, naming ``error``; ``write_error`` holds it. When even
        summary.json cannot be written, it stays as it was last written."""
        run = self.run or Generation()
        verdict = self.verdict or run_verdict(
            run,
            self.records,
            [p.relative_to(self.out) for p in self.files],
            self.options.target_dof,
        )
        self.write_error = str(error)
        self.verdict = RunVerdict(
            RunOutcome.FELL_SHORT,
            (*verdict.shortfalls, f"the run's files could not all be written: {error}"),
            verdict.warnings,
            verdict.final_design,
        )
        with contextlib.suppress(RigidfoldError):
            self.log.sync(run.attempts)
            self.write_summary(run)
        self.ended = True

    def release(self) -> None:
        """Remove the run's lock on DIR (:func:`lock_run_dir`); call once the run has ended."""
        self.lock.unlink(missing_ok=True)

    def on_attempt(self, run: Generation, attempt: Attempt) -> None:
        """Append the attempt to the log; summary.json is written again when
        ``Settings.generation.summary_interval`` seconds have passed since it last was (a
        solution, a retraction and the end write it every time)."""
        self.run = run
        self.log.sync(run.attempts)
        if attempt.outcome is AttemptOutcome.ACCEPTED:
            return  # its solution (:meth:`on_solution`) writes summary.json next
        interval = self.case.settings.generation.summary_interval
        if time.monotonic() - self.summary_written >= interval:
            self.write_summary(run)

    def on_solution(self, run: Generation, solution: Solution) -> None:
        """Write an accepted solution: with ``--check all`` checked as it comes
        (:func:`rigidfold.pipeline.checks.check_solution`: Step 8, the motion, Step 9 as
        asked) with its FOLD and SVG files; otherwise its FOLD file only (the folded form and
        its figures: :func:`rigidfold.pipeline.checks.solution_record`), its diagram drawn
        if it becomes the final design (:meth:`finish`). Its record and file are added
        together (held from a signal), so summary.json lists only files on disk."""
        self.run = run
        checked = None
        if self.options.check == "all":
            checked = check_solution(
                solution, self.case, self.options, motion=True, deform=self.options.deform
            )
        record = solution_record(solution, self.case) if checked is None else checked.record
        path = self._write_solution(solution, checked)
        with held_interrupts():
            self.solutions.append(solution)
            self.records.append(record)
            self.files.append(path)
            if checked is not None:
                self._keep(solution.step, checked)
        self.log.sync(run.attempts)  # backtracking may have accepted its attempt again
        self.write_summary(run)

    def on_retract(self, run: Generation, taken: tuple[Solution, ...]) -> None:
        """Backtracking or a restart retracted the last solutions (``taken``, the last
        first): their FOLD and SVG files leave ``solutions/`` and their records summary.json
        (the run stays a chain, and the next solution takes the first one's step); their
        attempts are appended to the log again, with the outcome DEAD_END; summary.json is
        written once."""
        self.run = run
        with held_interrupts():  # the records and the files go together
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

    def _keep(self, step: int, checked: Checked) -> None:
        """Note the checks of the solution at ``step``: its record, and the stages' times."""
        for stage, t in checked.record.time_s.items():
            self.stage_times[stage] = self.stage_times.get(stage, 0.0) + t
        self.records[step] = checked.record
        self.checked[step] = checked

    def _write_solution(self, solution: Solution, checked: Checked | None) -> Path:
        """Write the FOLD file of ``solution`` (``solutions/step_XX_dof_YY.fold``): with its
        ``checked`` results (Steps 8-9, :func:`write_checked_shape`) and the SVG of its
        diagram beside it, or without them (the folded form and its figures, no diagram).
        Returns the FOLD path."""
        dof = solution.mechanism.dof
        path = self.solutions_dir / f"step_{solution.step:02d}_dof_{dof:02d}.fold"
        title = f"rigidfold generate: step {solution.step}, DOF {dof}"
        metadata = {
            **self.case.metadata(),
            **solution.result.to_dict(),
            "step": solution.step,
            "dof": dof,
            "criterion": self.options.criterion,
            "lookahead": self.options.lookahead,
        }
        if checked is None:
            write_fold(path, solution.result.pattern, title=title, metadata=metadata)
        else:
            write_checked_shape(
                path,
                solution.result.pattern,
                checked.verification,
                title=title,
                svg_title=f"step {solution.step}, DOF {dof}: development diagram",
                metadata=metadata,
            )
        return path

    def finish(self, run: Generation) -> RunVerdict:
        """The verdict on the finished run (:func:`run_verdict`), written into summary.json,
        and the final design (:attr:`rigidfold.generate.Generation.final`) exported to
        ``DIR/final/`` in every format of :func:`rigidfold.exports.export_design`, named
        after its solution file, the files written together (:meth:`_export`). With
        ``check="final"`` the final design's development diagram (Step 8), folding motion
        and Step 9 run here, once, and its FOLD file is written with them, its SVG beside
        it; its thick panels and structure are checked as the options ask
        (:func:`rigidfold.pipeline.checks.check_final`)."""
        self.run = run
        final = run.final
        if final is not None:
            self.final_step = final.step
            if self.options.check == "final" or final.step not in self.checked:
                checked = check_solution(
                    final, self.case, self.options, motion=True, deform=self.options.deform
                )
                self._write_solution(final, checked)
                with held_interrupts():
                    self.solutions[final.step] = final  # its path may have been traced since
                    self._keep(final.step, checked)
            checked = self.checked[final.step]
            self.final = (final.result.pattern, checked.coords2d)
            o = self.options
            if o.fabricate is not None or o.structure is not None or o.drive is not None:
                name = self.files[final.step].stem
                with kept_interrupts():  # trimesh's code catches BaseException
                    built = check_final(checked, final, self.options, self.out, name)
                self.records[final.step] = built.record
                self.fabrication, self.structure = built.fabrication, built.structure
                self.drive = built.drive
        self.verdict = run_verdict(
            run,
            self.records,
            [p.relative_to(self.out) for p in self.files],
            self.options.target_dof,
        )
        if self.final is not None:
            pattern, coords2d = self.final
            stem = self.files[-1 if final is None else final.step].stem
            self._export(pattern, coords2d, stem)
        self.log.sync(run.attempts)
        self.write_summary(run)
        return self.verdict

    def _export(self, pattern: CreasePattern, coords2d: np.ndarray, stem: str) -> None:
        """The final design's exports (:func:`rigidfold.exports.export_design`), written
        together or not at all: into a new directory of their own in DIR, then, every one
        written, renamed into ``DIR/final/`` while signals are held; a failed write (a full
        disk) or an interrupt leaves none of them (``exports`` stays empty). Third-party
        code that catches BaseException (trimesh, on import and in its functions) cannot
        eat an interrupt: it is raised again when the export ends (:func:`kept_interrupts`)."""
        final_dir = prepare_output_dir(self.out / FINAL_DIR, within=self.out)  # no link
        stage = self.out / f".{FINAL_DIR}.{secrets.token_hex(6)}.tmp"
        try:
            with kept_interrupts():
                written = export_design(
                    pattern, coords2d, stage, name=stem, title=f"rigidfold: {stem}"
                )
            with held_interrupts():
                moved = []
                try:
                    for path in written:
                        os.replace(path, final_dir / path.name)
                        moved.append(final_dir / path.name)
                except OSError as exc:
                    for path in moved:
                        path.unlink(missing_ok=True)
                    raise RigidfoldError(
                        f"cannot write the final design's exports into '{final_dir}': "
                        f"{exc.strerror or exc}"
                    ) from None
                self.exports = moved
        finally:
            with contextlib.suppress(OSError):
                shutil.rmtree(stage)

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
