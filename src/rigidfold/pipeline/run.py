"""One design run: :func:`run` does the search, the checks, the final design's path, the
verdict and the checks of the final design as built, and tells its sinks as it goes.

``run(case, options, sinks)`` runs :func:`rigidfold.generate.generate` (Steps 2-7) and

* checks each accepted solution as ``options.check`` asks
  (:func:`rigidfold.pipeline.checks.check_solution`; a retraction drops its checks);
* once the search has ended, traces the final design's folding path, once, where the search
  has not (:func:`rigidfold.mechanism.path.trace_path` with ``options.support_face``), and
  checks the final design (Steps 8-9 and its folding motion along that path);
* gives the verdict (:func:`rigidfold.pipeline.verdict.run_verdict`), then the final
  design as built (:func:`rigidfold.pipeline.checks.check_final`: thick panels, structure,
  drive) and its exports, into the directory of the sink that has one (``run_dir``: the run
  directory writer, :class:`rigidfold.pipeline.writer.RunWriter`);
* returns a frozen :class:`~rigidfold.pipeline.result.RunResult`.

Its sinks receive the events of :mod:`rigidfold.pipeline.events` as it goes, in order. An
interrupt (Ctrl-C, SIGTERM) anywhere in the run, native code included
(:func:`rigidfold.runtime.interrupts.kept_interrupts`), ends it with
:class:`~rigidfold.pipeline.events.RunInterrupted` (signals held while the sinks handle it),
then :class:`Interrupted` (a KeyboardInterrupt) is raised with the result. A
:class:`~rigidfold.errors.RigidfoldError` before the search has ended (bad input) is raised;
after it, with sinks, the run ends with :class:`~rigidfold.pipeline.events.RunFailed`, its
verdict naming the error (its files could not all be written), and is returned.

``motion``: the command's checks (True): Step 8 and the folding motion of each checked
solution, Step 9 with ``options.deform``. The study's (False): no motion, so Step 8 runs
only with Step 9 (a study writes no diagram), and the final design's path is traced after
the search for its deployability alone (the paper's method).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import time
from collections.abc import Iterable
from dataclasses import replace
from pathlib import Path

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.exports import export_design
from rigidfold.generate import (
    Attempt,
    GenerateOptions,
    Generation,
    Solution,
    Stop,
    best_so_far,
    generate,
)
from rigidfold.generate.budget import time_budget
from rigidfold.generate.case import Case
from rigidfold.io import prepare_output_dir
from rigidfold.mechanism.path import FoldingPath, trace_path
from rigidfold.mesh import CreasePattern
from rigidfold.pipeline.built import check_built_options
from rigidfold.pipeline.checks import Built, Checked, check_final, check_solution, solution_record
from rigidfold.pipeline.events import (
    AttemptEnded,
    Event,
    FinalChecked,
    RunEnded,
    RunFailed,
    RunInterrupted,
    Sink,
    SolutionAccepted,
    SolutionsRetracted,
)
from rigidfold.pipeline.result import RunResult
from rigidfold.pipeline.verdict import RunOutcome, RunVerdict, run_verdict
from rigidfold.rundir.layout import FINAL_DIR, solution_file
from rigidfold.rundir.schema import SolutionRecord
from rigidfold.runtime.interrupts import held_interrupts, kept_interrupts


class Interrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C or SIGTERM, once its sinks were told
    (:class:`~rigidfold.pipeline.events.RunInterrupted`): ``result`` is the run as it
    stood, its verdict naming the best design known to deploy or none."""

    def __init__(self, result: RunResult) -> None:
        super().__init__()
        self.result = result


def run(
    case: Case,
    options: GenerateOptions,
    sinks: Iterable[Sink] = (),
    *,
    motion: bool = True,
    started: float | None = None,
) -> RunResult:
    """Run the design ``case`` with ``options``, telling ``sinks`` as it goes; see the
    module's text. ValueError (one line) before anything runs for supports, actuators or
    loads the crease pattern lacks, and for as-built checks without a sink with a
    ``run_dir`` to write their files into.

    ``started``: the time of ``time.monotonic()`` that ``options.time_limit`` T counts from
    (default: now; the command line gives its process's start). The run ends by T + two
    graces, T + max(10 s, 5 % of T) with the defaults: the search stops before T by what
    the final design's margin, checks, exports and report are estimated to take beyond
    half a grace (from the pattern's size), naming the final design ends a grace after the
    search, the final design's folding path a grace and a half (a trace it cuts makes the
    motion ``cut``) (:mod:`rigidfold.generate.budget`)."""
    return _Run(case, options, tuple(sinks), motion, started).go()


def stopped(result: RunResult) -> RunResult:
    """``result`` of a run stopped by Ctrl-C or SIGTERM, wherever the signal landed (in a
    solve, a diagram, a trace, the final checks, the exports): its stop INTERRUPTED, its
    final design the best known to deploy (:func:`rigidfold.generate.best_so_far`), and
    its verdict (:func:`run_verdict`), which names that design or says that none is known
    (no path is traced, no check is run and nothing is exported)."""
    generation = result.generation
    generation.stop, generation.stop_detail = Stop.INTERRUPTED, ""
    best_so_far(generation)
    files = list(result.solution_files)
    verdict = run_verdict(
        generation, list(result.records), files, result.options.target_dof, result.case.settings
    )
    return replace(result, verdict=verdict)


