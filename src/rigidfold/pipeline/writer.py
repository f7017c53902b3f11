"""Files of a generation run, written as the run goes so an interrupt loses nothing.

:class:`RunWriter` is a sink of :func:`rigidfold.pipeline.run` (:mod:`rigidfold.pipeline.events`).
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
import time
from pathlib import Path

from rigidfold.deform import Verification
from rigidfold.errors import RigidfoldError
from rigidfold.generate import (
    Attempt,
    AttemptOutcome,
    GenerateOptions,
    Generation,
    Solution,
)
from rigidfold.generate.case import Case
from rigidfold.io import (
    FoldData,
    append_json_line,
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
from rigidfold.pipeline import events as ev
from rigidfold.pipeline.built import check_built_options
from rigidfold.pipeline.checks import Checked, traced_motion
from rigidfold.pipeline.report import report_run
from rigidfold.pipeline.result import RunResult
from rigidfold.pipeline.run import stopped
from rigidfold.rundir.layout import (
    RUN_FILES,
    SOLUTIONS_DIR,
    TARGET_FILE,
    clear_earlier_run,
    lock_run_dir,
    solution_file,
)
from rigidfold.rundir.schema import LOG_FILE, SCHEMA_VERSION, RunSummary
from rigidfold.runtime.interrupts import held_interrupts
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

    _CHANGING = frozenset({AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END, AttemptOutcome.NO_GAP})
    """The outcomes that may change after an attempt was logged (backtracking; a fallback
    design without a clear gap taken at the end)."""

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
    """The run directory of ``rigidfold generate``, a sink of :func:`rigidfold.pipeline.run`
    (:mod:`rigidfold.pipeline.events`): it writes the files of the run from its events, so
    an interrupt loses nothing, and computes nothing.

    * :class:`~rigidfold.pipeline.events.AttemptEnded`: the attempt appended to the log;
      summary.json again when ``Settings.generation.summary_interval`` seconds have passed
      since it last was (a solution, a retraction and the end write it every time).
    * :class:`~rigidfold.pipeline.events.SolutionAccepted`: its FOLD file (with its checks
      and the SVG of its diagram where they ran, :func:`write_checked_shape`; else its
      folded form and figures), then summary.json.
    * :class:`~rigidfold.pipeline.events.SolutionsRetracted`: their FOLD and SVG files
      leave ``solutions/``; their attempts are appended to the log again (DEAD_END).
    * :class:`~rigidfold.pipeline.events.FinalChecked`: the final design's FOLD file again,
      with its checks, and its SVG.
    * :class:`~rigidfold.pipeline.events.RunEnded`: summary.json with the verdict, then,
      with ``report``, ``DIR/report.html`` (:func:`rigidfold.pipeline.report.report_run`).
    * :class:`~rigidfold.pipeline.events.RunInterrupted`,
      :class:`~rigidfold.pipeline.events.RunFailed`: summary.json of the run as it stopped
      (signals held while it is written; a failed write keeps the one written last).

    ``run_dir`` (DIR) is where the run writes the final design's as-built checks and exports
    (:func:`rigidfold.pipeline.checks.check_final`). ``overwrite``: replace the files of an
    earlier run in ``out`` (:func:`clear_earlier_run`), which are refused otherwise. The lock
    on DIR is taken when it is made and released when the run ends, or when a ``with`` block
    around it ends, however (:meth:`release`). :meth:`interrupted` writes summary.json of an
    interrupt that came outside the run (before it began); ``result`` is the run's result
    once the writer has written its end.
    """

    def __init__(
        self,
        out: str | Path,
        case: Case,
        options: GenerateOptions,
        *,
        overwrite: bool = False,
        report: bool = True,
    ) -> None:
        refuse_replacing_inputs(case.inputs, [Path(out) / name for name in RUN_FILES])
        check_built_options(case.pattern, options)
        self.out = prepare_output_dir(out)
        with held_interrupts():  # the lock and the note of it go together
            self.lock = lock_run_dir(self.out)
        try:
            clear_earlier_run(self.out, overwrite=overwrite, inputs=case.inputs)
            self.solutions_dir = prepare_output_dir(self.out / SOLUTIONS_DIR, within=self.out)
            self.target_file: str | None = None  # a mesh target's spline, for the report
            if isinstance(case.surface, SplineSurface):
                write_json(self.out / TARGET_FILE, case.surface.grid())
                self.target_file = TARGET_FILE
        except BaseException:  # a user error, or Ctrl-C while the directory is prepared
            self.release()
            raise
        self.case, self.options, self.report = case, options, report
        self.seen: RunResult | None = None  # the run as last written
        self.result: RunResult | None = None  # the run's result, once its end is written
        self.log = AttemptLog(self.out / LOG_FILE)
        self.summary_written = -float("inf")  # time.monotonic() of the last summary.json

    @property
    def run_dir(self) -> Path:
        """The run's directory: the pipeline's as-built checks and exports write there."""
        return self.out

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def release(self) -> None:
        """Remove the run's lock on DIR (:func:`lock_run_dir`); again changes nothing."""
        self.lock.unlink(missing_ok=True)

    def on_event(self, event: ev.Event) -> None:
        match event:
            case ev.AttemptEnded(result, attempt):
                self.log.sync(result.generation.attempts)
                interval = self.case.settings.generation.summary_interval
                if attempt.outcome is not AttemptOutcome.ACCEPTED and (
                    time.monotonic() - self.summary_written >= interval
                ):
                    self.write_summary(result)  # an accepted one: its solution's writes it
            case ev.SolutionAccepted(result, solution, checked):
                self._write_solution(solution, checked)
                self.log.sync(result.generation.attempts)  # backtracking: accepted again
                self.write_summary(result)
            case ev.SolutionsRetracted(result, taken):
                with held_interrupts():  # the files go together
                    for solution in taken:
                        fold = self.out / solution_file(solution.step, solution.mechanism.dof)
                        for path in (fold, fold.with_suffix(".svg")):
                            path.unlink(missing_ok=True)
                self.log.sync(result.generation.attempts)
                self.write_summary(result)
            case ev.FinalChecked(result, solution, checked):
                self._write_solution(solution, checked)
                self.seen = result
            case ev.RunEnded(result):
                self.log.sync(result.generation.attempts)
                self.write_summary(result)
                if self.report:
                    report_run(self.out)
                self._end(result)
            case ev.RunInterrupted(result):
                with held_interrupts(reraise=False):
                    self.log.start()
                    self.log.sync(result.generation.attempts)
                    self.write_summary(result)
                    self._end(result)
            case ev.RunFailed(result):
                with contextlib.suppress(RigidfoldError):
                    self.log.sync(result.generation.attempts)
                    self.write_summary(result)
                self._end(result)

    def _end(self, result: RunResult) -> None:
        self.result = result
        self.release()

    def interrupted(self) -> RunResult:
        """The run's result once the writer has written its end; otherwise (an interrupt
        that came outside the run: before it began) summary.json of the run as last written
        (none: stopped before its first attempt ended) with the stop INTERRUPTED and its
        verdict (:func:`rigidfold.pipeline.run.stopped`), the log's missing attempts
        appended, signals held."""
        if self.result is not None:
            return self.result
        with held_interrupts(reraise=False):
            result = stopped(self.seen or RunResult(self.case, self.options, Generation()))
            self.log.start()
            self.log.sync(result.generation.attempts)
            self.write_summary(result)
            self._end(result)
        return result

    def _write_solution(self, solution: Solution, checked: Checked | None) -> Path:
        """Write the FOLD file of ``solution`` (``solutions/step_XX_dof_YY.fold``): with its
        ``checked`` results (Steps 8-9, :func:`write_checked_shape`) and the SVG of its
        diagram beside it, or without them (the folded form and its figures, no diagram).
        Returns the FOLD path."""
        dof = solution.mechanism.dof
        path = self.out / solution_file(solution.step, dof)
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

    def summary(self, result: RunResult) -> RunSummary:
        """summary.json's record of the run ``result``."""
        return RunSummary.from_run(
            result.generation,
            list(result.records),
            stage_times=dict(result.stage_times),
            options=self.options.to_dict() | {"symmetric": bool(self.case.planes)},
            case=self.case.metadata(),
            solutions=tuple(str(p) for p in result.solution_files),
            verdict=None if result.verdict is None else result.verdict.to_dict(),
            exports=tuple(str(p) for p in result.exports),
            target_surface=self.target_file,
        )

    def write_summary(self, result: RunResult) -> None:
        """Write summary.json (atomically) of the run ``result`` (:meth:`summary`)."""
        write_json(self.out / "summary.json", self.summary(result).to_dict())
        self.summary_written = time.monotonic()
        self.seen = result
