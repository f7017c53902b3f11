"""The records of a generation run (Steps 2-7): what one solve was made of
(:class:`AttemptOutcome`, :class:`Attempt`), an accepted shape (:class:`Solution`), how a run
ended (:class:`Stop`) and the run itself with the paper's counters (:class:`Generation`).

:mod:`rigidfold.generate` produces them and exports them; the run writer, the run reader, the
report and the study store read and write them (``Attempt.to_dict``/``from_dict``,
``Generation.to_dict``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigidfold.mechanism import Mechanism
from rigidfold.mechanism.path import FoldingPath
from rigidfold.optimize import OptimizeResult, Status
from rigidfold.outcomes import Outcome


class AttemptOutcome(Outcome):
    """What generation made of one solve of problem (6) (Steps 4-5)."""

    ACCEPTED = "accepted", "DOF >= 1, F <= F_tol and no locked crease: a solution (Step 6)"
    EXCEED = (
        "exceed",
        "the solve missed F <= F_tol, did not converge, or folded a fixed crease back onto "
        "its facets (Step 4, N_exceed)",
    )
    LOCK = "lock", "the mechanism has a locked crease (Step 5, N_lock)"
    ZERO_DOF = "zero_dof", "the mechanism has DOF 0: generation ends (Step 5 -> Step 8)"
    PATH = (
        "path",
        "the shape's rigid-folding path does not reach the flat state (Step 5, N_path)",
    )
    RIGID = (
        "second_order_rigid",
        "the shape is mobile at first order only: a self-stress holds its flexes at second "
        "order, so it cannot fold (Step 5, N_rigid)",
    )
    TIME_LIMIT = (
        "time_limit",
        "the run's time limit cut the solve or its path trace short: no verdict on the "
        "candidate (not counted in N_exceed or N_path; the run ends)",
    )
    NO_GAP = (
        "no_gap",
        "a solution at the target DOF without a clear gap (near-mechanisms, or the search's "
        "count and the singular values' differ): kept as the run's fallback design while the "
        "search looks for one with a clear gap (``Settings.generation.clear_gap``)",
    )
    NO_GAIN = (
        "no_gain",
        "a fix of a near-mechanism (``Settings.generation.near_tries``) whose solution has "
        "more DOF than its shape (with ``Settings.generation.near_gain``, no fewer): not kept "
        "(the solve moved the shape into softer modes), the shape goes on with its ranked "
        "candidates; or, with ``Settings.generation.idle_gain``, a candidate forecast to "
        "remove no DOF whose solution has no fewer DOF than its shape: the same shape with "
        "one more crease fixed, not kept",
    )
    INITIAL_FAILED = "initial_failed", "the solve from the target surface was not accepted"
    DEAD_END = (
        "dead_end",
        "a solution retracted by backtracking or by a restart with a fold limit: no "
        "candidate of its shape gave a deployable solution, or a chain that reached a lower "
        "DOF was taken back (Step 7)",
    )


class Stop(Outcome):
    """How a generation run ended; ``Generation.stop_reason`` words it with its detail."""

    RUNNING = "running", "generation has not ended"
    TARGET_REACHED = "target_reached", "the target DOF is reached"
    ZERO_DOF = "zero_dof", "a solution has DOF 0 (Step 5 -> Step 8)"
    NO_CANDIDATE = "no_candidate", "no candidate crease succeeds (Step 7)"
    NO_DEPLOYABLE = (
        "no_deployable",
        "none of the last candidates gave a solution whose folding path reaches the flat "
        "state (Step 7, N_path; in a chain bounded by a fold limit, also solves that fail)",
    )
    INITIAL_FAILED = "initial_failed", "no developable polyhedron from the initial shape"
    INTERRUPTED = "interrupted", "the run was interrupted (Ctrl-C or SIGTERM)"
    TIME_LIMIT = "time_limit", "the run's time limit was reached (Step 7)"

    def reason(self, detail: str = "") -> str:
        """The stop reason's words with the run's ``detail`` (see :data:`STOP_REASONS`)."""
        return STOP_REASONS[self].format(detail)


STOP_REASONS = {
    Stop.RUNNING: "running",
    Stop.TARGET_REACHED: "target DOF {} reached",
    Stop.ZERO_DOF: "DOF 0 reached",
    Stop.NO_CANDIDATE: "no candidate crease succeeds",
    Stop.NO_DEPLOYABLE: "no deployable solution in {} candidates",
    Stop.INITIAL_FAILED: "no developable polyhedron from the initial shape ({})",
    Stop.INTERRUPTED: "interrupted",
    Stop.TIME_LIMIT: "time limit of {} s reached",
}
"""The words of each :class:`Stop`, ``{}`` standing for the detail (the target DOF, or the
outcome of the initial solve). Every rigidfold version has written these texts to
summary.json and to study databases."""


@dataclass
class Attempt:
    """One solve of problem (6) during generation, accepted or not.

    status : Status
        How the solve ended.
    outcome : AttemptOutcome
        What generation made of it.
    locked : list of int
        The creases locked at the shape found (every folded free crease at DOF 0).
    skipped, skipped_locks : int, list of dict
        With look-ahead: the candidates passed over just before this one because they were
        predicted to lock, had locked at an earlier shape, were forecast second-order rigid
        or (``Settings.generation.idle_last``) to remove no mechanism, each as ``{"fixed":
        [edges], "locks": [edges it would lock], "locked_before": [edges its fix locked
        before], "rigid": bool, "idle": bool}``.
    predicted_locks : list of int or None
        With look-ahead: the creases this fix was predicted to lock (non-empty only where
        every other candidate had failed); None without look-ahead and for the initial
        solve.
    carried : list of int
        With look-ahead: the nearly flat creases fixed together with the candidate, the ones
        it alone would lock (``fixed_added`` holds the candidate's creases, then these).
    locked_predicted, locked_left : list of bool, list of float or None
        Per crease of ``locked`` (after a fix): whether the forecast at the shape before
        predicted it, and the rotation it was forecast to keep, relative to the largest
        (:attr:`rigidfold.selection.LockForecast.rotation_left`; None for a crease flat
        before). Made with and without look-ahead.
    locked_fold_deg : list of float
        Per crease of ``locked``: its fold angle at the shape found, degrees.
    path : dict or None
        The deployability check (:meth:`rigidfold.mechanism.path.FoldingPath.to_dict`): how
        the shape's folding path ended, and for a path that does not reach the flat state,
        where it came closest (its measure m and the free creases' fold angles there); None
        where it did not run.
    path_time : float
        Seconds of the check.
    second_order : dict or None
        For a checked solution whose path does not reach the flat state: the second-order
        test of its flexes (:meth:`rigidfold.mechanism.second_order.Obstruction.to_dict`):
        whether it is second-order rigid (outcome RIGID) and how strongly; None where it did
        not run.
    rigid_forecast : bool or None
        At a shape whose children are checked (with or without the look-ahead): whether this
        fix was forecast to leave a second-order rigid shape (:class:`rigidfold.mechanism.
        second_order.ChildForecast`); None where no forecast was made.
    fold_limit_deg : float or None
        The bound (12) the solve kept every free crease within, degrees: that of the chain
        started again after the one before dead-ended (``Settings.generation.fold_limits``,
        the restarts of :mod:`rigidfold.generate`); None in the first chain.
    batch : int
        With several creases per solve (``GenerateOptions.batch``): the number of ranked
        candidates fixed together in this solve (``fixed_added`` holds their creases);
        0 for a solve of one candidate.
    near : float or None
        For a candidate tried before the ranked ones because it turns in the shape's
        near-mechanisms but hardly in its exact ones (:mod:`rigidfold.selection.near`): its
        share r (exact rotation over counted); None for any other.
    path_from : int or None
        For a solution rejected without a trace because an earlier attempt's solution had
        the same shape (``Settings.generation.same_shape_tol``): that attempt's index, whose
        ``path`` and ``second_order`` this one repeats; None for any other.
    solve_from : int or None
        For an attempt that repeats an earlier one (the same fix from bitwise the same
        shape under the same bound: :mod:`rigidfold.generate.memo`): that attempt's index,
        whose solve, analysis and check it repeats without computing them again (its
        seconds are 0); None for any other.
    search_round : int
        The round of the search it belongs to (``Settings.generation.reseeds``): 0 the
        first; a later round started again from the initial shape with other seeds.
    """

    index: int
    fixed_added: tuple[int, ...]
    score: float | None
    status: Status
    F: float
    iterations: int
    dof: int | None
    locked: list[int]
    outcome: AttemptOutcome
    solve_time: float
    analysis_time: float
    selection_time: float = 0.0
    skipped: int = 0
    skipped_locks: list[dict] = field(default_factory=list)
    predicted_locks: list[int] | None = None
    carried: list[int] = field(default_factory=list)
    locked_predicted: list[bool] = field(default_factory=list)
    locked_left: list[float | None] = field(default_factory=list)
    locked_fold_deg: list[float] = field(default_factory=list)
    path: dict | None = None
    path_time: float = 0.0
    second_order: dict | None = None
    rigid_forecast: bool | None = None
    fold_limit_deg: float | None = None
    batch: int = 0
    near: float | None = None
    path_from: int | None = None
    solve_from: int | None = None
    search_round: int = 0

    def to_dict(self) -> dict:
        """JSON-serialisable fields (the enums as their values)."""
        return self.__dict__ | {"status": self.status.value, "outcome": self.outcome.value}

    @classmethod
    def from_dict(cls, data: dict) -> Attempt:
        """The attempt :meth:`to_dict` wrote as ``data`` (a line of a run's log, whose shape
        :func:`rigidfold.rundir.read_log` checks first); a field it lacks takes its default."""
        known = {k: v for k, v in data.items() if k in cls.__dataclass_fields__}
        return cls(
            **known
            | {
                "fixed_added": tuple(data["fixed_added"]),
                "status": Status(data["status"]),
                "outcome": AttemptOutcome(data["outcome"]),
            }
        )


@dataclass
class Solution:
    """An accepted shape: DOF >= 1, F <= F_tol, no locked crease (or, for a target DOF of 0,
    the DOF-0 shape that ends the run); with the deployability check, also its folding path
    to the flat state (``path``, None where it did not run)."""

    step: int
    result: OptimizeResult
    mechanism: Mechanism
    path: FoldingPath | None = None


@dataclass
class Generation:
    """Outcome of a generation run, with the paper's counters (Section 6.3).

    stop : Stop
        How the run ended; ``stop_detail`` is the target DOF (TARGET_REACHED) or the outcome
        of the initial solve (INITIAL_FAILED), "" otherwise.
    n_backtrack : int
        Solutions retracted by backtracking (their attempts' outcome DEAD_END); where the
        run ends with the chain it had before backtracking, its solutions are not counted.
    n_rigid : int
        Solutions rejected as second-order rigid (outcome RIGID): mobile at first order
        only; beside N_path, the paths that do not reach the flat state for other reasons.
    """

    initial_dof: int | None = None
    solutions: list[Solution] = field(default_factory=list)
    attempts: list[Attempt] = field(default_factory=list)
    n_lock: int = 0
    n_exceed: int = 0
    n_path: int = 0
    n_backtrack: int = 0
    n_rigid: int = 0
    deploy_check: bool = False
    final_step: int | None = None
    stop: Stop = Stop.RUNNING
    stop_detail: str = ""
    dof_margin: dict | None = None  # rigidfold.mechanism.margin.DofMargin.to_dict()
    build_time: float = 0.0
    final_path_time: float = 0.0  # the traces that named the final design (time_s.path)
    rewind_path_time: float = 0.0  # the traces of chain shapes that rewinds probed (time_s.path)
    numerics: dict | None = None  # rigidfold.runtime.numerics.NumericEnvironment.to_dict()

    @property
    def stop_reason(self) -> str:
        """How the run ended, in words: e.g. "target DOF 1 reached" (see :data:`STOP_REASONS`)."""
        return self.stop.reason(self.stop_detail)

    @property
    def final(self) -> Solution | None:
        """The final design: the last solution, or, with the deployability check on a run
        that fell short of its target, the lowest-DOF solution that deploys (``final_step``);
        None without one."""
        if not self.solutions:
            return None
        return self.solutions[-1 if self.final_step is None else self.final_step]

    @property
    def final_dof(self) -> int | None:
        """The DOF of the final design (:attr:`final`), which may be above
        :attr:`lowest_dof` where the run fell short with the deployability check."""
        final = self.final
        return None if final is None else final.mechanism.dof

    @property
    def lowest_dof(self) -> int | None:
        """The lowest DOF a solution reached (the last solution's)."""
        return self.solutions[-1].mechanism.dof if self.solutions else None

    @property
    def solved(self) -> list[Attempt]:
        """The attempts whose solve was computed, in order (not those that repeat an earlier
        one, ``Attempt.solve_from``): the run's solves."""
        return [a for a in self.attempts if a.solve_from is None]

    @property
    def n_skipped(self) -> int:
        """Candidates skipped by the look-ahead (predicted to lock, not solved)."""
        return sum(a.skipped for a in self.attempts)

    @property
    def n_reduce(self) -> int:
        """DOF reduced from the initial shape's, over accepted shapes."""
        if not self.solutions:
            return 0
        assert self.initial_dof is not None  # set before the first solution is recorded
        return self.initial_dof - self.solutions[-1].mechanism.dof

    def to_dict(self) -> dict:
        """JSON-serialisable counters, stop and times of the run, each under its attribute's
        name (``n_lock``: the paper's N_lock), the key of summary.json
        (:class:`rigidfold.rundir.RunSummary`) and the study's column."""
        accepted_F = [s.result.F for s in self.solutions]
        solved = self.solved
        all_F = [a.F for a in solved if np.isfinite(a.F)]
        return {
            "stop": self.stop.value,
            "stop_reason": self.stop_reason,
            "initial_dof": self.initial_dof,
            "final_dof": self.final_dof,
            "lowest_dof": self.lowest_dof,
            "n_reduce": self.n_reduce,
            "n_lock": self.n_lock,
            "n_exceed": self.n_exceed,
            "n_path": self.n_path,
            "n_backtrack": self.n_backtrack,
            "n_rigid": self.n_rigid,
            "deploy_check": self.deploy_check,
            "final_step": None if self.final is None else self.final.step,
            "final_deploys": (
                None if self.final is None or self.final.path is None else self.final.path.deploys
            ),
            "dof_margin": self.dof_margin,
            "n_solutions": len(self.solutions),
            "n_solves": len(solved),
            "n_repeats": len(self.attempts) - len(solved),
            "n_skipped": self.n_skipped,
            "mean_f_accepted": float(np.mean(accepted_F)) if accepted_F else None,
            "mean_f_all_solves": float(np.mean(all_F)) if all_F else None,
            "numerics": self.numerics,
            "time_s": {
                "build": self.build_time,
                "solve": sum(a.solve_time for a in self.attempts),
                "analysis": sum(a.analysis_time for a in self.attempts),
                "selection": sum(a.selection_time for a in self.attempts),
                "path": sum(a.path_time for a in self.attempts)
                + self.final_path_time
                + self.rewind_path_time,
            },
        }