class _Run:
    """The state of one run while it goes; :meth:`result` is its snapshot."""

    def __init__(
        self,
        case: Case,
        options: GenerateOptions,
        sinks: tuple[Sink, ...],
        motion: bool,
        started: float | None = None,
    ) -> None:
        check_built_options(case.pattern, options)
        self.started = time.monotonic() if started is None else started
        # the final design's path and motion end 1.5 graces after the search's end
        self.budget = time_budget(
            self.started, options.time_limit, case.pattern.n_vertices, case.settings
        )
        self.run_dir: Path | None = next(
            (d for s in sinks if (d := getattr(s, "run_dir", None)) is not None), None
        )
        built = options.fabricate, options.structure, options.drive
        if self.run_dir is None and any(b is not None for b in built):
            raise RigidfoldError(
                "the final design's thick panels, structure and drive write their files into "
                "a run directory: give run() a sink with one (RunWriter)"
            )
        self.case, self.options, self.sinks, self.motion = case, options, sinks, motion
        self.checks = motion or options.deform  # the study: Step 8 only with Step 9
        self.every = self.checks and options.check == "all"
        self.generation: Generation | None = None
        self.records: list[SolutionRecord] = []
        self.checked: dict[int, Checked] = {}
        self.stage_times = {"develop": 0.0, "deform": 0.0, "motion": 0.0}
        self.verdict: RunVerdict | None = None
        self.built: Built | None = None
        self.exports: tuple[Path, ...] = ()
        self.final_path: FoldingPath | None = None
        self.final_path_time = 0.0
        self.ended: RunResult | None = None  # the run's result, once it has ended
        self.received: list[int] = []  # the signals kept_interrupts noted

    def result(self, **changes) -> RunResult:
        """The run as it stands, with ``changes`` to its fields."""
        result = RunResult(
            self.case,
            self.options,
            self.generation or Generation(),
            tuple(self.records),
            dict(self.checked),
            dict(self.stage_times),
            self.verdict,
            self.built,
            self.exports,
            self.final_path,
            self.final_path_time,
        )
        return replace(result, **changes) if changes else result

    def emit(self, event: Event) -> None:
        for sink in self.sinks:
            sink.on_event(event)

    def go(self) -> RunResult:
        try:
            # CasADi, IPOPT, trimesh, matplotlib: native code never eats an interrupt
            with kept_interrupts() as self.received:
                self.generation = generate(
                    self.case,
                    self.options,
                    on_attempt=self.on_attempt,
                    on_solution=self.on_solution,
                    on_retract=self.on_retract,
                    started=self.started,
                )
                result = self.finish(self.generation)
            self.ended = result  # from here a signal does not make it an interrupted run
            return result
        except KeyboardInterrupt:
            if self.ended is not None:  # it came as the run returned
                return self.ended
            raise Interrupted(self.interrupted()) from None
        except RigidfoldError as exc:
            if not self.sinks or self.generation is None or self.generation.stop is Stop.RUNNING:
                raise  # the search's: bad input; without sinks, the caller's to record
            return self.failed(exc)

    # ------------------------------------------------------------------------ the search
    def on_attempt(self, generation: Generation, attempt: Attempt) -> None:
        if self.received:
            raise KeyboardInterrupt  # native code ate it: the run stops here
        self.generation = generation
        self.emit(AttemptEnded(self.result(), attempt))

    def on_solution(self, generation: Generation, solution: Solution) -> None:
        """Check an accepted solution as ``options.check`` asks; its record is kept once
        the sinks have handled it (so a run directory lists only files on disk)."""
        if self.received:
            raise KeyboardInterrupt
        self.generation = generation
        checked = None
        if self.every:
            checked = self.check(solution)
        record = solution_record(solution, self.case) if checked is None else checked.record
        self.emit(SolutionAccepted(self.result(records=(*self.records, record)), solution, checked))
        with held_interrupts():  # the record and its checks go together
            self.records.append(record)
            if checked is not None:
                self.checked[solution.step] = checked

    def on_retract(self, generation: Generation, taken: tuple[Solution, ...]) -> None:
        """Backtracking or a restart took back the last solutions: their records and checks
        go first (so a run directory never lists a file removed)."""
        self.generation = generation
        with held_interrupts():
            for solution in taken:
                assert self.records and self.records[-1].step == solution.step, "not the last"
                self.records.pop()
                self.checked.pop(solution.step, None)
        self.emit(SolutionsRetracted(self.result(), tuple(taken)))

    def check(self, solution: Solution, path: FoldingPath | None = None) -> Checked:
        """The checks of ``solution`` as the run asks (:func:`check_solution`: the motion
        with ``motion``, Step 9 with ``options.deform``; ``path`` its traced folding path),
        their seconds added to the stage times."""
        checked = check_solution(
            solution,
            self.case,
            self.options,
            motion=self.motion,
            deform=self.options.deform,
            path=path,
        )
        self.add_times(checked)
        return checked

    def add_times(self, checked: Checked) -> None:
        for stage, t in checked.record.time_s.items():
            self.stage_times[stage] = self.stage_times.get(stage, 0.0) + t

    # -------------------------------------------------------------------------- the end
    def finish(self, generation: Generation) -> RunResult:
        """The final design's path and checks, the verdict, the final design as built and
        its exports; :class:`RunEnded`."""
        final = generation.final
        if final is not None:
            self.final_path = final.path
            checked = self.checked.get(final.step)
            again = self.checks and (self.options.check == "final" or checked is None)
            if not self.motion or (again and final.mechanism.dof > 0):
                self.final_path = self.trace_final(final)
            if again:
                checked = self.check(final, self.final_path)
                if self.motion:  # the trace is the motion's
                    self.stage_times["motion"] += self.final_path_time
                self.emit(FinalChecked(self.result(), final, checked))
                with held_interrupts():
                    self.records[final.step] = checked.record
                    self.checked[final.step] = checked
            self.built_checks(final, checked)
        files = [solution_file(r.step, r.dof) for r in self.records]  # type: ignore[arg-type]
        self.verdict = run_verdict(
            generation, self.records, files, self.options.target_dof, self.case.settings
        )
        checked = None if final is None else self.checked.get(final.step)
        if final is not None and checked is not None and self.run_dir is not None:
            self.export(final.result.pattern, checked.coords2d, files[final.step].stem)
        result = self.result()
        self.emit(RunEnded(result))
        return result

    def trace_final(self, final: Solution) -> FoldingPath:
        """The final design's folding path: the search's, or traced here, once
        (``options.support_face``, the run's settings); its seconds in
        ``final_path_time``."""
        if final.path is not None:
            return final.path
        t0 = time.perf_counter()
        path = trace_path(
            final.result.pattern,
            dof=final.mechanism.dof,
            support_face=self.options.support_face,
            settings=self.case.settings,
            deadline=None if self.budget is None else self.budget.path,
        )
        self.final_path_time = time.perf_counter() - t0
        return path

    def built_checks(self, final: Solution, checked: Checked | None) -> None:
        """The final design as built, as the options ask (:func:`check_final`), its files in
        the sink's run directory."""
        o = self.options
        if checked is None or self.run_dir is None:
            return
        if o.fabricate is None and o.structure is None and o.drive is None:
            return
        name = solution_file(final.step, final.mechanism.dof).stem
        with kept_interrupts():  # trimesh's code catches BaseException
            built = check_final(checked, final, o, self.run_dir, name)
        with held_interrupts():
            self.records[final.step] = built.record
            self.built = built

    def export(self, pattern: CreasePattern, coords2d: np.ndarray, stem: str) -> None:
        """The final design's exports (:func:`rigidfold.exports.export_design`), written
        together or not at all: into a new directory of their own in the run directory,
        then, every one written, renamed into ``DIR/final/`` while signals are held; a
        failed write (a full disk) or an interrupt leaves none of them (``exports`` stays
        empty). Third-party code that catches BaseException (trimesh, on import and in its
        functions) cannot eat an interrupt: it is raised again when the export ends
        (:func:`kept_interrupts`)."""
        out = self.run_dir
        assert out is not None
        final_dir = prepare_output_dir(out / FINAL_DIR, within=out)  # no link
        stage = out / f".{FINAL_DIR}.{secrets.token_hex(6)}.tmp"
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
                self.exports = tuple(p.relative_to(out) for p in moved)
        finally:
            with contextlib.suppress(OSError):
                shutil.rmtree(stage)

    def interrupted(self) -> RunResult:
        """The run stopped by Ctrl-C or SIGTERM (:func:`stopped`); :class:`RunInterrupted`,
        signals held while the sinks handle it."""
        with held_interrupts(reraise=False):
            result = stopped(self.result())
            self.generation, self.verdict = result.generation, result.verdict
            self.emit(RunInterrupted(result))
        return result

    def failed(self, error: RigidfoldError) -> RunResult:
        """The run ended but its files could not all be written: its verdict falls short,
        naming ``error``; :class:`RunFailed` (a sink that cannot write even then keeps what
        it wrote last)."""
        generation = self.generation
        assert generation is not None
        files = [solution_file(r.step, r.dof) for r in self.records]  # type: ignore[arg-type]
        verdict = self.verdict or run_verdict(
            generation, self.records, files, self.options.target_dof, self.case.settings
        )
        self.verdict = RunVerdict(
            RunOutcome.FELL_SHORT,
            (*verdict.shortfalls, f"the run's files could not all be written: {error}"),
            verdict.warnings,
            verdict.final_design,
        )
        result = self.result(write_error=str(error))
        for sink in self.sinks:
            with contextlib.suppress(RigidfoldError):
                sink.on_event(RunFailed(result))
        self.ended = result
        return result
