"""The verdict on a finished generation run: whether it delivered, and the exit code of
``rigidfold generate`` that follows (0 or 1)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from rigidfold.config import DEFAULTS, Settings
from rigidfold.generate import AttemptOutcome, Generation, Stop
from rigidfold.generate.final import known_to_deploy as deploys
from rigidfold.outcomes import Outcome
from rigidfold.rundir.schema import SolutionRecord, Stage


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


def run_verdict(
    run: Generation,
    records: list[SolutionRecord],
    files: list[Path],
    target: int,
    settings: Settings = DEFAULTS,
) -> RunVerdict:
    """The verdict on ``run``: passed when it reached ``target`` (Stop.TARGET_REACHED, or
    DOF 0 for a target of 0) and every check that ran on the final design
    (:attr:`rigidfold.generate.Generation.final`) passed: development diagram converged,
    folding motion traced, large deformation reached the plane, and, where they ran, its
    thick panels deploy without collision (``--thickness``) and its structure check passed
    (``--structure``), each failure with its detail. A check that failed on
    another solution is a warning, and so is a target at or above the initial DOF (no crease
    fixed) and a DOF-0 final design (it does not fold). With the deployability check, a run
    that fell short says so when no deployable design was found at a lower DOF (N_path > 0),
    and a design at the target DOF without a clear gap (:class:`rigidfold.mechanism.margin.
    DofMargin`: its soft modes are mechanisms for a builder, issue 49) falls short of it,
    saying so first, unless the run accepted such a design (``Settings.generation.clear_gap``
    off, ``--accept-no-gap``: then, as without the check, the margin is a warning).

    records : each solution's checks, in the order of ``files`` (their FOLD paths, relative
    to the run's DIR); :meth:`SolutionRecord.failed_stages` says what failed. ``settings``:
    the run's (``Settings.generation.exceed_share``).
    """
    if run.stop is Stop.INTERRUPTED:
        return _interrupted(run, records, files)
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
        missed = _out_of_reach(run, settings.generation.exceed_share)
        if missed:
            short.append(missed)
        failed = run.n_path + run.n_rigid
        if run.deploy_check and failed and run.stop is not Stop.INTERRUPTED:
            counts = f"N_path {run.n_path}, N_rigid {run.n_rigid}" if run.n_rigid else "N_path"
            short.append(
                f"no deployable design below DOF {final.mechanism.dof}: the folding paths of "
                f"{failed} solution{'s' if failed > 1 else ''} did not reach the flat "
                f"state ({counts})"
            )
    named = final is not None and bool(files)
    if records:
        final_record = records[k]
        for stage in final_record.failed_stages():
            detail = final_record.detail(stage)
            short.append(
                f"{stage.message} for the final design" + (f" ({detail})" if detail else "")
            )
    earlier: dict[Stage, list[str]] = {stage: [] for stage in Stage}
    for i, (record, path) in enumerate(zip(records, files, strict=True)):
        if i != (k % len(records)):
            for stage in record.failed_stages():
                earlier[stage].append(path.name)
    warnings = tuple(f"{s.message} for {', '.join(n)}" for s, n in earlier.items() if n)
    if run.initial_dof is not None and run.initial_dof <= target:
        warnings += (
            f"the initial DOF {run.initial_dof} is already at or below the target DOF "
            f"{target}: no crease was fixed",
        )
    margin = run.dof_margin
    if final is not None and margin is not None and not margin.get("clear", True):
        if reached and run.deploy_check and settings.generation.clear_gap:
            short.insert(
                0,
                f"the target DOF {target} was reached only without a clear DOF gap: "
                f"{margin['message']}",
            )
        else:
            warnings += (str(margin["message"]),)
    if final is not None and final.mechanism.dof == 0 and reached:
        warnings += (
            "a DOF-0 design has no mechanism: it does not fold (no folding motion or "
            "large-deformation check)",
        )
    return RunVerdict(
        RunOutcome.FELL_SHORT if short else RunOutcome.PASSED,
        tuple(short),
        warnings,
        files[k] if named else None,
    )


def _out_of_reach(run: Generation, share: float) -> str | None:
    """Where at least ``share`` of the solves after the first (those computed, not the
    attempts that repeat one: ``Attempt.solve_from``) were not accepted by Step 4
    (``N_exceed``: F above ``f_tol``, no convergence), what a run that fell short ran into:
    with more creases fixed, no shape met the constraints of problem (6) within dz of the
    surface (a coarse pattern on a curved surface: the drawn single vertex on the dome); None
    otherwise."""
    later = run.solved[1:]  # the first attempt is the initial solve, never a repeat
    missed = [a.F for a in later if a.outcome is AttemptOutcome.EXCEED]
    if not later or not missed or len(missed) < share * len(later):
        return None
    least = min((F for F in missed if math.isfinite(F)), default=None)
    worst = "" if least is None else f"; the least F {least:.2g}, above f_tol"
    return (
        f"{len(missed)} of the {len(later)} solves after the first met no shape within dz of "
        f"the surface with their creases fixed (N_exceed{worst}): the pattern reaches the "
        f"surface only with more DOF ({SOLVE_HINT})"
    )


def known_to_deploy(record: SolutionRecord) -> bool:
    """Whether a solution is known to deploy: its deployability check's path reached the flat
    state, or its folding motion was traced from flat (the checks of the final design)."""
    path = record.deployability or {}
    return path.get("deploys") is True or record.passed(Stage.MOTION) is True


def _interrupted(run: Generation, records: list[SolutionRecord], files: list[Path]) -> RunVerdict:
    """The verdict on a run interrupted by Ctrl-C or SIGTERM (it fell short): its final
    design is the lowest-DOF solution known to deploy (:func:`known_to_deploy`, or its path
    traced since its record was written: naming a round's design), None when none is, which
    it then says."""
    if len(records) != len(files):
        raise ValueError(f"{len(records)} records for {len(files)} solution files")
    chain = run.solutions

    def is_known(k: int) -> bool:
        traced = k < len(chain) and chain[k].step == records[k].step and deploys(chain[k])
        return traced or known_to_deploy(records[k])

    known = [k for k in range(len(records)) if is_known(k)]
    if known:
        k = known[-1]  # the chain's DOF falls as it goes: the last is the lowest
        short = (f"interrupted; best design known to deploy: DOF {records[k].dof}",)
    elif records:
        short = (
            f"interrupted; no design is known to deploy (none of the {len(records)} "
            "solutions had its folding path traced to the flat state)",
        )
    else:
        short = ("interrupted before the first solution",)
    return RunVerdict(RunOutcome.FELL_SHORT, short, (), files[known[-1]] if known else None)
