"""Sequential form generation by fixing crease lines (Section 3, Steps 2-7).

::

    Step 2  E_fix = {}, solutions = []
    Step 3  solve problem (6) (from the target surface, then from the last accepted shape)
    Step 4  not accepted (F > F_tol or not converged)         -> Step 7   (N_exceed += 1)
    Step 5  analyse the mechanism:
              DOF >= 1, no locked crease   -> accept, Step 6
              DOF >= 1, a locked crease    -> Step 7                       (N_lock += 1)
              DOF = 0                      -> end, to Step 8 (not counted, Section 6.3);
                                              with ``retry_zero_dof=True`` and a target DOF
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
from dataclasses import dataclass

import numpy as np

from rigidfold.config import (
    Settings,
    one_blas_thread,
)
from rigidfold.generate.budget import time_budget
from rigidfold.generate.case import Case
from rigidfold.generate.chains import (
    Chain,
    ChainControl,
    Frame,
    attempt_time,
    chain_dof,
    makes_sets,
    run_problem,
    with_fold_limit,
)
from rigidfold.generate.deploy_check import DeployCheck
from rigidfold.generate.memo import AttemptMemo, attempt_key
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.records import (
    Attempt,
    AttemptOutcome,
    Generation,
    Solution,
    Stop,
)
from rigidfold.mechanism import Mechanism, analyze, check_analysis_size
from rigidfold.mechanism.margin import DofMargin, dof_margin
from rigidfold.mechanism.path import FoldingPath
from rigidfold.mechanism.second_order import ChildForecast
from rigidfold.mechanism.stiffness import hinge_stiffness
from rigidfold.mesh import CreasePattern
from rigidfold.optimize import OptimizeResult
from rigidfold.runtime.numerics import numeric_environment
from rigidfold.selection import (
    Choice,
    crease_groups,
    lock_forecast,
    lookahead_order,
    rank_candidates,
    score_creases,
)
from rigidfold.selection.batch import compatible_set
from rigidfold.selection.near import near_candidates


@dataclass
class _Trial:
    """What one solve produced: the result, its mechanism (None: not analysed) and its
    folding path (None: not traced)."""

    result: OptimizeResult
    mechanism: Mechanism | None
    path: FoldingPath | None


class _Steps(ChainControl):
    """The steps of one generation run on its state: the problem (built once), the options,
    the run being recorded and the callbacks that see it; the moves between chains
    (backtracking, restarts, the sets' end) are :class:`ChainControl`'s."""

    def __init__(
        self,
        case: Case,
        options: GenerateOptions,
        on_attempt: Callable[[Generation, Attempt], None] | None,
        on_solution: Callable[[Generation, Solution], None] | None,
        on_retract: Callable[[Generation, tuple[Solution, ...]], None] | None = None,
        started: float | None = None,
    ) -> None:
        self.case, self.options, self.settings = case, options, case.settings
        self.on_attempt, self.on_solution, self.on_retract = on_attempt, on_solution, on_retract
        self.rng = np.random.default_rng(options.seed)
        self.run = Generation(
            numerics=numeric_environment().to_dict(), deploy_check=options.deploy_check
        )
        t0 = time.perf_counter()
        self.started = time.monotonic() if started is None else started
        self.budget = time_budget(
            self.started, options.time_limit, case.pattern.n_vertices, case.settings
        )
        self.problem = run_problem(case, options)
        self.run.build_time = time.perf_counter() - t0
        self.groups = (
            crease_groups(case.pattern, case.planes, self.settings) if case.planes else None
        )
        # a DOF-0 shape cannot deploy: with the deployability check and a target >= 1 it is
        # over-reduction, retried like a lock (as with retry_zero_dof=True)
        # the DOF the search counts (Settings.mechanism.dof_count): with "gap", the analysis
        # counts the singular values below dof_gap times rank_tol (near-mechanisms are DOF)
        self.count = _dof_count(self.settings, options)
        m = self.settings.mechanism
        self.asettings = (
            self.settings.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
            if self.count == "gap"
            else self.settings
        )
        self.batch = makes_sets(options)
        self.batch_size = self.settings.generation.batch_first  # the next set's size
        self.peeling = False  # the chain's sets retracted one at a time (unbatch)
        # near-mechanisms first (rigidfold.selection.near): with the gap count and the check
        self.sweep = (
            options.deploy_check and self.count == "gap" and self.settings.generation.near_tries > 0
        )
        self.zero_ends = (
            not self.settings.generation.retry_zero_dof and not options.deploy_check
        ) or options.target_dof == 0
        self.locked_before: dict[tuple[int, ...], list[int]] = {}  # look-ahead: fixes that locked
        self.shapes: list[Frame] = []  # Step 6 at each solution being reduced, the last on top
        self.accepted: list[Attempt] = []  # the attempt of each solution
        self.deepest: Chain | None = None  # the chain of lowest DOF that backtracking left
        self.margins: dict[int, DofMargin] = {}  # by attempt index: those of target solutions
        self.backtracks = 0  # retractions by backtracking in the chain being built
        self.rejected = 0  # the chain's candidates whose paths do not reach the flat state
        # near-mechanisms first: shapes still to skip, and the next skip after one whose near
        # fixes all gained nothing (1, 2, 4, ...; Settings.generation.near_gain)
        self.near_skip = self.near_backoff = 0
        # the restarts with bound (12) at each fold limit in turn: (limit, case) not yet used
        self.restarts: list[tuple[float, Case]] = [
            (limit, bounded)
            for limit in self.settings.generation.fold_limits
            if (bounded := with_fold_limit(case, options, limit)) is not case
        ]
        self.ladder = list(self.restarts)
        self.unbounded = self.problem
        self.search_round = 0  # Settings.generation.reseeds
        self.stiffness = self.settings  # the K_j's spread: the paper's in the first round
        self.first: Chain | None = None  # the first round's chain, once later rounds began
        self.best: Chain | None = None  # a later round's chain that ended lower (conclude)
        self.silent = False  # a later round under way (ChainControl.publish)
        self.fold_limit: float | None = None  # the bound of the chain's solves (radians)
        # the fixes whose solutions were retracted, by the step of the shape they reduced:
        # not tried again where a restart's kept shape is ranked anew
        self.dead: dict[int, set[tuple[int, ...]]] = {}
        self.checks = DeployCheck(options, self.settings)  # Step 5's check, its rejections
        # the attempts by starting shape and fix: none is solved twice
        self.memo: AttemptMemo[_Trial] = AttemptMemo(self.settings.generation.reuse_max_dof)

    def solve(
        self, fixed: np.ndarray, start, added, score, *, polish: bool = True
    ) -> tuple[Attempt, _Trial]:
        """Steps 3-5 for one set of fixed creases: solve problem (6) from ``start``, polish
        (with the deployability check and ``polish``), analyse the mechanism, classify, trace
        the path.
        With a time limit the solve ends at the run's deadline, the initial solve (``start``
        None: without it the run has no design) half a grace after T
        (:attr:`TimeBudget.first_solve`); with the deployability check a child's solve
        (``start`` given) ends after ``Settings.generation.child_max_iter`` iterations, or
        where its least feasible F has not halved in ``child_stall`` iterations above F_tol."""
        opts = self.options
        if start is not None or self.budget is None:
            deadline = self.deadline
        else:
            deadline = self.budget.first_solve
        # a child's solve that runs on, or whose F stalls, mostly finds no shape within dz
        # (child_max_iter, child_stall)
        child = start is not None and opts.deploy_check
        gen = self.settings.generation
        result = self.problem.solve(
            fixed=fixed,
            start=start,
            solver=opts.solver,
            deadline=deadline,
            max_iter=gen.child_max_iter if child else None,
            stall=gen.child_stall if child else None,
        )
        cut = deadline is not None and time.monotonic() > deadline
        if opts.deploy_check and polish:
            result = self.problem.polish(result, deadline)
        t1 = time.perf_counter()
        mech = (
            analyze(result.pattern, support_face=opts.support_face, settings=self.asettings)
            if result.converged
            else None
        )
        t_an = time.perf_counter() - t1
        outcome = _classify(mech, self.zero_ends)
        if mech is None and cut:  # the time limit ended the solve: no verdict
            outcome = AttemptOutcome.TIME_LIMIT
        path, t_path, checked = None, 0.0, None
        if outcome is AttemptOutcome.ACCEPTED and self.checks.applies(mech):
            assert mech is not None
            t2 = time.perf_counter()
            checked = self.checks.check(
                result.pattern, mech.dof, len(self.run.attempts), self.deadline
            )
            outcome, path = checked.outcome, checked.path
            t_path = time.perf_counter() - t2
        if outcome is AttemptOutcome.ACCEPTED and start is not None and self.wants_gap(mech):
            assert mech is not None
            margin = self.margin(result.pattern, mech.dof)
            self.margins[len(self.run.attempts)] = margin  # this attempt's index
            if not margin.clear:
                outcome = AttemptOutcome.NO_GAP
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
            path=None if checked is None else checked.path_record,
            path_time=t_path,
            second_order=None if checked is None else checked.second_record,
            fold_limit_deg=None if self.fold_limit is None else math.degrees(self.fold_limit),
            path_from=None if checked is None else checked.path_from,
            search_round=self.search_round,
        )
        self.run.attempts.append(rec)
        return rec, _Trial(result, mech, path)

    @property
    def deadline(self) -> float | None:
        """The end of the search (:attr:`TimeBudget.search`: the time limit less the
        reserve for the final design's stages), a time of ``time.monotonic()``; None
        without a limit. The solve under way and a candidate's path trace end there."""
        return None if self.budget is None else self.budget.search

    @property
    def final_deadline(self) -> float | None:
        """The end of naming the final design (:attr:`TimeBudget.naming`, a grace after the
        search's end; None without a limit)."""
        return None if self.budget is None else self.budget.naming

    def time_up(self) -> Stop:
        """The run's Stop at its time limit, with the limit as its detail."""
        self.run.stop_detail = f"{self.options.time_limit:g}"
        return Stop.TIME_LIMIT

    def out_of_time(self) -> bool:
        """The run's time limit (``GenerateOptions.time_limit``) has passed."""
        deadline = self.deadline
        return deadline is not None and time.monotonic() > deadline

    def wants_gap(self, mech: Mechanism | None) -> bool:
        """Whether a solution of ``mech`` must show a clear DOF gap to be accepted
        (``Settings.generation.clear_gap``, with the deployability check, at the target)."""
        return (
            mech is not None
            and self.options.deploy_check
            and self.settings.generation.clear_gap
            and 1 <= mech.dof <= self.options.target_dof
        )

    def margin(self, pattern: CreasePattern, counted: int) -> DofMargin:
        """The DOF margin of a solution's shape whose search counted ``counted``."""
        return dof_margin(
            pattern,
            self.checks.support_face(pattern),
            self.settings,
            count=self.count,
            counted=counted,
        )

    def keep_no_gap(self, rec: Attempt, trial: _Trial) -> None:
        """Keep a solution at the target DOF without a clear gap (its attempt's outcome
        NO_GAP) as the run's fallback: the chain that ends with it becomes :attr:`deepest`
        where it is lower than the one kept, so that :meth:`settle` delivers it when the
        search finds nothing better."""
        assert trial.mechanism is not None  # a solution was analysed
        run = self.run
        sol = Solution(len(run.solutions), trial.result, trial.mechanism, trial.path)
        chain = Chain(
            [*run.solutions, sol],
            [*self.accepted, rec],
            Stop.TARGET_REACHED,
            str(self.options.target_dof),
        )
        if self.deepest is None or chain_dof(chain.solutions) < chain_dof(self.deepest.solutions):
            self.deepest = chain

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
            self.show(sol)

    def rank(self, current: Solution) -> tuple[list, Iterator[Choice], ChildForecast | None, float]:
        """Step 6 at the shape ``current``: the ranked crease groups with their scores, the
        order to try them in (look-ahead: lazy, forecast block by block), the second-order
        forecast of its children and the seconds."""
        t1 = time.perf_counter()
        K = hinge_stiffness(
            current.mechanism.frame.n_hinges, int(self.rng.integers(2**32)), self.stiffness
        )
        scores = score_creases(current.mechanism, K=K, settings=self.asettings)
        ranked = rank_candidates(scores, self.options.criterion, groups=self.groups, rng=self.rng)
        forecast = self.checks.child_forecast(current.result.pattern, current.mechanism.dof)
        order: Iterator[Choice] = (
            lookahead_order(
                current.mechanism,
                [g for g, _ in ranked],
                settings=self.asettings,
                dof0_ends=self.zero_ends,
                locked_before=self.locked_before,
                rigid=None if forecast is None else forecast.rigid,
                idle_last=self.options.deploy_check and self.settings.generation.idle_last,
            )
            if self.options.lookahead
            else _forecast_order([g for g, _ in ranked], forecast)
        )
        return ranked, order, forecast, time.perf_counter() - t1

    def annotate(self, rec: Attempt, choice: Choice, shape: Frame, current: Solution) -> None:
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
                    "idle": c.idle,
                }
                for c in choice.passed
            ]
        if rec.locked:
            rec.locked_predicted, rec.locked_left = _explain_lock(
                rec, current.mechanism, self.asettings
            )
            if self.options.lookahead and not len(choice.carried):
                self.locked_before[group] = rec.locked

    def reduce(self, current: Solution) -> Stop | None:
        """Steps 6-7 at the shape ``current``: fix the best candidate, replacing it with the
        next on failure, until one is accepted (None) or the run ends (its Stop). At a shape
        reduced before (backtracking returned to it), the candidates not yet tried."""
        if not self.shapes or self.shapes[-1].solution is not current:
            if self.out_of_time():  # no ranking of a shape that no solve will reduce
                return self.time_up()
            ranked, order, forecast, t_sel = self.rank(current)
            self.shapes.append(Frame(current, ranked, order, forecast, t_sel=t_sel))
        shape = self.shapes[-1]
        ranked, order = shape.ranked, shape.order
        if self.sweep and not shape.swept and self.set_size(current) < 2:
            # a shape that gets a set of creases leaves its near-mechanisms to the set:
            # taken one per solve far from the target, they mostly gain no DOF (issue 49)
            shape.swept = True
            done = self.fix_near(current, shape)
            if done is not False:
                return None if done is True else done
        if self.batch and not shape.batched:
            shape.batched = True
            done = self.fix_set(current, shape)
            if done is not False:
                return None if done is True else done
        while True:
            if self.out_of_time():
                return self.time_up()
            t1 = time.perf_counter()
            choice = next(order, None)  # look-ahead: lazy forecast
            shape.t_sel += time.perf_counter() - t1
            if choice is None:
                return Stop.NO_CANDIDATE
            group, score = ranked[choice.index]
            fix = (*group, *choice.carried.tolist())
            if fix in self.dead.get(current.step, ()) or fix in shape.tried:
                continue  # retracted before (a dead end), or tried first (fix_near)
            rec, trial = self.try_fix(current, shape, fix, score)
            if (  # an idle fix that kept the DOF: the shape again, not kept (idle_gain)
                choice.idle
                and self.settings.generation.idle_gain
                and self.is_solution(rec)
                and (rec.dof or 0) >= current.mechanism.dof
            ):
                rec.outcome = AttemptOutcome.NO_GAIN
            shape.fallback = choice.put_off  # every candidate forecast to deploy was tried
            self.annotate(rec, choice, shape, current)
            self.record(rec, trial)
            if self.is_solution(rec):
                return None
            if rec.outcome is AttemptOutcome.NO_GAP:
                self.keep_no_gap(rec, trial)
            if rec.outcome is AttemptOutcome.ZERO_DOF:
                return Stop.ZERO_DOF
            if rec.outcome is AttemptOutcome.TIME_LIMIT:
                return self.time_up()
            rigid = rec.outcome is AttemptOutcome.RIGID
            rejected = rigid or rec.outcome in (AttemptOutcome.PATH, AttemptOutcome.NO_GAP)
            shape.undeployable += rejected
            shape.failed += 1
            self.rejected += rejected
            shape.rigid_in_row = shape.rigid_in_row + 1 if rigid else 0
            budget = limit = self.settings.generation.deploy_max_candidates
            bounded = self.fold_limit is not None  # a solve that fails costs its iterations
            if self.restarts and not bounded and not self.worth_more(shape):
                # the first chain: give up sooner
                sooner = self.settings.generation.restart_after
                limit = min(limit, sooner) if limit > 0 else sooner
            if self.sets_made():  # the sets end sooner (unbatch)
                ends = self.settings.generation.batch_end_after
                limit = min(limit, ends) if limit > 0 else ends
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

    def try_fix(
        self,
        current: Solution,
        shape: Frame,
        fix: tuple[int, ...],
        score: float | None,
        *,
        polish: bool = True,
    ) -> tuple[Attempt, _Trial]:
        """Steps 3-5 at the shape ``current`` with the creases ``fix`` fixed as well
        (:meth:`solve` from its coordinates, ``polish`` passed on; a fix met before at bitwise
        the same shape repeats that attempt instead, :mod:`rigidfold.generate.memo`); the
        attempt is charged the selection time not yet charged, and ``shape`` the attempt's
        seconds. Not yet recorded."""
        start = current.result.pattern
        key = attempt_key(start, fix, self.fold_limit, polish)
        repeat = self.memo.repeat(key, len(self.run.attempts), self.search_round)
        if repeat is not None:  # the same fix from the same shape: its attempt again
            rec, trial = repeat
            assert rec.solve_from is not None
            if rec.solve_from in self.margins:
                self.margins[rec.index] = self.margins[rec.solve_from]
            rec.fixed_added, rec.score = tuple(fix), score
            self.run.attempts.append(rec)
        else:
            trial_fixed = start.fixed.copy()
            trial_fixed[list(fix)] = True
            rec, trial = self.solve(trial_fixed, start.coords, fix, score, polish=polish)
            # a rejected candidate's mechanism and path are not needed again
            needed = self.is_solution(rec) or rec.outcome is AttemptOutcome.NO_GAP
            self.memo.keep(key, rec, trial if needed else _Trial(trial.result, None, None))
        rec.selection_time, shape.t_sel = shape.t_sel, 0.0
        shape.spent += attempt_time(rec)
        return rec, trial

    def fix_near(self, current: Solution, shape: Frame) -> Stop | bool:
        """Near-mechanisms first (:mod:`rigidfold.selection.near`): at a shape whose DOF,
        counted with the gap, has fewer exact mechanisms, up to ``near_tries`` candidates
        that turn in its near-mechanisms but hardly in the exact ones (share below
        ``near_ratio``) are fixed one per solve before the ranked ones, where the shape has
        at most ``near_max`` near-mechanisms; a fix whose solution has more DOF than its
        shape (with ``near_gain``: no fewer) is not kept (``no_gain``), and with
        ``near_gain``, after a shape whose fixes all gained nothing, the next 1, 2, 4, ...
        shapes skip them. Returns True when one gave a solution, the run's
        Stop (the time limit; NO_CANDIDATE for a shape after the first without an exact
        mechanism, with ``near_rigid_backtrack``), or False (the shape goes on with its ranked
        candidates, those tried here left out)."""
        g = self.settings.generation
        counted = current.mechanism
        # the exact DOF from the search's own factorisation; its modes, where there are a few
        # near-mechanisms, from a second analysis at the rank threshold
        exact_dof = counted.dof_at(self.settings.mechanism.rank_tol)
        if exact_dof == 0 and current.step > 0 and g.near_rigid_backtrack:
            return Stop.NO_CANDIDATE  # rigid but for near-mechanisms: a dead end
        if exact_dof in (0, counted.dof) or counted.dof - exact_dof > g.near_max:
            return False  # no near-mechanism to take away, or a continuum (near_candidates)
        if self.near_skip > 0:
            self.near_skip -= 1  # the last near fixes gained nothing: this shape goes without
            return False
        t1 = time.perf_counter()
        exact = analyze(
            current.result.pattern, support_face=self.options.support_face, settings=self.settings
        )
        found = near_candidates(
            counted,
            exact,
            self.groups,
            g.near_ratio,
            self.settings.mechanism.lock_tol,
            most=g.near_max,
        )
        shape.t_sel += time.perf_counter() - t1
        dead = self.dead.get(current.step, ())
        tried = no_gain = 0
        for group, share in [c for c in found if c[0] not in dead][: g.near_tries]:
            if self.out_of_time():
                return self.time_up()
            shape.tried.add(group)
            rec, trial = self.try_fix(current, shape, group, None)
            rec.near = share
            # a count that rose is refused; with near_gain, one that stayed too
            if self.is_solution(rec) and (rec.dof or 0) >= current.mechanism.dof + (
                not g.near_gain
            ):
                rec.outcome = AttemptOutcome.NO_GAIN
            self.record(rec, trial)
            tried += 1
            no_gain += rec.outcome is AttemptOutcome.NO_GAIN
            if self.is_solution(rec):
                self.near_backoff = 0
                return True
            if rec.outcome is AttemptOutcome.TIME_LIMIT:
                return self.time_up()
            if rec.outcome is AttemptOutcome.ZERO_DOF:
                return Stop.ZERO_DOF
        if g.near_gain and tried and no_gain == tried:
            self.near_backoff = self.near_skip = max(1, 2 * self.near_backoff)
        return False

    def set_size(self, current: Solution) -> int:
        """The size of the next set of creases at the shape ``current``: 0 without sets
        (``GenerateOptions.batch``), otherwise at most the next set's size, never taking the
        exact DOF (at the rank threshold, without the near-mechanisms the gap count adds)
        within ``batch_single_dof`` of the target (below 2: one crease per solve)."""
        if not self.batch:
            return 0
        g = self.settings.generation
        exact = current.mechanism.dof_at(self.settings.mechanism.rank_tol)
        room = exact - max(self.options.target_dof, 1) - g.batch_single_dof
        return max(0, min(self.batch_size, g.batch_max, room))

    def fix_set(self, current: Solution, shape: Frame) -> Stop | bool:
        """Several creases in one solve (``GenerateOptions.batch``; :mod:`rigidfold.selection.
        batch`): at a shape more than ``batch_single_dof`` DOF above the target, the largest
        compatible set of its ranked candidates, of at most the next set's size and never
        taking the DOF within ``batch_single_dof`` of the target, is solved; on failure, half
        of it, down to two candidates. Returns True when a set gave a solution (the next set
        may be twice as large), the run's Stop (the time limit), or False (the shape goes on
        one crease at a time)."""
        size = self.set_size(current)
        if size < 2:
            return False
        g = self.settings.generation
        t1 = time.perf_counter()
        groups = [tuple(map(int, grp)) for grp, _ in shape.ranked]
        chosen = compatible_set(
            current.mechanism,
            groups,
            size,
            settings=self.asettings,
            skip=lambda k: groups[k] in self.locked_before,
        )
        shape.t_sel += time.perf_counter() - t1
        while len(chosen) >= 2:
            if self.out_of_time():
                return self.time_up()
            fix = tuple(e for k in chosen for e in groups[k])
            # not polished: a set never takes the DOF to where the deployability check
            # runs, so no path is traced from its shape (issue 49)
            rec, trial = self.try_fix(current, shape, fix, shape.ranked[chosen[0]][1], polish=False)
            rec.batch = len(chosen)
            self.record(rec, trial)
            if self.is_solution(rec):
                self.batch_size = min(2 * len(chosen), g.batch_max)
                return True
            if rec.outcome is AttemptOutcome.TIME_LIMIT:
                return self.time_up()
            chosen = chosen[: len(chosen) // 2]
            self.batch_size = max(2, len(chosen))
        return False


@one_blas_thread()  # the same path on every machine (see one_blas_thread)
def generate(
    case: Case,
    options: GenerateOptions | None = None,
    *,
    on_attempt: Callable[[Generation, Attempt], None] | None = None,
    on_solution: Callable[[Generation, Solution], None] | None = None,
    on_retract: Callable[[Generation, tuple[Solution, ...]], None] | None = None,
    started: float | None = None,
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
    after the callbacks of everything finished so far. ``started``: the time of
    ``time.monotonic()`` that the time limit counts from (default: the call; the command
    line gives its process's start, :func:`rigidfold.runtime.clock.process_age`).
    """
    opts = (options or GenerateOptions()).replace(**changes)
    check_analysis_size(case.pattern, case.settings)  # before the first solve, not after it
    steps = _Steps(case, opts, on_attempt, on_solution, on_retract, started)
    run = steps.run
    # Steps 2-5 for the triangulated target surface
    rec, trial = steps.solve(case.pattern.fixed.copy(), None, (), None)
    if rec.outcome is AttemptOutcome.TIME_LIMIT:  # the limit ended the first solve
        run.stop, run.stop_detail = Stop.TIME_LIMIT, f"{opts.time_limit:g}"
        steps.record(rec, trial)
        return run
    if not steps.is_solution(rec):
        run.stop, run.stop_detail = Stop.INITIAL_FAILED, _first_failure(rec)
        rec.outcome = AttemptOutcome.INITIAL_FAILED
        steps.record(rec, trial)
        return run
    assert trial.mechanism is not None  # a solution was analysed
    run.initial_dof = trial.mechanism.dof
    steps.record(rec, trial)
    try:
        while run.solutions[-1].mechanism.dof > opts.target_dof:  # Steps 6-7, then 3-5 again
            stop = steps.reduce(run.solutions[-1])
            if stop is not None and not (
                steps.unbatch(stop)
                or steps.restart(stop)
                or steps.backtrack(stop)
                or steps.restart(stop, after_backtracking=True)
                or steps.reseed(stop, steps.final_deadline)
            ):
                steps.conclude(stop, steps.final_deadline)
                break
        else:
            run.stop, run.stop_detail = Stop.TARGET_REACHED, str(opts.target_dof)
            steps.publish()
    except KeyboardInterrupt:
        steps.interrupted()  # the chain the callbacks have
        raise
    final = run.final
    if final is not None:  # its margin, once: the search's where it took one
        attempt = steps.accepted[final.step].index
        margin = steps.margins.get(attempt) or steps.margin(
            final.result.pattern, final.mechanism.dof
        )
        run.dof_margin = margin.to_dict()
    return run


def _first_failure(rec: Attempt) -> str:
    """Why the first solve gave no design, in words: for a solve not accepted (``exceed``)
    the solver's status with F and its iterations (IPOPT's "infeasible" or its iteration
    limit are not what "exceed" says), otherwise the attempt's outcome (a lock, DOF 0)."""
    if rec.outcome is not AttemptOutcome.EXCEED:
        return rec.outcome.value
    return f"{rec.status.value}: F {rec.F:.2g} after {rec.iterations} iterations"


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


def _dof_count(settings: Settings, options: GenerateOptions) -> str:
    """The DOF count of a run (``Settings.mechanism.dof_count``): "auto" is "gap" with the
    deployability check, the paper's "threshold" without it (the paper's Step 5)."""
    count = settings.mechanism.dof_count
    if count == "auto":
        return "gap" if options.deploy_check else "threshold"
    return count


def _classify(mech: Mechanism | None, zero_ends: bool) -> AttemptOutcome:
    """Steps 4-5 on a solve's mechanism (None: not accepted, not analysed)."""
    if mech is None:
        return AttemptOutcome.EXCEED
    if mech.dof == 0:
        # the paper's final cycle (Step 5 -> Step 8); optionally, with a target >= 1, an
        # over-reduction counted as a lock: every folded free crease has stopped moving
        return AttemptOutcome.ZERO_DOF if zero_ends else AttemptOutcome.LOCK
    return AttemptOutcome.LOCK if mech.has_lock else AttemptOutcome.ACCEPTED


def _explain_lock(
    rec: Attempt, before: Mechanism, settings: Settings
) -> tuple[list[bool], list[float | None]]:
    """``locked_predicted`` and ``locked_left`` of an attempt that locked creases: the
    forecast of its candidate at the shape ``before`` the fix."""
    forecast = lock_forecast(before, [rec.fixed_added], settings=settings)
    predicted = set(forecast.locks(0).tolist())
    return [e in predicted for e in rec.locked], forecast.left(0, rec.locked)
