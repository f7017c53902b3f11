"""Sequential form generation by fixing crease lines (Section 3, Steps 2-7).

::

    Step 2  E_fix = {}, solutions = []
    Step 3  solve problem (6) (from the target surface, then from the last accepted shape)
    Step 4  not accepted (F > F_tol or not converged)         -> Step 7   (N_exceed += 1)
    Step 5  analyse the mechanism:
              DOF >= 1, no locked crease   -> accept, Step 6
              DOF >= 1, a locked crease    -> Step 7                       (N_lock += 1)
              DOF = 0                      -> end, to Step 8 (not counted, Section 6.3);
                                              with ``zero_dof_ends=False`` and a target DOF
                                              >= 1: a lock, Step 7
    Step 6  rank the free creases of the last accepted shape by the criterion; fix the best
    Step 7  E_fix = {} -> no developable polyhedron; otherwise replace the last fixed crease
            (group) with the next candidate of that ranking

Generation ends when the target DOF is reached, at DOF 0, or when no candidate succeeds.
The NLP is built once; every solve starts from the last accepted shape.

With the deployability check, Step 7 may backtrack (``Settings.generation.backtrack_max``
times a run): when every candidate of a shape after the first fails, its solution is
retracted (its attempt's outcome becomes DEAD_END, and it leaves ``Generation.solutions``)
and Step 7 resumes at the shape before it with that shape's remaining candidates, in the
order ranked there (each shape's ranking is kept on a stack; nothing is ranked or tried
again). A run whose backtracking ends at a higher DOF than the chain it retracted ends with
that chain instead (the solutions found since are retracted). Without the check, or with
``backtrack_max = 0``, Step 7 is the paper's.

With ``lookahead=True`` (any criterion), Step 6 forecasts, at the last accepted shape, the
creases each candidate would lock at first order (:func:`rigidfold.selection.lock_forecast`,
block by block of the ranking as the candidates are reached); candidates predicted to lock,
and those whose fix locked a crease at an earlier shape of the run, are skipped and the others
keep the criterion's order. The skipped ones are not dropped: once every other candidate has
failed, first those whose forecast locks are nearly flat creases that their fix carries flat
are fixed together with them (one group, ``Attempt.carried``: the group's creases are fixed,
not locked), then the skipped ones alone, in the criterion's order; so generation never ends
where it would not without look-ahead (:func:`rigidfold.selection.lookahead_order`). A
candidate whose fix leaves DOF 0 is not skipped where DOF 0 ends generation. Every lock, with
or without look-ahead, is logged with the forecast of its candidate and the locked creases'
fold angles (:class:`Attempt`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from rigidfold.case import Case
from rigidfold.config import (
    Settings,
    one_blas_thread,
)
from rigidfold.frame.model import default_support_face
from rigidfold.generate_options import GenerateOptions
from rigidfold.mechanism import Mechanism, analyze, check_analysis_size
from rigidfold.mechanism.margin import dof_margin
from rigidfold.mechanism.path import FoldingPath, trace_path
from rigidfold.mechanism.second_order import ChildForecast, Obstruction, obstruction
from rigidfold.mechanism.stiffness import hinge_stiffness
from rigidfold.mesh import CreasePattern
from rigidfold.numerics import numeric_environment
from rigidfold.optimize import OptimizeResult, Status
from rigidfold.selection import (
    Choice,
    crease_groups,
    lock_forecast,
    lookahead_order,
    rank_candidates,
    score_creases,
)
from rigidfold.status import Outcome


class AttemptOutcome(Outcome):
    """What generation made of one solve of problem (6) (Steps 4-5)."""

    ACCEPTED = "accepted", "DOF >= 1, F <= F_tol and no locked crease: a solution (Step 6)"
    EXCEED = "exceed", "the solve missed F <= F_tol or did not converge (Step 4, N_exceed)"
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
    INITIAL_FAILED = "initial_failed", "the solve from the target surface was not accepted"
    DEAD_END = (
        "dead_end",
        "a solution retracted by backtracking: no candidate of its shape gave a deployable "
        "solution, or a chain that reached a lower DOF was taken back (Step 7)",
    )


class Stop(Outcome):
    """How a generation run ended; ``Generation.stop_reason`` words it with its detail."""

    RUNNING = "running", "generation has not ended"
    TARGET_REACHED = "target_reached", "the target DOF is reached"
    ZERO_DOF = "zero_dof", "a solution has DOF 0 (Step 5 -> Step 8)"
    NO_CANDIDATE = "no_candidate", "no candidate crease succeeds (Step 7)"
    NO_DEPLOYABLE = (
        "no_deployable",
        "the folding paths of the last candidates do not reach the flat state (Step 7, N_path)",
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
        predicted to lock or had locked at an earlier shape, each as ``{"fixed": [edges],
        "locks": [edges it would lock], "locked_before": [edges its fix locked before]}``.
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
    fold_bound : bool
        Whether the solve kept every free crease within bound (12) at
        ``Settings.generation.fold_limit``: the attempts of the chain started again after the
        first chain's candidates did not deploy (:meth:`_Steps.restart`).
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
    fold_bound: bool = False

    def to_dict(self) -> dict:
        """JSON-serialisable fields (the enums as their values)."""
        return self.__dict__ | {"status": self.status.value, "outcome": self.outcome.value}

    @classmethod
    def from_dict(cls, data: dict) -> Attempt:
        """The attempt :meth:`to_dict` wrote as ``data`` (a line of a run's log, whose shape
        :func:`rigidfold.run.read_log` checks first); a field it lacks takes its default."""
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
    numerics: dict | None = None  # rigidfold.numerics.NumericEnvironment.to_dict()

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
        """JSON-serialisable counters, stop and times of the run."""
        accepted_F = [s.result.F for s in self.solutions]
        all_F = [a.F for a in self.attempts if np.isfinite(a.F)]
        return {
            "stop": self.stop.value,
            "stop_reason": self.stop_reason,
            "initial_dof": self.initial_dof,
            "final_dof": self.final_dof,
            "lowest_dof": self.lowest_dof,
            "N_reduce": self.n_reduce,
            "N_lock": self.n_lock,
            "N_exceed": self.n_exceed,
            "N_path": self.n_path,
            "N_backtrack": self.n_backtrack,
            "N_rigid": self.n_rigid,
            "deploy_check": self.deploy_check,
            "final_step": None if self.final is None else self.final.step,
            "final_deploys": (
                None if self.final is None or self.final.path is None else self.final.path.deploys
            ),
            "dof_margin": self.dof_margin,
            "n_solutions": len(self.solutions),
            "n_solves": len(self.attempts),
            "n_skipped": self.n_skipped,
            "mean_F_accepted": float(np.mean(accepted_F)) if accepted_F else None,
            "mean_F_all_solves": float(np.mean(all_F)) if all_F else None,
            "numerics": self.numerics,
            "time_s": {
                "build": self.build_time,
                "solve": sum(a.solve_time for a in self.attempts),
                "analysis": sum(a.analysis_time for a in self.attempts),
                "selection": sum(a.selection_time for a in self.attempts),
                "path": sum(a.path_time for a in self.attempts),
            },
        }


@dataclass
class _Trial:
    """What one solve produced: the result, its mechanism (None: not analysed) and its
    folding path (None: not traced)."""

    result: OptimizeResult
    mechanism: Mechanism | None
    path: FoldingPath | None


@dataclass
class _Shape:
    """Step 6 at one accepted shape, kept while the shape may be reduced again: the ranked
    crease groups with their scores, the candidates not yet tried (an iterator, lazy with
    look-ahead), the candidates whose paths did not reach the flat state, and the seconds of
    selection not yet charged to an attempt."""

    solution: Solution
    ranked: list
    order: Iterator[Choice]
    forecast: ChildForecast | None = None
    undeployable: int = 0
    rigid_in_row: int = 0
    t_sel: float = 0.0


@dataclass
class _Chain:
    """The solutions of a run (and their attempts) when it stopped at their last shape, kept
    in case backtracking ends at a higher DOF: the stop and its detail."""

    solutions: list[Solution]
    accepted: list[Attempt]
    stop: Stop
    detail: str


class _Steps:
    """The steps of one generation run on its state: the problem (built once), the options,
    the run being recorded and the callbacks that see it."""

    def __init__(
        self,
        case: Case,
        options: GenerateOptions,
        on_attempt: Callable[[Generation, Attempt], None] | None,
        on_solution: Callable[[Generation, Solution], None] | None,
        on_retract: Callable[[Generation, Solution], None] | None = None,
    ) -> None:
        self.case, self.options, self.settings = case, options, case.settings
        self.on_attempt, self.on_solution, self.on_retract = on_attempt, on_solution, on_retract
        self.rng = np.random.default_rng(options.seed)
        self.run = Generation(
            numerics=numeric_environment().to_dict(), deploy_check=options.deploy_check
        )
        t0 = time.perf_counter()
        self.started = time.monotonic()
        self.problem = case.problem(build_ipopt=options.solver == "ipopt")
        self.run.build_time = time.perf_counter() - t0
        self.groups = (
            crease_groups(case.pattern, case.planes, self.settings) if case.planes else None
        )
        # a DOF-0 shape cannot deploy: with the deployability check and a target >= 1 it is
        # over-reduction, retried like a lock (as with zero_dof_ends=False)
        self.zero_ends = (
            self.settings.generation.zero_dof_ends and not options.deploy_check
        ) or options.target_dof == 0
        self.locked_before: dict[tuple[int, ...], list[int]] = {}  # look-ahead: fixes that locked
        self.shapes: list[_Shape] = []  # Step 6 at each solution being reduced, the last on top
        self.accepted: list[Attempt] = []  # the attempt of each solution
        self.deepest: _Chain | None = None  # the chain of lowest DOF that backtracking left
        self.backtracks = 0  # retractions by backtracking in the chain being built
        # the restart with bound (12) at the fold limit: its case (None: no restart left)
        bounded = with_fold_limit(case, options)
        self.restart_case: Case | None = None if bounded is case else bounded
        self.fold_bound = False  # whether the solves are (12)-bounded (after the restart)

    def solve(self, fixed: np.ndarray, start, added, score) -> tuple[Attempt, _Trial]:
        """Steps 3-5 for one set of fixed creases: solve problem (6) from ``start``, polish
        (with the deployability check), analyse the mechanism, classify, trace the path."""
        opts, settings = self.options, self.settings
        result = self.problem.solve(fixed=fixed, start=start, solver=opts.solver)
        if opts.deploy_check:
            result = self.problem.polish(result)
        t1 = time.perf_counter()
        mech = (
            analyze(result.pattern, support_face=opts.support_face, settings=settings)
            if result.converged
            else None
        )
        t_an = time.perf_counter() - t1
        outcome = _classify(mech, self.zero_ends)
        path, t_path, second = None, 0.0, None
        if (
            outcome is AttemptOutcome.ACCEPTED
            and opts.deploy_check
            and _checked(mech, opts, settings)
        ):
            assert mech is not None
            t2 = time.perf_counter()
            path = trace_path(
                result.pattern, dof=mech.dof, support_face=opts.support_face, settings=settings
            )
            if not path.deploys:
                outcome = AttemptOutcome.PATH
                second = self.obstruction(result.pattern, mech.dof)
                if second is not None and second.rigid:
                    outcome = AttemptOutcome.RIGID
            t_path = time.perf_counter() - t2
        locked = [] if mech is None else mech.locked_creases.tolist()
        rec = Attempt(
            index=len(self.run.attempts),
            fixed_added=tuple(added),
            score=score,
            status=result.status,
            F=result.F,
            iterations=result.iterations,
            dof=None if mech is None else mech.dof,
            locked=locked,
            outcome=outcome,
            solve_time=result.wall_time,
            analysis_time=t_an,
            locked_fold_deg=np.degrees(result.pattern.fold_angles[locked]).tolist(),
            path=None if path is None else path.to_dict(),
            path_time=t_path,
            second_order=None if second is None else second.to_dict(),
            fold_bound=self.fold_bound,
        )
        self.run.attempts.append(rec)
        return rec, _Trial(result, mech, path)

    def support_face(self, pattern: CreasePattern) -> int:
        """The gauge triangle of the path and the second-order test (the options', or the
        one nearest the centroid)."""
        face = self.options.support_face
        return default_support_face(pattern) if face is None else int(face)

    def obstruction(self, pattern: CreasePattern, dof: int) -> Obstruction | None:
        """The second-order test of a checked solution whose path does not reach the flat
        state (``Settings.generation.second_order``); None where it is not made."""
        settings = self.settings
        if (
            not settings.generation.second_order
            or pattern.n_vertices > settings.mechanism.second_order_vertices
        ):
            return None
        return obstruction(pattern, self.support_face(pattern), dof, settings)

    def child_forecast(self, current: Solution) -> ChildForecast | None:
        """At a shape whose children get the deployability check: the second-order forecast
        of its candidates (None where it is not made)."""
        opts, settings = self.options, self.settings
        dof = current.mechanism.dof
        limit = settings.generation.deploy_check_max_dof
        pattern = current.result.pattern
        if (
            not (opts.deploy_check and settings.generation.second_order)
            or dof < 2
            or (limit > 0 and dof - 1 > max(limit, opts.target_dof))
            or pattern.n_vertices > settings.mechanism.second_order_vertices
        ):
            return None
        return ChildForecast.at(pattern, self.support_face(pattern), dof, settings)

    def out_of_time(self) -> bool:
        """The run's time limit (``GenerateOptions.time_limit``) has passed."""
        limit = self.options.time_limit
        return limit is not None and time.monotonic() - self.started > limit

    def is_solution(self, rec: Attempt) -> bool:
        """Whether an attempt gives a solution: accepted, or the DOF-0 shape of a target 0."""
        return rec.outcome is AttemptOutcome.ACCEPTED or (
            rec.outcome is AttemptOutcome.ZERO_DOF and self.options.target_dof == 0
        )

    def record(self, rec: Attempt, trial: _Trial) -> None:
        """Count an attempt, tell the callbacks, and keep a solution (:meth:`is_solution`)."""
        run = self.run
        run.n_exceed += rec.outcome is AttemptOutcome.EXCEED
        run.n_lock += rec.outcome is AttemptOutcome.LOCK
        run.n_path += rec.outcome is AttemptOutcome.PATH
        run.n_rigid += rec.outcome is AttemptOutcome.RIGID
        if self.on_attempt:
            self.on_attempt(run, rec)
        if self.is_solution(rec):
            assert trial.mechanism is not None  # a solution was analysed
            sol = Solution(len(run.solutions), trial.result, trial.mechanism, trial.path)
            run.solutions.append(sol)
            self.accepted.append(rec)
            if self.on_solution:
                self.on_solution(run, sol)

    def rank(self, current: Solution) -> tuple[list, Iterator[Choice], ChildForecast | None, float]:
        """Step 6 at the shape ``current``: the ranked crease groups with their scores, the
        order to try them in (look-ahead: lazy, forecast block by block), the second-order
        forecast of its children and the seconds."""
        t1 = time.perf_counter()
        settings = self.settings
        K = hinge_stiffness(
            current.mechanism.frame.n_hinges, int(self.rng.integers(2**32)), settings
        )
        scores = score_creases(current.mechanism, K=K, settings=settings)
        ranked = rank_candidates(scores, self.options.criterion, groups=self.groups, rng=self.rng)
        forecast = self.child_forecast(current)
        order: Iterator[Choice] = (
            lookahead_order(
                current.mechanism,
                [g for g, _ in ranked],
                settings=settings,
                dof0_ends=self.zero_ends,
                locked_before=self.locked_before,
                rigid=None if forecast is None else forecast.rigid,
            )
            if self.options.lookahead
            else _forecast_order([g for g, _ in ranked], forecast)
        )
        return ranked, order, forecast, time.perf_counter() - t1

    def annotate(self, rec: Attempt, choice: Choice, shape: _Shape, current: Solution) -> None:
        """The look-ahead's record of a candidate's attempt (what it skipped, what it was
        predicted to lock, what it carried, whether it was forecast second-order rigid) and
        the forecast's view of the creases it locked."""
        ranked = shape.ranked
        group = ranked[choice.index][0]
        if shape.forecast is not None:
            rec.rigid_forecast = choice.rigid
        if self.options.lookahead:
            rec.predicted_locks = [] if len(choice.carried) else choice.locks.tolist()
            rec.carried = choice.carried.tolist()
            rec.skipped = len(choice.passed)
            rec.skipped_locks = [
                {
                    "fixed": list(ranked[c.index][0]),
                    "locks": c.locks.tolist(),
                    "locked_before": c.locked_before.tolist(),
                    "rigid": c.rigid,
                }
                for c in choice.passed
            ]
        if rec.locked:
            rec.locked_predicted, rec.locked_left = _explain_lock(
                rec, current.mechanism, self.settings
            )
            if self.options.lookahead and not len(choice.carried):
                self.locked_before[group] = rec.locked

    def reduce(self, current: Solution) -> Stop | None:
        """Steps 6-7 at the shape ``current``: fix the best candidate, replacing it with the
        next on failure, until one is accepted (None) or the run ends (its Stop). At a shape
        reduced before (backtracking returned to it), the candidates not yet tried."""
        if not self.shapes or self.shapes[-1].solution is not current:
            ranked, order, forecast, t_sel = self.rank(current)
            self.shapes.append(_Shape(current, ranked, order, forecast, t_sel=t_sel))
        shape = self.shapes[-1]
        ranked, order = shape.ranked, shape.order
        while True:
            if self.out_of_time():
                self.run.stop_detail = f"{self.options.time_limit:g}"
                return Stop.TIME_LIMIT
            t1 = time.perf_counter()
            choice = next(order, None)  # look-ahead: lazy forecast
            shape.t_sel += time.perf_counter() - t1
            if choice is None:
                return Stop.NO_CANDIDATE
            group, score = ranked[choice.index]
            fix = (*group, *choice.carried.tolist())
            trial_fixed = current.result.pattern.fixed.copy()
            trial_fixed[list(fix)] = True
            rec, trial = self.solve(trial_fixed, current.result.coords, fix, score)
            rec.selection_time, shape.t_sel = shape.t_sel, 0.0
            self.annotate(rec, choice, shape, current)
            self.record(rec, trial)
            if self.is_solution(rec):
                return None
            if rec.outcome is AttemptOutcome.ZERO_DOF:
                return Stop.ZERO_DOF
            rigid = rec.outcome is AttemptOutcome.RIGID
            shape.undeployable += rigid or rec.outcome is AttemptOutcome.PATH
            shape.rigid_in_row = shape.rigid_in_row + 1 if rigid else 0
            limit = self.settings.generation.deploy_max_candidates
            if self.restart_case is not None:  # a restart is left: give the shape up sooner
                sooner = self.settings.generation.restart_after
                limit = min(limit, sooner) if limit > 0 else sooner
            confirm = self.settings.generation.rigid_confirmations
            if shape.undeployable >= limit > 0 or (  # bounded cost
                shape.forecast is not None
                and shape.forecast.dead_end
                and shape.rigid_in_row >= confirm > 0
            ):
                self.run.stop_detail = str(shape.undeployable)
                return Stop.NO_DEPLOYABLE

    def backtrack(self, stop: Stop) -> bool:
        """Step 7 beyond the last fix: after ``stop`` at the last solution's shape, retract
        that solution (not the initial shape's) while the run's budget
        (``Settings.generation.backtrack_max``) lasts and the deployability check runs; its
        attempt's outcome becomes DEAD_END. Returns whether it did (then the shape before it
        is reduced again)."""
        run = self.run
        if (
            not self.options.deploy_check
            or stop not in (Stop.NO_DEPLOYABLE, Stop.NO_CANDIDATE)
            or len(run.solutions) < 2
            or self.backtracks >= self.settings.generation.backtrack_max
        ):
            return False
        self.keep_deepest(stop)
        self.shapes.pop()
        self.retract()
        self.backtracks += 1
        run.stop_detail = ""
        return True

    def keep_deepest(self, stop: Stop) -> None:
        """Keep the chain as it stands (with ``stop``) as :attr:`deepest` where it reached a
        lower DOF than the one kept."""
        run = self.run
        if self.deepest is None or _dof(run.solutions) < _dof(self.deepest.solutions):
            self.deepest = _Chain(list(run.solutions), list(self.accepted), stop, run.stop_detail)

    def restart(self, stop: Stop) -> bool:
        """Step 7 beyond backtracking, once a run: after ``stop`` at the last solution's shape
        (its candidates' paths do not reach the flat state, ``Settings.generation.
        restart_after`` of them, or none is left), every solution after the initial one is
        retracted and the chain starts again from the initial shape with bound (12) at
        ``Settings.generation.fold_limit`` on every solve (:func:`with_fold_limit`; the
        attempts' ``fold_bound``), with a backtracking budget of its own. Where the new chain
        ends higher than the first, the run ends with the first (:meth:`settle`). Returns
        whether it did."""
        run = self.run
        if (
            self.restart_case is None
            or stop not in (Stop.NO_DEPLOYABLE, Stop.NO_CANDIDATE)
            or len(run.solutions) < 2
        ):
            return False
        self.keep_deepest(stop)
        while len(run.solutions) > 1:
            self.retract()
        self.shapes.clear()
        t0 = time.perf_counter()
        self.problem = self.restart_case.problem(build_ipopt=self.options.solver == "ipopt")
        run.build_time += time.perf_counter() - t0
        self.restart_case, self.fold_bound, self.backtracks = None, True, 0
        self.locked_before.clear()  # a new chain: the look-ahead's memory of locks is its own
        run.stop_detail = ""
        return True

    def retract(self) -> None:
        """Take back the last solution: its attempt's outcome becomes DEAD_END."""
        run = self.run
        solution = run.solutions.pop()
        self.accepted.pop().outcome = AttemptOutcome.DEAD_END
        run.n_backtrack += 1
        if self.on_retract:
            self.on_retract(run, solution)

    def settle(self, stop: Stop) -> None:
        """The run ends with ``stop`` at its last shape; where backtracking had left a chain
        that reached a lower DOF (:attr:`deepest`), that chain is taken back instead (the
        solutions found since are retracted, its own accepted again) with its stop."""
        run, deepest = self.run, self.deepest
        if deepest is None or _dof(deepest.solutions) >= _dof(run.solutions):
            run.stop = stop
            return
        common = 0
        for a, b in zip(deepest.solutions, run.solutions, strict=False):
            if a is not b:
                break
            common += 1
        while len(run.solutions) > common:
            self.retract()
        for solution, rec in zip(
            deepest.solutions[common:], deepest.accepted[common:], strict=True
        ):
            rec.outcome = AttemptOutcome.ACCEPTED
            run.n_backtrack -= 1  # no longer retracted
            assert solution.step == len(run.solutions)  # the chains share what is before
            run.solutions.append(solution)
            self.accepted.append(rec)
            if self.on_solution:
                self.on_solution(run, solution)
        run.stop, run.stop_detail = deepest.stop, deepest.detail


