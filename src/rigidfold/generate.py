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

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

import numpy as np

from rigidfold.case import Case
from rigidfold.config import (
    Settings,
    one_blas_thread,
)
from rigidfold.frame.model import default_support_face
from rigidfold.generate_options import GenerateOptions
from rigidfold.generate_records import (
    STOP_REASONS,
    Attempt,
    AttemptOutcome,
    Generation,
    Solution,
    Stop,
)
from rigidfold.mechanism import Mechanism, analyze, check_analysis_size
from rigidfold.mechanism.margin import dof_margin
from rigidfold.mechanism.path import FoldingPath, trace_path
from rigidfold.mechanism.second_order import ChildForecast, Obstruction, obstruction
from rigidfold.mechanism.stiffness import hinge_stiffness
from rigidfold.mesh import CreasePattern
from rigidfold.numerics import numeric_environment
from rigidfold.optimize import OptimizeResult
from rigidfold.selection import (
    Choice,
    crease_groups,
    lock_forecast,
    lookahead_order,
    rank_candidates,
    score_creases,
)

__all__ = [
    "STOP_REASONS",
    "Attempt",
    "AttemptOutcome",
    "GenerateOptions",
    "Generation",
    "Solution",
    "Stop",
    "best_so_far",
    "generate",
    "known_to_deploy",
    "with_fold_limit",
]
"""The records (:mod:`rigidfold.generate_records`) and the options
(:mod:`rigidfold.generate_options`) are exported with the steps that make them."""


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
    look-ahead), the candidates whose paths did not reach the flat state, the candidates
    that failed for any reason, and the seconds of selection not yet charged to an
    attempt."""

    solution: Solution
    ranked: list
    order: Iterator[Choice]
    forecast: ChildForecast | None = None
    undeployable: int = 0
    failed: int = 0
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
        on_retract: Callable[[Generation, tuple[Solution, ...]], None] | None = None,
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
        self.rejected = 0  # the chain's candidates whose paths do not reach the flat state
        # the restarts with bound (12) at each fold limit in turn: (limit, case) not yet used
        self.restarts: list[tuple[float, Case]] = [
            (limit, bounded)
            for limit in self.settings.generation.fold_limits
            if (bounded := with_fold_limit(case, options, limit)) is not case
        ]
        self.fold_limit: float | None = None  # the bound of the chain's solves (radians)

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
                result.pattern,
                dof=mech.dof,
                support_face=opts.support_face,
                settings=settings,
                deadline=self.deadline,
            )
            if not path.deploys:
                outcome = AttemptOutcome.PATH
                # a trace cut by the time limit: the run ends, the second-order test is moot
                second = None if self.out_of_time() else self.obstruction(result.pattern, mech.dof)
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
            fold_limit_deg=None if self.fold_limit is None else math.degrees(self.fold_limit),
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

    @property
    def deadline(self) -> float | None:
        """The end of the run's time limit (``GenerateOptions.time_limit``), a time of
        ``time.monotonic()``; None without a limit. A candidate's path trace ends there."""
        limit = self.options.time_limit
        return None if limit is None else self.started + limit

    def out_of_time(self) -> bool:
        """The run's time limit (``GenerateOptions.time_limit``) has passed."""
        deadline = self.deadline
        return deadline is not None and time.monotonic() > deadline

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
            rejected = rigid or rec.outcome is AttemptOutcome.PATH
            shape.undeployable += rejected
            shape.failed += 1
            self.rejected += rejected
            shape.rigid_in_row = shape.rigid_in_row + 1 if rigid else 0
            budget = limit = self.settings.generation.deploy_max_candidates
            bounded = self.fold_limit is not None  # a solve that fails costs its iterations
            if self.restarts and not bounded:  # the first chain: give up sooner
                sooner = self.settings.generation.restart_after
                limit = min(limit, sooner) if limit > 0 else sooner
            confirm = self.settings.generation.rigid_confirmations
            if (
                shape.undeployable >= limit > 0
                or (bounded and shape.failed >= budget > 0)
                or self.spent()
                or (  # bounded cost
                    shape.forecast is not None
                    and shape.forecast.dead_end
                    and shape.rigid_in_row >= confirm > 0
                )
            ):
                self.run.stop_detail = str(shape.failed if bounded else shape.undeployable)
                return Stop.NO_DEPLOYABLE

    def spent(self) -> bool:
        """Whether the chain, bounded and with a further fold limit, has had as many
        candidates rejected by their paths (N_path, N_rigid) as ``deploy_max_candidates``,
        at whatever shapes: it is then given up for the next limit, not backtracked."""
        budget = self.settings.generation.deploy_max_candidates
        return self.fold_limit is not None and bool(self.restarts) and self.rejected >= budget > 0

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

    def restart(self, stop: Stop, *, after_backtracking: bool = False) -> bool:
        """Step 7 beyond backtracking: after ``stop`` at the last solution's shape (its
        candidates' paths do not reach the flat state, or none is left), every solution after
        the initial one is retracted and the chain starts again from the initial shape with
        bound (12) at the next of ``Settings.generation.fold_limits`` on every solve
        (:func:`with_fold_limit`; the attempts' ``fold_limit_deg``), with a backtracking
        budget of its own. The first chain is given up after ``restart_after`` rejected paths
        at one shape, before any backtracking; a bounded chain once its backtracking is spent
        (``after_backtracking``) or, where a further limit is left, once
        ``deploy_max_candidates`` of its candidates were rejected by their paths, at whatever
        shapes (:meth:`spent`). Where no later chain ends lower, the run ends with the lowest
        (:meth:`settle`). Returns whether it did."""
        run = self.run
        if (
            not self.restarts
            or not (after_backtracking or self.fold_limit is None or self.spent())
            or stop not in (Stop.NO_DEPLOYABLE, Stop.NO_CANDIDATE)
            or len(run.solutions) < 2
        ):
            return False
        self.keep_deepest(stop)
        self.retract(keep=1)
        self.shapes.clear()
        self.fold_limit, case = self.restarts.pop(0)
        t0 = time.perf_counter()
        self.problem = case.problem(build_ipopt=self.options.solver == "ipopt")
        run.build_time += time.perf_counter() - t0
        self.backtracks = self.rejected = 0
        self.locked_before.clear()  # a new chain: the look-ahead's memory of locks is its own
        run.stop_detail = ""
        return True

    def retract(self, keep: int | None = None) -> None:
        """Take back the last solution (``keep`` given: every solution after the first
        ``keep``): their attempts' outcome becomes DEAD_END; the callback sees them at once,
        the last first."""
        run = self.run
        keep = len(run.solutions) - 1 if keep is None else keep
        taken: list[Solution] = []
        while len(run.solutions) > keep:
            taken.append(run.solutions.pop())
            self.accepted.pop().outcome = AttemptOutcome.DEAD_END
            run.n_backtrack += 1
        if self.on_retract and taken:
            self.on_retract(run, tuple(taken))

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
        self.retract(keep=common)
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
    on_retract: Callable[[Generation, tuple[Solution, ...]], None] | None = None,
    **changes,
) -> Generation:
    """Run Steps 2-7 on a case; callbacks see every attempt, every accepted solution and
    the solutions retracted by backtracking or a restart (``on_retract(run, taken)``, once
    they have left ``run.solutions`` and their attempts' outcome became DEAD_END: ``taken``
    the last solutions seen by ``on_solution``, the last first, one call for each
    retraction however many it takes back; the next solution takes the step of the earliest).

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
        if stop is not None and not (
            steps.restart(stop)
            or steps.backtrack(stop)
            or steps.restart(stop, after_backtracking=True)
        ):
            steps.settle(stop)
            _deployable_final(run, opts, case.settings, bisect=stop is Stop.TIME_LIMIT)
            break
    else:
        run.stop, run.stop_detail = Stop.TARGET_REACHED, str(opts.target_dof)
    final = run.final
    if final is not None:
        pattern = final.result.pattern
        run.dof_margin = dof_margin(pattern, steps.support_face(pattern), case.settings).to_dict()
    return run


def with_fold_limit(case: Case, options: GenerateOptions, limit: float) -> Case:
    """The case of a run's restart at the fold limit ``limit`` (radians;
    :meth:`_Steps.restart`): with the deployability check and no bound (12) of the user's
    (``Settings.design.rho_bar``), (12) at ``limit``; otherwise ``case`` itself (no
    restart).

    Each fix flattens a crease, and the solve makes up for it by folding the creases left
    free further: on drawn patterns the chain ends with panels folded nearly onto each other
    (creases near 180 degrees), and the folding paths of such shapes turn back or collide
    before the flat state (docs/deployability.md, issue 40). Bound (12) keeps every solve
    away from that, and IPOPT's barrier on it favours the less folded of the shapes that
    solve (6)."""
    s = case.settings
    if not options.deploy_check or s.design.rho_bar is not None:
        return case
    return replace(case, settings=s.with_(rho_bar=limit))


def best_so_far(run: Generation) -> None:
    """Name the final design of a run that stops before its end (interrupted): the
    lowest-DOF solution whose folding path is known to reach the flat state (of two at one
    DOF, the later); where none is known, ``final_step`` stays None (the last solution),
    which the verdict does not name as a design (:func:`known_to_deploy`). No path is
    traced."""
    known = [s for s in run.solutions if known_to_deploy(s)]
    if known:
        run.final_step = min(known, key=lambda s: (s.mechanism.dof, -s.step)).step


def known_to_deploy(solution: Solution) -> bool:
    """Whether the solution's folding path was traced and reached the flat state (the
    deployability check of Step 5)."""
    return solution.path is not None and bool(solution.path.deploys)


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


def _deployable_final(
    run: Generation, options: GenerateOptions, settings: Settings, *, bisect: bool
) -> None:
    """With the deployability check, a run that ends short of its target names as its final
    design the lowest-DOF solution whose folding path reaches the flat state (tracing the
    paths not yet traced, from the last solution back); none: the last solution.

    A run stopped by its time limit (``bisect``) bisects the chain instead, so that the
    limit is not overrun by up to K traces of its K solutions (the many-DOF paths above the
    lowest are the slow ones) but about log2(K): it names a solution whose own path deploys
    and none of whose probed successors' does. Where the chain's paths deploy down to some
    DOF and none below (as on the drawn patterns measured, docs/deployability.md), that is
    the lowest-DOF solution that deploys, as the scan finds it.
    """
    if not options.deploy_check:
        return

    def deploys(solution: Solution) -> bool:
        if solution.path is None:
            solution.path = trace_path(
                solution.result.pattern,
                dof=solution.mechanism.dof,
                support_face=options.support_face,
                settings=settings,
            )
        return solution.path.deploys

    chain = run.solutions
    if bisect:
        known = [i for i, s in enumerate(chain) if s.path is not None and s.path.deploys]
        lo, hi = (known[-1] if known else -1), len(chain)  # deploys at lo; not known above
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if deploys(chain[mid]) else (lo, mid)
        if lo >= 0:
            run.final_step = chain[lo].step
        return
    for solution in reversed(chain):
        if deploys(solution):
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
