"""Files of a generation run, written as the run goes so an interrupt loses nothing.

``DIR/solutions/step_XX_dof_YY.fold`` for every accepted solution (its folded form, a
``creasePattern`` frame with its development diagram (Step 8) and the folding motion as
``foldedForm`` frames, the support panel held still) and ``.svg`` beside it, ``DIR/log.json``
(every attempt) and ``DIR/summary.json`` (the paper's counters, the development and
deformation figures (Step 9), each solution's verdicts of the large-deformation analysis and
the folding motion side by side (:class:`rigidfold.deform.Verdicts`), and stage times).
Every file is written atomically (temporary file, then rename), so each one on disk is always
valid.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.case import Case
from rigidfold.config import CHECKS
from rigidfold.deform import DeformStatus, MotionStatus, Verification, verify
from rigidfold.develop import DevelopStatus
from rigidfold.errors import RigidfoldError
from rigidfold.exports import export_design
from rigidfold.generate import Attempt, Generation, Solution, Stop
from rigidfold.io import (
    FoldData,
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
from rigidfold.status import Outcome
from rigidfold.surfaces import SplineSurface

TARGET_FILE = "target_surface.json"
"""The fitted spline of a mesh target (:meth:`rigidfold.surfaces.SplineSurface.grid`), which
summary.json names under ``target_surface`` so that the report can show the fit."""

RUN_FILES = ("summary.json", "log.json", "report.html", TARGET_FILE)
"""The files a generation run writes at the top of its directory."""

RUN_DIRS = ("solutions", "figures", "final")
"""The directories a generation run writes (solution files, figures, exports)."""


class RunOutcome(Outcome):
    """Whether a generation run delivered: the command's exit code follows it (0 or 1)."""

    PASSED = "passed", "the target DOF was reached and every check of the final design passed"
    FELL_SHORT = "fell_short", "the run fell short"


@dataclass(frozen=True)
class RunVerdict:
    """The verdict on a finished generation run.

    outcome : RunOutcome; shortfalls : what fell short, one sentence each (empty when
    passed); warnings : checks that failed on earlier solutions, which are not the design
    delivered (one sentence each); final_design : the last solution written (the lowest DOF),
    None without any.
    """

    outcome: RunOutcome
    shortfalls: tuple[str, ...]
    warnings: tuple[str, ...]
    final_design: Path | None

    @property
    def message(self) -> str:
        """One line: what fell short, or that everything passed; then the warnings."""
        head = "; ".join(self.shortfalls) if self.shortfalls else self.outcome.message
        return "; ".join([head, *(f"note: {w}" for w in self.warnings)])

    def to_dict(self) -> dict:
        return {
            "outcome": self.outcome.value,
            "message": self.message,
            "shortfalls": list(self.shortfalls),
            "warnings": list(self.warnings),
            "final_design": None if self.final_design is None else self.final_design.as_posix(),
        }


SOLVE_HINT = (
    "to try: a larger --dz (the distance allowed from the surface), wider --theta-min / "
    "--theta-max (the sector-angle bounds), or another triangulation (--diagonals parallel or "
    "alternate for a grid)"
)
"""What the command line suggests when problem (6) has no accepted solution from the target
surface (``generate``'s verdict, ``optimize``'s last line)."""

_CHECKS = {
    "development": "development diagram (Step 8) failed",
    "motion": "folding motion not traced",
    "deformation": "large deformation (Step 9) did not reach the plane",
}


def _failed_checks(check: dict) -> list[str]:
    """The stages of :data:`_CHECKS` that ran on one solution and failed."""
    failed = []
    if check["development"]["status"] != DevelopStatus.CONVERGED:
        failed.append("development")
    if check["motion"] is not None and check["motion"]["status"] != MotionStatus.OK:
        failed.append("motion")
    deformed = check["deformation"]
    if deformed is not None and deformed["status"] != DeformStatus.REACHED_PLANE:
        failed.append("deformation")
    return failed