@one_blas_thread()  # the same path on every machine (see one_blas_thread)
def generate(
    case: Case,
    options: GenerateOptions | None = None,
    *,
    on_attempt: Callable[[Generation, Attempt], None] | None = None,
    on_solution: Callable[[Generation, Solution], None] | None = None,
    on_retract: Callable[[Generation, Solution], None] | None = None,
    **changes,
) -> Generation:
    """Run Steps 2-7 on a case; callbacks see every attempt, every accepted solution and
    every solution retracted by backtracking (``on_retract``, after it has left
    ``run.solutions`` and its attempt's outcome became DEAD_END: the last solution seen by
    ``on_solution``; the next solution takes its step).

    ``options`` (default :class:`GenerateOptions`'s defaults) with ``changes`` to its fields
    given as keywords, e.g. ``generate(case, criterion="s", target_dof=2)``. With mirror
    planes in the case, creases are fixed in mirror groups (2 or 4 at once). With
    ``target_dof=0`` the DOF-0 shape that ends the run is its last solution (its attempt's
    outcome stays ZERO_DOF) and the stop is TARGET_REACHED. A KeyboardInterrupt propagates
    after the callbacks of everything finished so far.
    """
    opts = (options or GenerateOptions()).replace(**changes)
    check_analysis_size(case.pattern, case.settings)  # before the first solve, not after it
    steps = _Steps(case, opts, on_attempt, on_solution, on_retract)
    run = steps.run
    # Steps 2-5 for the triangulated target surface
    rec, trial = steps.solve(case.pattern.fixed.copy(), None, (), None)
    if not steps.is_solution(rec):
        run.stop, run.stop_detail = Stop.INITIAL_FAILED, rec.outcome.value
        rec.outcome = AttemptOutcome.INITIAL_FAILED
        steps.record(rec, trial)
        return run
    assert trial.mechanism is not None  # a solution was analysed
    run.initial_dof = trial.mechanism.dof
    steps.record(rec, trial)
    while run.solutions[-1].mechanism.dof > opts.target_dof:  # Steps 6-7, then 3-5 again
        stop = steps.reduce(run.solutions[-1])
        if stop is not None and not steps.restart(stop) and not steps.backtrack(stop):
            steps.settle(stop)
            _deployable_final(run, opts, case.settings)
            break
    else:
        run.stop, run.stop_detail = Stop.TARGET_REACHED, str(opts.target_dof)
    final = run.final
    if final is not None:
        pattern = final.result.pattern
        run.dof_margin = dof_margin(pattern, steps.support_face(pattern), case.settings).to_dict()
    return run


