"""The chains of a run (Step 7 beyond the last fix, with the deployability check): a chain
is the stack of accepted shapes being reduced, one :class:`Frame` each; when a shape's
candidates are spent, the chain backtracks to the shape before it, restarts from the
initial shape with bound (12) at the next fold limit, or ends its sets of creases
(``GenerateOptions.batch`` "auto") and goes on one crease per solve; a round of the search
ends with the chain that reached the lowest DOF (:meth:`ChainControl.settle`), and its final
design is named; where it falls short of the target, later rounds start again from the
initial shape with other fictitious hinge stiffnesses (:meth:`ChainControl.reseed`), kept
where one reaches the target, or ends with a design known to deploy of lower DOF than the
first round's (:meth:`ChainControl.conclude`).

:class:`ChainControl` holds these moves; the steps of one run (:mod:`rigidfold.generate.
steps`) inherit them and own the state they act on, declared here.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from rigidfold.config import Settings
from rigidfold.generate.case import Case
from rigidfold.generate.deploy_check import DeployCheck
from rigidfold.generate.final import (
    deployable_final,
    known_to_deploy,
    lowest_deploying,
    traced_deploys,
)
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.records import Attempt, AttemptOutcome, Generation, Solution, Stop
from rigidfold.mechanism.second_order import ChildForecast
from rigidfold.optimize import FormFindingProblem, SolverName
from rigidfold.selection import Choice


@dataclass
class Frame:
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
    spent: float = 0.0  # seconds of its candidates' attempts (selection, solve, trace)
    batched: bool = False  # a set of several creases was tried here (GenerateOptions.batch)
    swept: bool = False  # its near-mechanisms' candidates were tried here (fix_near)
    tried: set[tuple[int, ...]] = field(default_factory=set)  # fixes tried by fix_near
    fallback: bool = False  # the last candidate was forecast to lock or to be rigid


DEAD_ENDS = (Stop.NO_DEPLOYABLE, Stop.NO_CANDIDATE)
"""The stops at a shape that end a chain (no candidate deploys, or none is left): where
sets end (:meth:`ChainControl.unbatch`), a chain restarts or backtracks."""


@dataclass
class Chain:
    """The solutions of a run (and their attempts) when it stopped at their last shape, kept
    in case backtracking ends at a higher DOF: the stop and its detail."""

    solutions: list[Solution]
    accepted: list[Attempt]
    stop: Stop
    detail: str
    final_step: int | None = None  # the design named at its end (the first round's)


class ChainControl:
    """Backtracking, restarts at the fold limits, the end of the sets and the chain a run
    ends with, on the state of one run's steps (:mod:`rigidfold.generate.steps`)."""

    run: Generation
    options: GenerateOptions
    settings: Settings
    problem: FormFindingProblem
    on_solution: Callable[[Generation, Solution], None] | None
    on_retract: Callable[[Generation, tuple[Solution, ...]], None] | None
    rng: np.random.Generator
    batch: bool  # sets of creases are made (GenerateOptions.batch)
    batch_size: int  # the next set's size
    peeling: bool  # a dead end retracts the chain's last set (Settings.generation.unbatch_peel)
    stiffness: Settings  # the settings of the round's K_j (reseed_spread after the first)
    shapes: list[Frame]  # Step 6 at each solution being reduced, the last on top
    accepted: list[Attempt]  # the attempt of each solution
    deepest: Chain | None  # the chain of lowest DOF that backtracking left
    backtracks: int  # retractions by backtracking in the chain being built
    rejected: int  # the chain's candidates whose paths do not reach the flat state
    restarts: list[tuple[float, Case]]  # (fold limit, case) not yet used
    fold_limit: float | None  # the bound of the chain's solves (radians)
    dead: dict[int, set[tuple[int, ...]]]  # retracted fixes, by the step of their shape
    locked_before: dict[tuple[int, ...], list[int]]  # look-ahead: fixes that locked
    search_round: int  # the round of the search (reseed), 0 the first
    first: Chain | None  # the first round's chain and design, once later rounds began
    best: Chain | None  # the later rounds' lowest chain ending with a design that deploys
    silent: bool  # a later round under way: its solutions not shown to the callbacks (publish)
    ladder: list[tuple[float, Case]]  # every round's restarts, in order
    unbounded: FormFindingProblem  # the problem of a round's first chain
    checks: DeployCheck  # the deployability check of the run's candidates

    def worth_more(self, shape: Frame) -> bool:
        """Whether the first chain keeps trying candidates at ``shape`` past
        ``restart_after`` rejected paths instead of restarting: while its next candidates
        are still forecast to deploy (the last one tried was not put off by the look-ahead
        or the second-order forecast) and what its candidates have cost so far is less than
        re-solving the chain to this shape (the seconds of its accepted attempts), and, with
        ``Settings.generation.rewind`` once ``restart_after`` of them were rejected, while
        the shape's own path reaches the flat state (:meth:`lost_above`)."""
        chain = sum(attempt_time(rec) for rec in self.accepted[1:])
        if shape.fallback or shape.spent >= chain:
            return False
        # with the rewind, a shape that does not deploy itself is not worth more
        restart_after = self.settings.generation.restart_after
        return shape.undeployable < restart_after or self.lost_above() is None

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
        attempt's outcome becomes DEAD_END. With ``Settings.generation.rewind``, where the
        shape does not deploy itself, every solution below the chain's lowest that deploys
        is retracted instead (:meth:`lost_above`), as one retraction of the budget. Returns
        whether it did (then the shape before it, or that lowest one, is reduced again)."""
        run = self.run
        if (
            not self.options.deploy_check
            or stop not in DEAD_ENDS
            or len(run.solutions) < 2
            or self.backtracks >= self.settings.generation.backtrack_max
        ):
            return False
        self.keep_deepest(stop)
        last = len(run.solutions) - 1
        keep = self.lost_above() or last  # the lowest that deploys lies below the last
        while self.shapes and self.shapes[-1].solution.step >= keep:
            self.shapes.pop()
        if keep < last:  # a rewind: the retracted shapes' dead ends go with them
            self.dead = {step: fixes for step, fixes in self.dead.items() if step < keep}
        self.dead.setdefault(keep - 1, set()).add(tuple(self.accepted[keep].fixed_added))
        self.retract(keep=keep)
        self.backtracks += 1
        run.stop_detail = ""
        return True

    def lost_above(self) -> int | None:
        """Where the chain lost its deployability (``Settings.generation.rewind``): at a dead
        end of its last shape, whose children get the check, the shape's own path is traced;
        where that does not reach the flat state, the number of the chain's solutions up to
        the lowest whose path deploys (:func:`lowest_deploying` from the chain's end back,
        down to the latest known to deploy, or the initial shape), which backtracking and a
        restart keep: at most the chain's length less one. None: the rewind does not apply,
        the last shape deploys, or a trace was cut by the deadline. The traces are kept on
        the solutions (``Solution.path``): a shape is traced once a run, and the final
        design's naming reads them."""
        run, chain = self.run, self.run.solutions
        if (
            not self.settings.generation.rewind
            or len(chain) < 3
            or not self.checks.checks_children(chain[-1].mechanism.dof)
        ):
            return None
        cut = False

        def deploys(solution: Solution) -> bool:
            nonlocal cut
            verdict, seconds = traced_deploys(solution, self.options, self.settings, self.deadline)
            run.rewind_path_time += seconds
            cut = cut or verdict is None
            return bool(verdict)

        if deploys(chain[-1]) or cut:
            return None
        known = [k for k, solution in enumerate(chain) if known_to_deploy(solution)]
        lowest = lowest_deploying(chain, max(known, default=0), deploys, gallop=True)
        return None if cut else lowest + 1

    def keep_deepest(self, stop: Stop) -> None:
        """Keep the chain as it stands (with ``stop``) as :attr:`deepest` where it reached a
        lower DOF than the one kept."""
        run = self.run
        if self.deepest is None or chain_dof(run.solutions) < chain_dof(self.deepest.solutions):
            self.deepest = Chain(list(run.solutions), list(self.accepted), stop, run.stop_detail)

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
        shapes (:meth:`spent`). With ``Settings.generation.rewind`` the new chain keeps no
        solution below the old one's lowest that deploys (:meth:`lost_above`). Where no later
        chain ends lower, the run ends with the lowest (:meth:`settle`). Returns whether it
        did."""
        run = self.run
        if (
            not self.restarts
            or not (after_backtracking or self.fold_limit is None or self.spent())
            or stop not in DEAD_ENDS
        ):
            return False
        self.keep_deepest(stop)
        limit, case = self.restarts.pop(0)
        keep = within(run.solutions, limit)
        self.new_chain(keep=min(keep, self.lost_above() or keep))
        self.fold_limit = limit
        t0 = time.perf_counter()
        self.problem = run_problem(case, self.options)
        run.build_time += time.perf_counter() - t0
        return True

    def out_of_time(self) -> bool:
        """Whether the search's time is spent (the steps' time limit)."""
        raise NotImplementedError

    @property
    def deadline(self) -> float | None:
        """The end of the search (the steps' time limit), a time of ``time.monotonic()``."""
        raise NotImplementedError

    def reseed(self, stop: Stop, deadline: float | None) -> bool:
        """Step 7 beyond the fold limits: after ``stop`` at the last solution's shape with
        every chain of the round spent, the search starts a new round from the initial shape
        (``Settings.generation.reseeds`` of them at most, ``reseeds_timed`` with a time
        limit, with the deployability check and while the search has time): the ranking's
        generator seeded with (seed, round), and the fictitious hinge stiffnesses K_j of the
        criteria spread by ``reseed_spread`` of their mean
        (:meth:`rigidfold.generate.steps._Steps.rank`), so that creases of close scores rank
        otherwise; the round's first chain unbounded and with the sets of creases, its
        restarts at the fold limits and its backtracking as in the first round.
        The rounds share the verdicts of rejected shapes
        (:class:`rigidfold.generate.deploy_check.DeployCheck`).

        At the first round's end, its chain is settled and its final design named
        (``deadline``, :func:`rigidfold.generate.final.deployable_final`) as a run of one
        round would, and kept (:attr:`first`): a later round is kept where it reaches the
        target; at the end of one that falls short, its lowest chain is kept where it ends
        with a design known to deploy below the design kept so far (:meth:`keep_best`: a
        solution at the target without a clear gap, say, against the first round's DOF 2),
        and :meth:`conclude` takes the lowest back, the first round's chain and design where
        no later round ended lower. No path is traced for it: a later round's design is
        kept only where its deployment is already known, so that the grace after the
        search is not spent naming one (docs/broad_set.md, sessions 34 and 37).
        The later rounds are :attr:`silent`: the callbacks keep the first round's chain (a
        run directory its files, the design named) while they go, and see a round's chain
        only once it is kept at the run's end (:meth:`publish`); an interrupt meanwhile ends the
        run with the first round's chain (:meth:`interrupted`). Returns whether a round
        began."""
        if (
            not self.options.deploy_check
            or stop not in DEAD_ENDS
            or self.search_round >= self.rounds_allowed()
        ):
            return False
        run = self.run
        if self.first is None:  # the first round ends as a run of one round would
            self.settle(stop)
            self.name_final(stop, deadline)
            self.first = Chain(
                list(run.solutions), list(self.accepted), run.stop, run.stop_detail, run.final_step
            )
        else:
            self.keep_best(stop)
        if self.out_of_time():
            return False
        self.silent = True
        self.search_round += 1
        self.deepest = None
        run.final_step = None
        self.new_chain(keep=1)
        self.dead.clear()
        self.restarts = list(self.ladder)
        self.fold_limit = None
        self.problem = self.unbounded
        self.batch = makes_sets(self.options)
        self.batch_size = self.settings.generation.batch_first
        self.peeling = False
        self.rng = np.random.default_rng([self.options.seed, self.search_round])
        g = self.settings.generation
        self.stiffness = self.settings.with_(
            hinge_stiffness_spread=g.reseed_spread * g.hinge_stiffness
        )
        return True

    def rounds_allowed(self) -> int:
        """The later rounds a run may make: ``reseeds``, or ``reseeds_timed`` with a time
        limit (which ends the last)."""
        g = self.settings.generation
        return g.reseeds if self.options.time_limit is None else g.reseeds_timed

    def conclude(self, stop: Stop, deadline: float | None) -> None:
        """The run ends with ``stop`` short of its target: its chain settled
        (:meth:`settle`) and its final design named (``deadline``); where later rounds
        began (:meth:`reseed`) and none reached the target, the lowest chain of theirs that
        ends with a design known to deploy below the first round's design (:attr:`best`) is
        taken back and shown to the callbacks (:meth:`publish`), its last solution the
        design; where there is none, the first round's chain and design (its stop too)."""
        first = self.first
        if first is None:
            self.settle(stop)
            self.name_final(stop, deadline)
            return
        self.keep_best(stop)
        if self.best is not None:  # a later round ended lower, with a design that deploys
            self.take_back(self.best)  # silently, then shown to the callbacks
            self.run.final_step = self.run.solutions[-1].step
            self.publish()
            return
        self.take_back(first)  # silently: the callbacks have had its chain all along
        self.run.final_step = first.final_step
        self.silent = False

    def keep_best(self, stop: Stop) -> None:
        """At the end of a later round (with ``stop`` at its last shape): keep its lowest chain
        as :attr:`best` where that chain's last solution is known to deploy (its path was
        traced to the flat state: no trace is needed to name it) and its DOF is below that
        of the design the run would end with so far (:meth:`kept_dof`). The round's lowest
        chain is the chain as it stands or the one backtracking left (:attr:`deepest`; a
        solution at the target without a clear gap, :meth:`keep_no_gap`, among them)."""
        run = self.run
        chains = [Chain(list(run.solutions), list(self.accepted), stop, run.stop_detail)]
        if self.deepest is not None:
            chains.append(self.deepest)
        for chain in chains:
            last = chain.solutions[-1]
            if known_to_deploy(last) and last.mechanism.dof < self.kept_dof():
                self.best = chain

    def kept_dof(self) -> int:
        """The DOF of the design a run in its later rounds would end with now: the later
        rounds' :attr:`best`, else the first round's named design (where it named none, any
        design known to deploy is lower: the first round's initial DOF plus one)."""
        if self.best is not None:
            return chain_dof(self.best.solutions)
        first = self.first
        assert first is not None  # a later round is under way
        if first.final_step is None:
            return first.solutions[0].mechanism.dof + 1
        return first.solutions[first.final_step].mechanism.dof

    def publish(self) -> None:
        """A later round's chain is the run's (it reached the target, or ended lowest,
        :meth:`conclude`): the callbacks see the first round's chain retracted (but its
        initial shape) and the round's accepted, in order. Where an
        interrupt comes as they do, the chain ends as far as they saw it (the design then
        the best known, :func:`rigidfold.generate.final.best_so_far`)."""
        if not self.silent:
            return
        first, run = self.first, self.run
        assert first is not None
        self.silent = False
        if self.on_retract and len(first.solutions) > 1:
            self.on_retract(run, tuple(reversed(first.solutions[1:])))
        shown = 1  # the initial shape, the chains' common start
        try:
            for solution in run.solutions[1:]:
                self.show(solution)
                shown += 1
        except KeyboardInterrupt:
            self.silent = True
            self.retract(keep=shown)
            self.silent = False
            run.final_step = None
            raise

    def show(self, solution: Solution) -> None:
        """The callback sees a solution kept (not in a :attr:`silent` round)."""
        if self.on_solution and not self.silent:
            self.on_solution(self.run, solution)

    def interrupted(self) -> None:
        """An interrupt (Ctrl-C, SIGTERM) stops the run: where a later round was under way,
        the run's chain is the first round's again and its design the one named at the
        first round's end, as the callbacks have them. Nothing is shown to the callbacks."""
        if self.silent and self.first is not None:
            self.take_back(self.first)
            self.run.final_step = self.first.final_step
            for rec in self.run.attempts:  # one accepted as the interrupt came: its round's
                if rec.search_round > 0 and rec.outcome is AttemptOutcome.ACCEPTED:
                    rec.outcome = AttemptOutcome.DEAD_END
        self.silent = False

    def name_final(self, stop: Stop, deadline: float | None) -> None:
        """Name the final design of the chain as it stands (the lowest-DOF solution that
        deploys; a stop by the time limit bisects the chain)."""
        deployable_final(
            self.run,
            self.options,
            self.settings,
            bisect=stop is Stop.TIME_LIMIT,
            deadline=deadline,
        )

    def new_chain(self, keep: int) -> None:
        """A new chain from the first ``keep`` solutions (:meth:`restart`, :meth:`unbatch`):
        the rest retracted, with their dead ends, the shapes being reduced, the chain's
        backtracking and rejected paths, and the look-ahead's memory of locks."""
        self.retract(keep=keep)
        self.dead = {step: fixes for step, fixes in self.dead.items() if step < keep}
        self.shapes.clear()
        self.backtracks = self.rejected = 0
        self.locked_before.clear()
        self.run.stop_detail = ""

    def sets_made(self) -> bool:
        """Whether the chain is batched (``GenerateOptions.batch`` "auto", before its first
        dead end) and a set of creases in it gave a solution: its shapes are then given up at
        ``batch_end_after`` rejected paths, and :meth:`unbatch` goes back to before the
        first set."""
        return (
            self.batch
            and self.options.batch == "auto"
            and any(rec.batch >= 2 for rec in self.accepted)
        )

    def unbatch(self, stop: Stop) -> bool:
        """With ``GenerateOptions.batch`` "auto", the first dead end of the batched chain
        (``stop``: its shape's candidates' paths do not reach the flat state, or none is
        left) ends the sets of creases: the solutions from the first set on are retracted
        and the chain goes on from the shape before it one crease per solve, unbounded, with
        the run's backtracking and restarts still to come: from there on the run is the one
        of ``batch`` "off" (the sets cost what their solves took). Where the sets dead-end
        (the waterbomb family: DOF 2 in a few solves, no DOF-1 child deploys) the paper's
        order is not lost; where they reach the target, the run took a few solves per
        dozen DOF. With ``Settings.generation.unbatch_peel`` the sets are peeled instead:
        this dead end and each later one while the chain holds a set retract only from its
        last set on (:attr:`peeling`), before backtracking does, until no set is left.
        Returns whether it retracted (no set accepted: the chain is already the paper's,
        and the run goes on as without sets)."""
        if (
            self.options.batch != "auto"
            or stop not in DEAD_ENDS
            or not (self.batch or self.peeling)
        ):
            return False
        self.batch = False
        sets = [k for k, rec in enumerate(self.accepted) if rec.batch >= 2]
        if not sets:
            self.peeling = False
            return False
        self.peeling = self.settings.generation.unbatch_peel
        self.keep_deepest(stop)
        self.new_chain(keep=sets[-1] if self.peeling else sets[0])
        # the ranking's draws as at the start, so that from the initial shape the chain is
        # the one of batch "off" (the sets' rankings drew from the same generator); a peel
        # from a later shape draws from the start too
        self.rng = np.random.default_rng(self.options.seed)
        return True

    def retract(self, keep: int | None = None) -> None:
        """Take back the last solution (``keep`` given: every solution after the first
        ``keep``): their attempts' outcome becomes DEAD_END; the callback sees them at once,
        the last first (not in a :attr:`silent` round)."""
        run = self.run
        keep = len(run.solutions) - 1 if keep is None else keep
        taken: list[Solution] = []
        while len(run.solutions) > keep:
            taken.append(run.solutions.pop())
            self.accepted.pop().outcome = AttemptOutcome.DEAD_END
            run.n_backtrack += 1
        if self.on_retract and taken and not self.silent:
            self.on_retract(run, tuple(taken))

    def settle(self, stop: Stop) -> None:
        """The round ends with ``stop`` at its last shape; where backtracking had left a
        chain that reached a lower DOF (:attr:`deepest`), that chain is taken back instead
        (:meth:`take_back`) with its stop."""
        run, deepest = self.run, self.deepest
        if deepest is None or chain_dof(deepest.solutions) >= chain_dof(run.solutions):
            run.stop = stop
            return
        self.take_back(deepest)

    def take_back(self, chain: Chain) -> None:
        """Make ``chain`` the run's again: the solutions found since it was left are
        retracted, its own accepted again (the callbacks see both), and the run's stop is
        its stop."""
        run = self.run
        common = 0
        for a, b in zip(chain.solutions, run.solutions, strict=False):
            if a is not b:
                break
            common += 1
        self.retract(keep=common)
        for solution, rec in zip(chain.solutions[common:], chain.accepted[common:], strict=True):
            run.n_backtrack -= rec.outcome is AttemptOutcome.DEAD_END  # no longer retracted
            rec.outcome = AttemptOutcome.ACCEPTED  # or a fallback without a clear gap, taken
            assert solution.step == len(run.solutions)  # the chains share what is before
            run.solutions.append(solution)
            self.accepted.append(rec)
            self.show(solution)
        run.stop, run.stop_detail = chain.stop, chain.detail


def with_fold_limit(case: Case, options: GenerateOptions, limit: float) -> Case:
    """The case of a run's restart at the fold limit ``limit`` (radians;
    :meth:`ChainControl.restart`): with the deployability check and no bound (12) of the user's
    (``Settings.design.rho_max``), (12) at ``limit``; otherwise ``case`` itself (no
    restart).

    Each fix flattens a crease, and the solve makes up for it by folding the creases left
    free further: on drawn patterns the chain ends with panels folded nearly onto each other
    (creases near 180 degrees), and the folding paths of such shapes turn back or collide
    before the flat state (docs/deployability.md, issue 40). Bound (12) keeps every solve
    away from that, and IPOPT's barrier on it favours the less folded of the shapes that
    solve (6)."""
    s = case.settings
    if not options.deploy_check or s.design.rho_max is not None:
        return case
    return replace(case, settings=s.with_(rho_max=limit))


def run_problem(case: Case, options: GenerateOptions) -> FormFindingProblem:
    """Problem (6) of ``case`` as a run with ``options`` solves it: IPOPT built at once where
    it is the run's solver, the projection first where the options ask it
    (``GenerateOptions.project_first``)."""
    return case.problem(
        build_ipopt=options.solver == SolverName.IPOPT, project_first=options.project_first
    )


def makes_sets(options: GenerateOptions) -> bool:
    """Whether a round's first chain fixes sets of several creases per solve
    (``GenerateOptions.batch`` "on", or "auto" with the deployability check)."""
    return options.batch == "on" or (options.batch == "auto" and options.deploy_check)


def attempt_time(rec: Attempt) -> float:
    """Seconds of one attempt: its selection, solve, analysis and trace."""
    return rec.selection_time + rec.solve_time + rec.analysis_time + rec.path_time


def within(solutions: list[Solution], limit: float) -> int:
    """How many solutions of a chain a restart at the fold limit ``limit`` (radians) keeps:
    those before the first whose free creases are not all within it (they solve problem (6)
    with bound (12) too), but not the chain's last (its candidates failed), and at least
    the initial shape."""
    keep = 1
    for k, solution in enumerate(solutions[1:-1], start=1):
        shape = solution.result.pattern
        free = ~shape.fixed & ~shape.is_boundary_edge
        if np.abs(shape.fold_angles[free]).max(initial=0.0) > limit:
            break
        keep = k + 1
    return keep


def chain_dof(solutions: list[Solution]) -> int:
    """The DOF of a chain's last solution."""
    return solutions[-1].mechanism.dof