def run_verdict(run: Generation, checks: list[dict], files: list[Path], target: int) -> RunVerdict:
    """The verdict on ``run``: passed when it reached ``target`` (Stop.TARGET_REACHED, or
    DOF 0 for a target of 0) and every check that ran on the final design
    (:attr:`rigidfold.generate.Generation.final`) passed: development diagram converged,
    folding motion traced, large deformation reached the plane. A check that failed on
    another solution is a warning, and so is a target at or above the initial DOF (no crease
    fixed) and a DOF-0 final design (it does not fold). With the deployability check, a run
    that fell short says so when no deployable design was found at a lower DOF (N_path > 0).

    checks : the figures of each solution's check (``Verification.to_dict()`` with its
    ``step``), in the order of ``files`` (their FOLD paths, relative to the run's DIR).
    """
    short = []
    reached = run.stop is Stop.TARGET_REACHED or (run.stop is Stop.ZERO_DOF and target == 0)
    final = run.final
    k = -1 if final is None else final.step
    if final is None:
        hint = f" ({SOLVE_HINT})" if run.stop is Stop.INITIAL_FAILED else ""
        short.append(f"no solution: {run.stop_reason}{hint}")
    elif not reached:
        short.append(
            f"target DOF {target} not reached: final DOF {final.mechanism.dof} ({run.stop_reason})"
        )
        if run.deploy_check and run.n_path:
            short.append(
                f"no deployable design below DOF {final.mechanism.dof}: the folding paths of "
                f"{run.n_path} solution{'s' if run.n_path > 1 else ''} did not reach the flat "
                "state (N_path)"
            )
    if checks:
        short += [f"{_CHECKS[s]} for the final design" for s in _failed_checks(checks[k])]
    earlier: dict[str, list[str]] = {stage: [] for stage in _CHECKS}
    for i, (check, path) in enumerate(zip(checks, files, strict=True)):
        if i != (k % len(checks)):
            for stage in _failed_checks(check):
                earlier[stage].append(path.name)
    warnings = tuple(f"{_CHECKS[s]} for {', '.join(n)}" for s, n in earlier.items() if n)
    if run.initial_dof is not None and run.initial_dof <= target:
        warnings += (
            f"the initial DOF {run.initial_dof} is already at or below the target DOF "
            f"{target}: no crease was fixed",
        )
    if final is not None and final.mechanism.dof == 0 and reached:
        warnings += (
            "a DOF-0 design has no mechanism: it does not fold (no folding motion or "
            "large-deformation check)",
        )
    return RunVerdict(
        RunOutcome.FELL_SHORT if short else RunOutcome.PASSED,
        tuple(short),
        warnings,
        files[k] if files else None,
    )


LOCK_NAME = ".rigidfold-run.lock"
"""The file that marks a directory as in use by a running ``generate`` (it holds the pid)."""


def lock_run_dir(out: Path) -> Path:
    """Claim ``out`` for one run: :data:`LOCK_NAME` in it holding this process's id. Returns
    the lock's path; ValueError when another live run holds it.

    The lock file is opened (created when absent; a symbolic link is refused, never
    followed) and decided on under an exclusive ``flock`` of it, which every claimant takes
    before it reads the pid: a live pid refuses; a lock that is empty, unreadable, or left
    by a process that no longer runs is taken over in place (this pid written over it). So
    of two processes taking over one stale lock, one gets it and the other finds it held,
    and a lock being created is never taken for a stale one. A lock released (removed) while
    it was waited for is made again.
    """
    import fcntl

    path = out / LOCK_NAME
    for _ in range(100):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            if path.is_symlink():
                raise RigidfoldError(
                    f"cannot lock output directory '{out}': its {LOCK_NAME} is a symbolic "
                    "link, not a rigidfold lock; remove it"
                ) from None
            raise RigidfoldError(f"cannot lock output directory '{out}': {exc.strerror}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)  # held only while deciding; closing drops it
            try:
                same = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # released (and maybe made again) while we waited: start over
                continue
            pid = _lock_owner(fd)
            if pid is not None and _alive(pid):
                raise RigidfoldError(
                    f"output directory '{out}' is in use by another rigidfold run (pid {pid}); "
                    "wait for it to end, or use another --out"
                )
            os.ftruncate(fd, 0)  # new, or stale: its run is gone
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            return path
        except OSError as exc:
            raise RigidfoldError(f"cannot lock output directory '{out}': {exc.strerror}") from None
        finally:
            os.close(fd)
    raise RigidfoldError(f"cannot lock output directory '{out}': its lock keeps coming back")


def _lock_owner(fd: int) -> int | None:
    """The pid written in the open lock file ``fd``, None when there is none: empty, not a
    number, or not a possible pid (0 or less names a process group in ``kill``)."""
    try:
        pid = int(os.pread(fd, 64, 0).decode("ascii").strip())
    except (OSError, ValueError):  # UnicodeDecodeError is a ValueError
        return None
    return pid if pid > 0 else None


def _alive(pid: int) -> bool:
    """Whether a process with this id runs (on this machine)."""
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):  # OverflowError: no pid is that large
        return False
    except PermissionError:
        return True
    return True