def with_fold_limit(case: Case, options: GenerateOptions) -> Case:
    """The case of a run's restart (:meth:`_Steps.restart`): with the deployability check and
    no bound (12) of the user's (``Settings.design.rho_bar``), (12) at
    ``Settings.generation.fold_limit``; otherwise ``case`` itself (no restart).

    Each fix flattens a crease, and the solve makes up for it by folding the creases left
    free further: on drawn patterns the chain ends with panels folded nearly onto each other
    (creases near 180 degrees), and the folding paths of such shapes turn back or collide
    before the flat state (docs/deployability.md, issue 40). Bound (12) keeps every solve
    away from that, and IPOPT's barrier on it favours the less folded of the shapes that
    solve (6)."""
    s = case.settings
    limit = s.generation.fold_limit
    if not options.deploy_check or s.design.rho_bar is not None or limit is None:
        return case
    return replace(case, settings=s.with_(rho_bar=limit))


def best_so_far(run: Generation) -> None:
    """Name the final design of a run that stops before its end (interrupted): the
    lowest-DOF solution whose folding path is known to reach the flat state, else the last
    (no path is traced)."""
    for solution in reversed(run.solutions):
        if solution.path is not None and solution.path.deploys:
            run.final_step = solution.step
            return


def _forecast_order(candidates: list, forecast: ChildForecast | None) -> Iterator[Choice]:
    """Without the look-ahead: the criterion's order, except that the candidates forecast to
    leave a second-order rigid shape come last (in the criterion's order); with no forecast,
    the criterion's order."""
    if forecast is None:
        yield from (Choice(k) for k in range(len(candidates)))
        return
    rigid = []
    for k, group in enumerate(candidates):
        if forecast.rigid(tuple(map(int, group))):
            rigid.append(Choice(k, rigid=True))
        else:
            yield Choice(k)
    yield from rigid