def clear_earlier_run(
    out: str | Path,
    *,
    overwrite: bool,
    inputs: tuple[Path, ...] = (),
    names: tuple[str, ...] = (*RUN_FILES, *RUN_DIRS),
) -> Path:
    """Refuse, or with ``overwrite`` remove, the files of an earlier run in ``out``.

    Only the run's own files and directories, ``names`` (a generation run's by default:
    :data:`RUN_FILES`, :data:`RUN_DIRS`), count and are removed; other files in ``out``
    stay. With ``overwrite`` the temporary files of those names that a killed run left
    (``.report.html.<random>.tmp``: :func:`rigidfold.io.files.temp_files`) are removed too.
    A symbolic link among them is removed itself, never followed. Removing one of the
    run's ``inputs`` (e.g. an earlier solution used as the pattern) is refused. Returns
    ``out`` as a Path. Raises ValueError naming what was found.
    """
    from rigidfold.io.files import temp_files

    out = Path(out)
    found = [out / n for n in names if (out / n).is_symlink() or (out / n).exists()]
    if found and not overwrite:
        raise RigidfoldError(
            f"output directory '{out}' holds an earlier run ({', '.join(p.name for p in found)}): "
            "give --overwrite to replace it, or another --out"
        )
    if overwrite:
        found += temp_files(out, names)
    if not found:
        return out
    for path in found:
        for given in inputs:
            doomed = (
                given.absolute() == path.absolute()
                if path.is_symlink()
                else (
                    path.resolve() == given.resolve() or path.resolve() in given.resolve().parents
                )
            )
            if doomed:
                raise RigidfoldError(
                    f"--overwrite would remove the input file '{given}' with the earlier run's "
                    f"{path.name}: copy it out of '{out}' first, or use another --out"
                )
    try:
        for path in found:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink(missing_ok=True)
    except OSError as exc:
        raise RigidfoldError(
            f"cannot remove the earlier run's {exc.filename}: {exc.strerror}"
        ) from None
    return out


def verification_frames(pattern: CreasePattern, check: Verification) -> list[dict]:
    """FOLD ``file_frames`` of a checked shape ``pattern``: its development diagram
    (``creasePattern``), then its folding motion from flat to folded (``foldedForm``, each
    frame with its own fold angles) when it was traced."""
    frames = [crease_pattern_frame(check.development.coords2d)]
    motion = _traced_motion(check)
    if motion is not None:
        frames += motion_frames(pattern, *motion)
    return frames


def _traced_motion(check: Verification) -> tuple[np.ndarray, np.ndarray] | None:
    """(frames (K, V, 3), parameter (K,)) of the folding motion, None unless it was traced."""
    if check.motion is None or check.motion.status is not MotionStatus.OK:
        return None
    return check.motion.frames, check.motion.parameter


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
            source, coords2d, motion=_traced_motion(check), title=title, metadata=figures
        )
        fold = write_document(path, document)
    svg = write_svg(
        path.with_suffix(".svg"), pattern, coords2d, title=svg_title, assignment=letters
    )
    return [fold, svg]