def _dof(solutions: list[Solution]) -> int:
    """The DOF of a chain's last solution."""
    return solutions[-1].mechanism.dof


def _classify(mech: Mechanism | None, zero_ends: bool) -> AttemptOutcome:
    """Steps 4-5 on a solve's mechanism (None: not accepted, not analysed)."""
    if mech is None:
        return AttemptOutcome.EXCEED
    if mech.dof == 0:
        # the paper's final cycle (Step 5 -> Step 8); optionally, with a target >= 1, an
        # over-reduction counted as a lock: every folded free crease has stopped moving
        return AttemptOutcome.ZERO_DOF if zero_ends else AttemptOutcome.LOCK
    return AttemptOutcome.LOCK if mech.has_lock else AttemptOutcome.ACCEPTED


def _deployable_final(run: Generation, options: GenerateOptions, settings: Settings) -> None:
    """With the deployability check, a run that ends short of its target names as its final
    design the lowest-DOF solution whose folding path reaches the flat state (tracing the
    paths not yet traced, from the last solution back); none: the last solution."""
    if not options.deploy_check:
        return
    for solution in reversed(run.solutions):
        if solution.path is None:
            solution.path = trace_path(
                solution.result.pattern,
                dof=solution.mechanism.dof,
                support_face=options.support_face,
                settings=settings,
            )
        if solution.path.deploys:
            run.final_step = solution.step
            return


def _checked(mech: Mechanism | None, options: GenerateOptions, settings: Settings) -> bool:
    """Whether the deployability check runs on an accepted solution with this mechanism: at
    most ``Settings.generation.deploy_check_max_dof`` or the target DOF (0: every solution)."""
    limit = settings.generation.deploy_check_max_dof
    return mech is not None and (limit <= 0 or mech.dof <= max(limit, options.target_dof))


def _explain_lock(
    rec: Attempt, before: Mechanism, settings: Settings
) -> tuple[list[bool], list[float | None]]:
    """``locked_predicted`` and ``locked_left`` of an attempt that locked creases: the
    forecast of its candidate at the shape ``before`` the fix."""
    forecast = lock_forecast(before, [rec.fixed_added], settings=settings)
    predicted = set(forecast.locks(0).tolist())
    return [e in predicted for e in rec.locked], forecast.left(0, rec.locked)