class RunWriter:
    """Callbacks for :func:`rigidfold.generate.generate` that keep DIR up to date.

    The development diagram (Step 8) runs on every solution as it comes; the folding motion
    and, with ``deform``, the large-deformation check (Step 9) run on the solutions ``check``
    names (:data:`CHECKS`): the final design only, once the run has ended (its FOLD file is
    then written again with them), or every solution as it comes. ``overwrite``: replace the
    files of an earlier run in ``out`` (:func:`clear_earlier_run`), which are refused
    otherwise. ``options["target_dof"]`` is the target the verdict (:meth:`finish`) judges by.
    """

    def __init__(
        self,
        out: str | Path,
        case: Case,
        options: dict,
        *,
        deform: bool = True,
        overwrite: bool = False,
        check: str = CHECKS[0],
    ) -> None:
        if check not in CHECKS:
            raise RigidfoldError(f"unknown check {check!r} (choose from {', '.join(CHECKS)})")
        refuse_replacing_inputs(case.inputs, [Path(out) / name for name in RUN_FILES])
        self.out = prepare_output_dir(out)
        self.lock = lock_run_dir(self.out)
        try:
            clear_earlier_run(self.out, overwrite=overwrite, inputs=case.inputs)
            self.solutions_dir = prepare_output_dir(self.out / "solutions")
            self.target_file: str | None = None  # a mesh target's spline, for the report
            if isinstance(case.surface, SplineSurface):
                write_json(self.out / TARGET_FILE, case.surface.grid())
                self.target_file = TARGET_FILE
        except ValueError:
            self.release()
            raise
        self.case, self.options, self.deform, self.check = case, options, deform, check
        self.solutions: list[Solution] = []
        self.developments: dict[int, np.ndarray] = {}  # step -> the development, (V, 2)
        self.files: list[Path] = []
        self.checks: list[dict] = []
        self.stage_times = {"develop": 0.0, "deform": 0.0, "motion": 0.0}
        self.verdict: RunVerdict | None = None
        self.final: tuple[CreasePattern, np.ndarray] | None = None
        self.exports: list[Path] = []

    @property
    def final_verdicts(self) -> str | None:
        """The final design's verdicts of the large-deformation analysis and the folding motion
        in one line, and why they differ when they do (:class:`rigidfold.deform.Verdicts`);
        None without a solution, or when one of the two did not run."""
        verdicts = self.checks[-1]["verdicts"] if self.checks else None
        return None if verdicts is None else verdicts["line"]

    def interrupted(self, run: Generation | None) -> None:
        """Write summary.json of a run stopped by Ctrl-C or SIGTERM: ``run`` (None when it
        was stopped before its first attempt ended) with the stop INTERRUPTED and no
        verdict."""
        if run is None:
            run = Generation()
        run.stop, run.stop_detail = Stop.INTERRUPTED, ""
        write_json(self.out / "log.json", {"attempts": [a.to_dict() for a in run.attempts]})
        self.write_summary(run)

    def release(self) -> None:
        """Remove the run's lock on DIR (:func:`lock_run_dir`); call once the run has ended."""
        self.lock.unlink(missing_ok=True)

    def on_attempt(self, run: Generation, attempt: Attempt) -> None:
        write_json(self.out / "log.json", {"attempts": [a.to_dict() for a in run.attempts]})
        self.write_summary(run)

    def on_solution(self, run: Generation, solution: Solution) -> None:
        full = self.check == "all"
        self.solutions.append(solution)
        self.checks.append({})
        self.files.append(self._write_solution(solution, deform=full and self.deform, motion=full))
        self.write_summary(run)

    def _write_solution(self, solution: Solution, *, deform: bool, motion: bool) -> Path:
        """Check one solution (Step 8; the motion and Step 9 as asked) and write its FOLD and
        SVG files; its figures replace ``checks[solution.step]``. Returns the FOLD path."""
        dof = solution.mechanism.dof
        pattern = solution.result.pattern
        check = verify(  # a DOF-0 shape (a target of 0) has no motion to trace or check
            pattern,
            run_deform=deform and dof > 0,
            run_motion=motion and dof > 0,
            dof=dof,
            path=solution.path,
            settings=self.case.settings,
        )
        for stage, t in check.times.items():
            self.stage_times[stage] += t
        dz = self.case.deviation(pattern.coords)
        fit = {"max_abs_dz_m": float(np.abs(dz).max()), "rms_dz_m": float(np.sqrt(np.mean(dz**2)))}
        figures = {"step": solution.step, "dof": dof, "fit": fit, **check.to_dict()}
        figures["deployability"] = None if solution.path is None else solution.path.to_dict()
        self.checks[solution.step] = figures
        self.developments[solution.step] = check.development.coords2d
        path = self.solutions_dir / f"step_{solution.step:02d}_dof_{dof:02d}.fold"
        write_checked_shape(
            path,
            pattern,
            check,
            title=f"rigidfold generate: step {solution.step}, DOF {dof}",
            svg_title=f"step {solution.step}, DOF {dof}: development diagram",
            metadata={
                **self.case.metadata(),
                **solution.result.to_dict(),
                "step": solution.step,
                "dof": dof,
                "criterion": self.options.get("criterion"),
                "lookahead": self.options.get("lookahead", False),
            },
        )
        return path

    def finish(self, run: Generation) -> RunVerdict:
        """The verdict on the finished run (:func:`run_verdict`), written into summary.json,
        and the final design (:attr:`rigidfold.generate.Generation.final`) exported to
        ``DIR/final/`` in every format of :func:`rigidfold.exports.export_design`, named
        after its solution file. With ``check="final"`` the final design's folding motion and
        Step 9 run first and its files are written again with them."""
        final = run.final
        if final is not None:
            if self.check == "final":
                self.solutions[final.step] = final  # its path may have been traced since
                self._write_solution(final, deform=self.deform, motion=True)
            pattern = final.result.pattern
            coords2d = self.developments[final.step]
            self.final = (pattern, coords2d)
        self.verdict = run_verdict(
            run,
            self.checks,
            [p.relative_to(self.out) for p in self.files],
            self.options["target_dof"],
        )
        if self.final is not None:
            pattern, coords2d = self.final
            stem = self.files[-1 if final is None else final.step].stem
            self.exports = export_design(
                pattern, coords2d, self.out / "final", name=stem, title=f"rigidfold: {stem}"
            )
        self.write_summary(run)
        return self.verdict

    def write_summary(self, run: Generation) -> None:
        summary = run.to_dict()
        summary["time_s"].update(self.stage_times)
        dev = [c["development"] for c in self.checks]
        deformed = [c["deformation"] for c in self.checks if c["deformation"] is not None]
        motions = [c["motion"] for c in self.checks if c["motion"] is not None]

        def stat(values, fn):
            return float(fn(values)) if values else None

        write_json(
            self.out / "summary.json",
            {
                **summary,
                "development": {
                    "mean_D": stat([d["D"] for d in dev], np.mean),
                    "max_D": stat([d["D"] for d in dev], np.max),
                    "flipped": sum(max(d["flipped"], 0) for d in dev),
                    "overlaps": sum(max(d["overlaps"], 0) for d in dev),
                },
                "deformation": {
                    "checked": len(deformed),
                    "reached_plane": sum(d["reached_plane"] for d in deformed),
                    "mean_dl_mm": stat([d["mean_dl_mm"] for d in deformed], np.mean),
                    "max_dl_mm": stat([d["max_dl_mm"] for d in deformed], np.max),
                    "mean_drho_fix_deg": stat([d["mean_drho_fix_deg"] for d in deformed], np.mean),
                    "max_drho_fix_deg": stat([d["max_drho_fix_deg"] for d in deformed], np.max),
                },
                "motion": {
                    "traced": sum(m["status"] == MotionStatus.OK for m in motions),
                    "max_length_error": stat([m["max_length_error"] for m in motions], np.max),
                },
                "per_solution": [
                    {k: v for k, v in c.items() if k != "deformation"}
                    | {
                        "deformation": None
                        if c["deformation"] is None
                        else {k: v for k, v in c["deformation"].items() if k != "history"}
                    }
                    for c in self.checks
                ],
                "options": self.options,
                "case": self.case.metadata(),
                "solutions": [str(p.relative_to(self.out)) for p in self.files],
                "verdict": None if self.verdict is None else self.verdict.to_dict(),
                "exports": [str(p.relative_to(self.out)) for p in self.exports],
                "target_surface": self.target_file,
            },
        )
