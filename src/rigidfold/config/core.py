"""Settings of form generation (Steps 2-8): the design parameters of problem (6), the
generation procedure, the solvers, geometric tolerances and the mechanism analysis."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigidfold.config.base import Group, setting
from rigidfold.errors import RigidfoldError

HESSIANS = ("closed-form", "casadi")
"""The Hessians of the Lagrangian IPOPT can use (``SolverSettings.ipopt_hessian``)."""
DOF_COUNTS = ("auto", "gap", "threshold")
"""How generation counts a shape's DOF (``MechanismSettings.dof_count``)."""
THETA_WIDEN = ("files", "all", "none")
"""Which crease patterns widen the sector-angle bounds to their own plan angles
(``DesignSettings.theta_widen``), the default first."""


@dataclass(frozen=True)
class DesignSettings(Group):
    """Design parameters of problem (6) (paper, Section 6.1)."""

    dz: float = setting(0.30, "Bound on |z_i - f(x_i, y_i)| in metres (paper: 0.30 m).")
    theta_min: float = setting(
        math.pi / 6, "Lower bound on every sector angle, radians (paper: pi/6)."
    )
    theta_max: float = setting(
        2 * math.pi / 3, "Upper bound on every sector angle, radians (paper: 2 pi/3)."
    )
    rho_max: float | None = setting(
        None, "Optional bound on |rho_j| of free creases, constraint (12), radians."
    )
    theta_widen: str = setting(
        "files",
        "Which crease patterns widen the sector-angle bounds to their own plan angles where "
        "the plan breaks them: 'files' (patterns read from FOLD or SVG files: their angles are "
        "their designer's, and a design's sector angles are those of its flat pattern), 'all' "
        "(the paper's patterns and rigidfold's grid: and mesh: triangulations too), 'none' "
        "(the bounds as given). The paper's patterns keep the paper's bounds under 'files' "
        "(:func:`rigidfold.generate.case.widened_angle_bounds`).",
    )
    theta_widen_room: float = setting(
        0.1,
        "Where a bound is widened, how far beyond the plan's own extreme angle it lies, as a "
        "fraction of the room: theta_min goes to (1 - this) x the smallest plan angle, "
        "theta_max to the largest plus this x (180 degrees - the largest), so that the flat "
        "pattern lies strictly inside.",
    )
    theta_widen_tol: float = setting(
        1e-3,
        "A plan angle breaks a sector-angle bound when it lies beyond it by more than this, "
        "radians (about 0.06 degrees): an angle drawn at the bound and rounded in the file "
        "(reschTriTessellation.svg: 29.996 degrees for 30) widens nothing.",
    )
    f_tol: float = setting(1e-7, "A solution of (6) is accepted when F <= f_tol (paper: 1e-7).")
    dz_bound_tol: float = setting(
        1e-3,
        "The report of a run flags a final design whose largest |z - target| is within this "
        "fraction of ``dz`` of the bound (the constraint is active: the design is as far from "
        "the target as ``dz`` allows); the fit check of a solution (``Stage.FIT``) fails "
        "where it is beyond the bound by more than this fraction.",
    )

    def __post_init__(self) -> None:
        if not (isinstance(self.dz, float | int) and math.isfinite(self.dz) and self.dz > 0):
            raise RigidfoldError(f"dz must be a positive number of metres, got {self.dz!r}")
        if not (0 < self.theta_min < self.theta_max < math.pi):
            raise RigidfoldError(
                "sector-angle bounds must satisfy 0 < theta_min < theta_max < 180 degrees, got "
                f"theta_min={math.degrees(self.theta_min):g}, "
                f"theta_max={math.degrees(self.theta_max):g} degrees"
            )
        if self.rho_max is not None and not (0 < self.rho_max < math.pi):
            raise RigidfoldError(
                f"rho_max must lie in (0, 180) degrees, got {math.degrees(self.rho_max):g}"
            )
        if not self.f_tol > 0:
            raise RigidfoldError(f"f_tol must be positive, got {self.f_tol!r}")
        self._choice("theta_widen", THETA_WIDEN)
        self._positive("theta_widen_room")
        self._fraction("theta_widen_room", below_one=True)
        self._non_negative("theta_widen_tol")


@dataclass(frozen=True)
class GenerationSettings(Group):
    """The generation procedure (Steps 4-7): the fictitious hinge stiffnesses of the
    criteria, lock prediction, the look-ahead and the deployability check."""

    retry_zero_dof: bool = setting(
        False,
        "``False``, Step 5 of the paper: a solution of (6) whose mechanism has DOF 0 ends "
        "generation (it goes to Step 8; not counted in N_reduce, N_lock or N_exceed). "
        "``True`` (``--retry-zero-dof``): while the target DOF is >= 1, count it as a lock and "
        "try the next candidate (Step 7) instead, which reaches the target more often at the "
        "price of more solves.",
    )
    clear_gap: bool = setting(
        True,
        "With the deployability check: a solution at the target DOF whose DOF has no clear "
        "gap (:class:`rigidfold.mechanism.margin.DofMargin`: near-mechanisms, or the "
        "search's count and the singular values' differ) is a rejected candidate "
        "(``no_gap``): the search goes on for one with a clear gap and delivers that one "
        "only where it finds none (the run then falls short, its verdict says so first). "
        "``False`` (``--accept-no-gap``): "
        "such a solution ends the run, as before session 24.",
    )
    hinge_stiffness: float = setting(
        1e-3, "Mean of the fictitious hinge stiffnesses K_j, N m (Section 6.1)."
    )
    hinge_stiffness_spread: float = setting(
        0.5e-6, "K_j are uniform in ``hinge_stiffness`` +/- this, N m (Section 6.1)."
    )
    lock_prediction_tol: float = setting(
        1e-4,
        "After multiplying K_j by 1e14, a hinge whose rotations outside the stiffest mode fall "
        "below this fraction of its rotations before is predicted locked (Section 4.2).",
    )
    lookahead_tol: float = setting(
        1e-7,
        "Look-ahead (``generate(..., lookahead=True)``, :mod:`rigidfold.selection.lookahead`): "
        "fixing a candidate is predicted to lock a folded free crease when the crease keeps, "
        "in the first-order mechanisms left after the fix, rotations of norm at most this "
        "times the largest any free crease keeps: the ``lock_tol`` test applied before the "
        "solve. At ``lock_tol`` (the default) the forecast is the analysis of the fixed shape "
        "at the same geometry; a larger value also skips candidates that leave a crease "
        "nearly still.",
    )
    lookahead_carry_angle: float = setting(
        math.radians(2.0),
        "Look-ahead, once every candidate not forecast to lock has failed: a candidate whose "
        "forecast locks only creases that its fix carries to within this angle of flat "
        "(radians; first order: their fold angles plus their rotations along the smallest "
        "mechanism motion that flattens the candidate) is fixed together with them, as one "
        "group (a degree-4 vertex closing flat). Fixed creases are forced flat, so the group "
        "asks only what fixing the candidate alone would do, less the lock.",
    )
    deploy_check_max_dof: int = setting(
        1,
        "The deployability check runs on accepted solutions of at most this DOF or the target "
        "DOF, whichever is larger (0: on every solution). A run that does not reach the "
        "target names the lowest-DOF solution that deploys as its final design.",
    )
    deploy_max_candidates: int = setting(
        30,
        "Step 7 gives up on a shape once this many of its candidates gave solutions whose "
        "folding paths do not reach the flat state (``Stop.NO_DEPLOYABLE``; 0: it tries them "
        "all): every candidate costs a solve and a trace, and a shape whose first candidates "
        "all fail rarely has a deployable one further down the ranking. In a chain bounded "
        "by a fold limit (``fold_limits``), a shape is also given up after this many failed "
        "candidates of any kind: under the bound, solves that do not converge (N_exceed) "
        "each cost a full solve, and the paper's Step 7 would try every candidate.",
    )
    backtrack_max: int = setting(
        3,
        "With the deployability check: retractions a chain may make (the run's first chain, "
        "and each restart's under ``fold_limits``; 0: none, the paper's Step 7). When every "
        "candidate of a shape after the first fails (``Stop.NO_DEPLOYABLE`` or "
        "``Stop.NO_CANDIDATE``), the solution of that shape is retracted (its attempt's "
        "outcome becomes ``dead_end``) and generation resumes at the shape before it with that "
        "shape's remaining candidates, in their ranked order. Without the check it does "
        "nothing.",
    )

    idle_last: bool = setting(
        True,
        "With the deployability check and the look-ahead: a candidate whose creases do not "
        "turn in any mechanism of the shape (their rows of H_phi still in every mode, "
        ":func:`rigidfold.selection.lock_forecast`) removes no DOF when fixed, and is put off "
        "like one forecast to lock (tried once every other candidate has failed). The "
        "criteria rank such creases first (fixing a crease that does not move costs no "
        "strain energy): on a 25 x 13 barrel vault the search fixed flat creases one per "
        "solve, 528 solves for the first 59 DOF removed, DOF 34 kept for 100 solves in a "
        "row (docs/broad_set.md, session 41). False: the criterion's order.",
    )
    idle_gain: bool = setting(
        True,
        "With ``idle_last``: a candidate put off as idle (forecast to remove no DOF) is kept "
        "only where its solution has fewer DOF than its shape. Such a candidate is tried once "
        "every other candidate of the shape failed; a solution that keeps the count is the "
        "same shape with a crease that does not turn fixed (no solver iteration moves it), "
        "and its ranked candidates are the shape's own, which all failed: keeping it replays "
        "them. On ``paper/2/bezier:1013`` with ``unbatch_peel`` a chain kept 30 such "
        "solutions at DOF 3 in a row, each followed by the same 16 failed solves: 164.3 s, "
        "and 25.1 s with ``idle_gain`` (docs/broad_set.md, session 44). False: kept unless "
        "the count rose.",
    )
    rewind: bool = setting(
        False,
        "With the deployability check: at a dead end of a shape whose children get the check "
        "(its DOF-1 candidates all failed), the shape's own folding path is traced; where it "
        "does not reach the flat state, the chain lost its deployability above it, and "
        "backtracking (or the first chain's restart) goes back to the lowest solution of the "
        "chain whose path deploys (probed from the chain's end back in doubling steps, then "
        "bisected: about 2 log2(d) traces for a shape d solutions above the dead end, "
        ":func:`rigidfold.generate.final.lowest_deploying`) instead of to the shape before: "
        "one retraction of the budget (``backtrack_max``). The first chain gives up such a "
        "shape at ``restart_after`` rejected paths whatever its candidates cost. False (the "
        "default): backtracking retracts one solution at a time. On the broad set the rewind "
        "passed the same cases as without it and its median run took 8.1 s against 6.7 s "
        "(docs/broad_set.md, session 41): a DOF-2 shape whose children all fail often "
        "deploys itself, and one that does not costs its traces.",
    )

    second_order: bool = setting(
        True,
        "With the deployability check: a solution whose folding path does not reach the flat "
        "state is tested at second order (:func:`rigidfold.mechanism.second_order."
        "obstruction`); a second-order rigid one is counted in N_rigid, not N_path. At a "
        "shape whose children are checked, candidates forecast to leave a second-order rigid "
        "child (:class:`~rigidfold.mechanism.second_order.ChildForecast`) are tried last "
        "(with the look-ahead, put off like those forecast to lock).",
    )
    second_order_first: bool = setting(
        True,
        "With ``second_order``: a candidate's solution is tested at second order before its "
        "path is traced, and one found second-order rigid is rejected (N_rigid) without the "
        "trace: it cannot fold at all, and its trace costs several times the test (the "
        "tracer halves its first step down to ``path_min_step`` before it stops short; "
        "docs/deployability.md, session 33). False: the test only after a path that does "
        "not reach the flat state.",
    )
    rigid_confirmations: int = setting(
        3,
        "With ``second_order``: a shape whose own stress form "
        "is definite on its flexes (every child forecast second-order rigid) is given up "
        "(``Stop.NO_DEPLOYABLE``, then backtracking) once this many of its candidates in a "
        "row were solved and found second-order rigid, instead of after "
        "``deploy_max_candidates`` (0: only that bound).",
    )
    fold_limits: tuple[float, ...] = setting(
        (math.radians(120.0), math.radians(90.0)),
        "With the deployability check (and no ``design.rho_max`` of the user's): where the "
        "run's chain dead-ends, it starts again from the initial shape with bound (12) at "
        "the next of these angles, radians, on every solve: each fix flattens a crease and "
        "the solve folds the creases left free further, and the paths of shapes with creases "
        "near 180 degrees turn back or collide before the flat state (issue 40; "
        "docs/deployability.md). The first chain is given up after ``restart_after`` "
        "rejected paths at one shape; a bounded one once its backtracking is spent or, where "
        "a further limit is left, once ``deploy_max_candidates`` of its candidates' paths "
        "were rejected, at whatever shapes. (): no restart.",
    )
    restart_after: int = setting(
        5,
        "With ``fold_limits``: the candidates of one shape whose paths do not reach the "
        "flat state (N_path, N_rigid) after which the first chain is given up and the run "
        "starts again with the first fold limit (``deploy_max_candidates`` after that).",
    )
    reseeds: int = setting(
        0,
        "With the deployability check: where every chain of a run without a time limit is "
        "spent (backtracking and the fold limits' restarts) short of the target DOF, the "
        "search starts again from the initial shape up to this many times, each round with a "
        "seed of its own and the wider spread ``reseed_spread`` for the fictitious hinge "
        "stiffnesses K_j of the criteria, whatever else as in the first round (the sets of "
        "creases, backtracking, the fold limits). The first round's final design is named "
        "when it ends; a later round is kept where it reaches the target, or where it ends "
        "with a design known to deploy of lower DOF than the first round's and the later "
        "rounds' before it (a DOF-1 design without a clear gap against the first round's "
        "DOF 2, say); otherwise the run ends as its first round did. The verdicts of the "
        "shapes rejected before are kept (``same_shape_tol``); while a later round goes, "
        "the run directory keeps the first round's files and design (a run stopped by "
        "Ctrl-C ends with them). 0 (the default): one round, as before session 34: without "
        "a time limit, rounds could take this many times a round's time.",
    )
    child_max_iter: int = setting(
        300,
        "With the deployability check: the solver's iteration limit of a child's solve "
        "(from its parent's shape, one crease or one set more fixed; the first solve, from "
        "the target surface, keeps ``Settings.solver.ipopt_max_iter``). On the 25 drawn and "
        "roof cases, of the 3397 child solves that converged none took more than 295 "
        "iterations, the projections' steps and IPOPT's together (99 % within 155), and the "
        "77 that did not took a quarter of the runs' time, six of them 7.6-16.8 s at IPOPT's "
        "limit (docs/broad_set.md, session 45); the limit bounds IPOPT's own iterations. "
        "Without the check (the "
        "paper's Step 5, its study) every solve keeps the settings' limit.",
    )
    child_stall: int = setting(
        60,
        "With the deployability check: a child's solve also ends where the least F of its "
        "feasible iterates has not halved in this many iterations while above ``f_tol`` "
        "(Status.STALLED, counted in N_exceed): it sits at a local minimum of F, and the "
        "fixed creases cannot be flattened within dz from the parent's shape "
        "(:func:`rigidfold.optimize.solver.stalled`). On the 25 drawn and roof cases and 37 "
        "of the broad set's sample no child solve that converged went 60 iterations above "
        "F_tol without halving that F, and the 68 failing solves of the drawn cases that it "
        "ends ran 174.5 s of the runs' 1585 s after that point "
        "(``benchmarks/stall_traces.py``, docs/broad_set.md, session 46).",
    )
    reseeds_timed: int = setting(
        30,
        "As ``reseeds``, for a run with a time limit, which ends the last round: a run that "
        "falls short spends its time on other chains (rounds of 10-70 s on the drawn "
        "patterns, docs/broad_set.md, session 34) instead of ending early.",
    )
    exceed_share: float = setting(
        0.5,
        "The verdict on a run that falls short says that its pattern reaches the surface only "
        "with more DOF where at least this share of the solves after the first found no shape "
        "within dz (N_exceed): Origami Simulator's single vertex on the dome, 47 of 58 "
        "(docs/broad_set.md, session 35). It decides what the verdict says, not the run.",
    )
    reseed_spread: float = setting(
        0.1,
        "With ``reseeds``: the K_j of a later round are uniform in ``hinge_stiffness`` times "
        "1 +/- this. The paper's spread (``hinge_stiffness_spread``, 5e-4 of the mean) only "
        "breaks ties between creases of equal score, and another seed of it mostly finds the "
        "same chain again (waterbomb and Resch's triangles on the dome: the same 147 and "
        "136-139 solves with seeds 1 and 2, docs/broad_set.md, session 34); a spread of 10 % "
        "weighs the creases' rotations in each mode otherwise, and the rankings differ where "
        "the scores are close: another chain, still ranked by the criterion.",
    )
    batch_first: int = setting(
        8,
        "With several creases per solve (``GenerateOptions.batch``): the size of the first "
        "set of creases fixed together; a set that solves doubles the next one (up to "
        "``batch_max``), one that fails is tried again with half of its creases, down to two, "
        "then the shape goes on one crease at a time.",
    )
    batch_max: int = setting(
        32, "With ``GenerateOptions.batch``: the most creases fixed together in one solve."
    )
    batch_single_dof: int = setting(
        10,
        "With ``GenerateOptions.batch``: within this many DOF of the target (and wherever the "
        "deployability check or the second-order forecast applies) one crease is fixed per "
        "solve, as in the paper; a set never takes a shape closer to the target. The DOF "
        "here are the exact ones (at ``mechanism_rank_tol``), not those counted with the gap: "
        "a set spends exact mechanisms first, and on a 41 x 41 grid on the dome, whose "
        "near-mechanisms come and go, a set of 19 sized by the count (30 DOF, 18 exact) left "
        "3 exact and 12 near (docs/broad_set.md, session 36).",
    )
    batch_end_after: int = setting(
        2,
        'With ``GenerateOptions.batch`` "auto", once a set of creases gave a solution in the '
        "chain: the candidates of one shape whose paths do not reach the flat state after "
        "which the sets end and the chain goes on one crease per solve from the shape before "
        "the first set (or sooner, where ``restart_after`` is smaller; without a set, "
        "``restart_after``): where the sets reach a shape none of "
        "whose children deploys (the waterbomb family), five rejected paths there cost tens "
        "of seconds of traces; one gave up a shape whose second child deploys "
        "(docs/broad_set.md, session 32).",
    )
    unbatch_peel: bool = setting(
        False,
        'With ``GenerateOptions.batch`` "auto": at the batched chain\'s first dead end the '
        "last set of creases is retracted (not every set from the first), and the chain goes "
        "on one crease per solve from the shape before it; each later dead end while the "
        "chain still holds a set retracts its last one, before backtracking, until none is "
        "left. False: the first dead end goes back to before the first set (the chain of "
        '``batch`` "off" from there). Measured in session 44 (docs/broad_set.md): on the '
        "broad set's 46 cases 34 pass against 32, none lost, but on the 25 drawn and roof "
        "cases 18 against 19 (lost: the HP's Miura-ori and the dome's Resch triangles; won: "
        "the HP's double-faced wedge); not adopted.",
    )
    batch_tol: float = setting(
        1e-3,
        "With ``GenerateOptions.batch``: a candidate joins the set when each of its creases' "
        "rotation rows (restricted to the shape's mechanisms) keeps at least this share of "
        "its norm outside the span of the set's rows, and every folded free crease outside "
        "the set keeps at least this share of its own rotations (no first-order lock; "
        ":mod:`rigidfold.selection.batch`).",
    )
    near_tries: int = setting(
        3,
        "With the deployability check and the gap count: at a shape with near-mechanisms "
        "(fewer exact mechanisms than its DOF), this many candidates that turn in them but "
        "hardly in the exact ones are tried first, one per solve "
        "(:mod:`rigidfold.selection.near`; 0: none).",
    )
    near_max: int = setting(
        8,
        "With ``near_tries``: near-mechanisms first only at shapes with at most this many "
        "(the DOF counted with the gap less the exact one). More is a continuum of soft "
        "modes, not a few isolated ones: on a 41 x 41 grid on the dome the singular values "
        "run evenly from 5e-8 to 1e-5 of the largest (68 near-mechanisms at the first "
        "shape), single fixes move the count up as often as down, and near-mechanisms first "
        "did not finish in 10 min (docs/broad_set.md, session 27).",
    )
    near_rigid_backtrack: bool = setting(
        True,
        "With ``near_tries``: a shape after the first whose DOF are all near-mechanisms "
        "(none at the rank threshold itself: it cannot fold, and its children, solved from "
        "it, rarely can) is a dead end: backtracked at once, its candidates untried "
        "(docs/broad_set.md, session 27: 26/40 either way on the broad set; a case that "
        "always failed passes, one that passes or fails by seconds at the limit failed).",
    )
    reuse_max_dof: int = setting(
        20,
        "A candidate met again at the same shape (bitwise the same coordinates and fixed "
        "creases, under the same fold limit) repeats the earlier attempt's solve, analysis "
        "and check instead of computing them again (``Attempt.solve_from``; "
        ":mod:`rigidfold.generate.memo`); the solutions of more DOF than this are not kept "
        "(their mechanisms fill memory, their solves are quick). 0: every attempt is "
        "computed.",
    )
    same_shape_tol: float = setting(
        1e-6,
        "With the deployability check: a candidate's solution whose shape lies within this "
        "(the largest vertex distance, in mean edge lengths) of an earlier one with the same "
        "fixed creases and DOF whose path did not reach the flat state is rejected as that "
        "one was, without tracing its path again (``Attempt.path_from``). A chain started "
        "again under a fold limit that its shapes never reach, or a shape come back to after "
        "backtracking, meets the same candidates again; their traces (seconds each, the "
        "solve a fraction of that) are not repeated. 0: every path is traced.",
    )
    near_gain: bool = setting(
        False,
        "With ``near_tries``: a near-mechanism fix is kept only when its solution has fewer "
        "DOF than its shape, and after a shape whose near fixes all gained nothing the next "
        "1, 2, 4, ... shapes skip them. False: kept unless the count rose. Measured on the "
        "broad set (docs/broad_set.md, session 43): the 25 x 13 vault's solves per DOF "
        "above DOF 10 fall from 1.36 to 0.81, but a same-count fix is sometimes the step to a "
        "chain that deploys (the L-shaped hall: 5.7 s and 19 solves without, 50.2 s and 292 "
        "with), and one case that passed fails; not adopted.",
    )
    near_ratio: float = setting(
        1e-2,
        "With ``near_tries``: a candidate is tried first when its rotation in the shape's "
        "exact mechanisms is below this share of its rotation in all those counted.",
    )
    time_limit_grace: float = setting(
        0.025,
        "With a time limit T (``--time-limit``): naming the final design of a run stopped by "
        "it (the path traces that search its chain, each with this deadline) ends by T + "
        "max(``time_limit_grace_min``, this times T). Half of the overrun a run may have "
        "(max(10 s, 5 % of T)); the checks and exports of the final design have the rest.",
    )
    time_limit_grace_min: float = setting(
        5.0, "Seconds: the least of the grace after a time limit (``time_limit_grace``)."
    )
    time_limit_reserve: float = setting(
        3.0,
        "Seconds a run with a time limit keeps for what follows the final design's path (its "
        "DOF margin, checks, exports, summary and report), plus "
        "``time_limit_reserve_per_vertex`` per vertex, at most ``time_limit_reserve_share`` "
        "of T: the search stops that much (less half a grace) before T "
        "(:mod:`rigidfold.generate.budget`).",
    )
    time_limit_reserve_per_vertex: float = setting(
        0.02,
        "Seconds per vertex of the reserve for the final design's stages "
        "(``time_limit_reserve``): 17 s on a 684-vertex drawn pattern, measured "
        "(docs/broad_set.md, Session 23).",
    )
    time_limit_load_max: float = setting(
        3.0,
        "The most that the machine's load (wall time over the process's CPU time during the "
        "run) may stretch the reserve for the final design's stages "
        "(``time_limit_reserve``); at most half of T is kept whatever the load.",
    )
    time_limit_reserve_share: float = setting(
        0.25,
        "The most of a time limit T that the reserve for the final design's stages "
        "(``time_limit_reserve``) may take: the search keeps at least the rest.",
    )
    summary_interval: float = setting(
        2.0,
        "Seconds between writes of a run's summary.json after attempts that are rejected "
        "(its log, ``log.jsonl``, gets every attempt as it ends): each solution, each "
        "retraction by backtracking, the end and an interrupt write it every time, so its "
        "counters are exact once the run has ended. 0: after every attempt.",
    )

    def __post_init__(self) -> None:
        if not (isinstance(self.backtrack_max, int) and self.backtrack_max >= 0):
            raise RigidfoldError(
                f"backtrack_max must be a whole number >= 0, got {self.backtrack_max!r}"
            )
        for limit in self.fold_limits:
            if not (0 < limit < math.pi):
                raise RigidfoldError(
                    f"a fold limit must lie in (0, 180) degrees, got {math.degrees(limit):g}"
                )
        if not (isinstance(self.restart_after, int) and self.restart_after >= 1):
            raise RigidfoldError(
                f"restart_after must be a whole number >= 1, got {self.restart_after!r}"
            )
        if not (isinstance(self.batch_end_after, int) and self.batch_end_after >= 1):
            raise RigidfoldError(
                f"batch_end_after must be a whole number >= 1, got {self.batch_end_after!r}"
            )
        self._non_negative(
            "summary_interval",
            "time_limit_grace",
            "time_limit_grace_min",
            "time_limit_reserve",
            "time_limit_reserve_per_vertex",
            "batch_tol",
            "near_ratio",
            "same_shape_tol",
        )
        self._fraction("reseed_spread", below_one=True)
        self._fraction("exceed_share")
        if not self.time_limit_load_max >= 1:
            raise RigidfoldError(
                f"time_limit_load_max must be at least 1, got {self.time_limit_load_max!r}"
            )
        if not 0 <= self.time_limit_reserve_share < 1:
            raise RigidfoldError(
                "time_limit_reserve_share must lie in [0, 1), got "
                f"{self.time_limit_reserve_share!r}"
            )
        self._integer(
            near_tries=0,
            near_max=0,
            reseeds=0,
            reseeds_timed=0,
            reuse_max_dof=0,
            child_max_iter=1,
            child_stall=1,
        )
        self._boolean(
            "retry_zero_dof",
            "clear_gap",
            "second_order",
            "near_rigid_backtrack",
            "near_gain",
            "idle_gain",
            "unbatch_peel",
            "rewind",
            "idle_last",
        )
        for name in ("batch_first", "batch_max", "batch_single_dof"):
            value = getattr(self, name)
            if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
                raise RigidfoldError(f"{name} must be a whole number >= 1, got {value!r}")


@dataclass(frozen=True)
class SolverSettings(Group):
    """The solvers of problem (6) (IPOPT, the projection onto F = 0, SciPy SLSQP), of the
    development diagram's problem (13), and the elimination of constraints (7)-(9)."""

    constraint_tol: float = setting(
        1e-8, "Largest accepted violation of any constraint of (6) (metres or radians)."
    )
    ipopt_tol: float = setting(1e-8, "IPOPT's convergence tolerance.")
    ipopt_max_iter: int = setting(500, "IPOPT's iteration limit.")
    ipopt_mu_strategy: str = setting("adaptive", "IPOPT's barrier-parameter strategy.")
    ipopt_hessian: str = setting(
        "closed-form",
        'IPOPT\'s Hessian of the Lagrangian: "closed-form" (element Hessians assembled with '
        'NumPy, ``rigidfold.optimize.hessian``) or "casadi" (CasADi\'s symbolic Hessian, the '
        "reference it is tested against). Both are exact; they differ by round-off.",
    )
    ipopt_stop_f: float = setting(
        1e-9,
        "F at which IPOPT hands over to the projection on patterns of ``projection_vertices`` "
        "or more (far below ``f_tol``, so that the projection starts near a zero of F); a "
        "projection that stops at a feasible point this close to F = 0 is taken without IPOPT.",
    )
    projection_vertices: int = setting(
        200,
        "From this many vertices on, the IPOPT solver of (6) first tries the projection onto "
        "F = 0 (:mod:`rigidfold.optimize.projection`) from the start; when that does not "
        "converge, IPOPT runs and stops at the first feasible iterate with F <= "
        "``ipopt_stop_f``, which the projection then finishes "
        "(:mod:`rigidfold.optimize.large`). Smaller patterns (the paper's, up to 121 "
        "vertices) run IPOPT alone.",
    )
    projection_tol: float = setting(1e-14, "The projection converges at F <= this.")
    projection_max_iter: int = setting(60, "The projection stops after this many factorisations.")
    projection_damping: float = setting(
        1e-3,
        "The projection starts with the damping this times |r| times the largest diagonal "
        "entry of J J^T.",
    )
    projection_margin: float = setting(
        1e-5,
        "How far inside its bound the projection holds a constraint of (6) that blocked one "
        "of its steps (radians for sector angles, metres for dz, the cosine for (12)).",
    )
    slsqp_ftol: float = setting(1e-12, "SciPy SLSQP's stopping tolerance.")
    slsqp_max_iter: int = setting(1000, "SciPy SLSQP's iteration limit.")
    polish_tol: float = setting(
        1e-26,
        "Before the deployability check, an accepted solution is projected onto F = 0 to this "
        "F (:meth:`rigidfold.optimize.FormFindingProblem.polish`): developable to round-off.",
    )
    polish_stall_steps: int = setting(
        5,
        "The polish stops (stalled) once its last this many accepted steps together lowered F "
        "by less than half: the Gauss-Newton model then predicts a decrease of a few per cent "
        "a step (the residual lies in directions the damping all but cuts off, or against a "
        "held bound), and the factorisations up to ``projection_max_iter`` would end near "
        "the same F. 0: never.",
    )
    develop_tol: float = setting(
        1e-12,
        "IPOPT tolerance of problem (13) (the development diagram, Step 8); tighter than "
        "``ipopt_tol`` so that a flat pattern develops onto itself to about 1e-10.",
    )
    linear_rank_tol: float = setting(
        1e-10,
        "Relative threshold of the rank-revealing QR that eliminates constraints (7)-(9).",
    )
    map_prune_tol: float = setting(
        1e-13, "Entries of the variable map below this magnitude are dropped as round-off."
    )

    def __post_init__(self) -> None:
        self._positive("projection_tol", "projection_damping", "projection_margin", "ipopt_stop_f")
        self._integer(projection_vertices=3, projection_max_iter=1, polish_stall_steps=0)
        self._choice("ipopt_hessian", HESSIANS)


@dataclass(frozen=True)
class GeometrySettings(Group):
    """Geometric tolerances of crease patterns, their symmetry and development diagrams."""

    degenerate_area: float = setting(
        1e-10,
        "A triangle whose area is below this times (its longest edge)**2 is degenerate.",
    )
    corner_angle: float = setting(
        math.radians(1.0),
        "A boundary vertex is a corner when the boundary turns there by more than this (radians).",
    )
    flat_angle: float = setting(
        1e-6, 'A free crease with |rho| below this (radians) is flat ("F" in FOLD files).'
    )
    symmetry_match_tol: float = setting(
        1e-6, "Distance (metres) within which a mirrored vertex must land on another vertex."
    )
    overlap_area_tol: float = setting(
        1e-9,
        "Two facets of a development diagram overlap when their intersection is larger than "
        "this fraction of the smaller one's area.",
    )
    triangulation_area_tol: float = setting(
        1e-12,
        "Triangulation of the polygon faces of FOLD and SVG files: a polygon is refused as "
        "degenerate when a triangle of it has a doubled signed area below this times the "
        "squared size of the polygon (the larger side of its bounding box, in its plane).",
    )
    plan_area_tol: float = setting(
        1e-6,
        "A sheet whose signed area in plan (its faces projected onto the xy plane) is within "
        "this fraction of its surface area of zero has no plan (a y-up file, a vertical "
        "sheet, a closed box, a flat-folded state): refused, since rigidfold needs z up. The "
        "same test refuses the triangle mesh of a target surface (``MeshSurface``).",
    )


@dataclass(frozen=True)
class MechanismSettings(Group):
    """The mechanism analysis (Eq. 16, Section 4): ranks, the sparse method for large
    patterns, and locks."""

    rank_tol: float = setting(
        1e-9,
        "Singular values below this times the largest one count as zero (rank of S, Eq. 16); "
        "in the kinematic and sparse analyses, the diagonal of the pivoted QR, and the Ritz "
        "values, below this times the largest row norm of the constraint matrix (sqrt 2, the "
        "row of an edge's length).",
        flat="mechanism_rank_tol",
    )
    sparse_analysis_vertices: int = setting(
        200,
        "``analyze`` (and so ``generate``) takes the sparse method "
        "(:mod:`rigidfold.mechanism.sparse`) for patterns with at least this many vertices "
        "and the dense kinematic one below: the paper's patterns (up to 121 vertices) keep "
        "the dense reference, and their results to the last digit.",
    )
    sparse_shift: float = setting(
        1e-14,
        "delta of the sparse analysis's filter ``(C^T C + delta I)^-1``: directions of "
        "singular value s with s^2 << delta pass it like the kernel (all those within reach "
        "of ``mechanism_rank_tol``), the others are damped by about delta / s^2 per solve. Ten "
        "times the round-off of C^T C (about 1e-15); small enough that two solves damp every "
        "direction with s > 1000 sqrt(delta) = 1e-4 below 1e-12 (a solved 31 x 31 grid has "
        "some fifteen singular values between 1e-6 and 3e-4 beside its kernel).",
    )
    sparse_oversampling: int = setting(
        12,
        "Columns of the sparse analysis's subspace beyond the expected DOF; the subspace "
        "doubles while fewer than half of them are damped below 1e-12 of the kernel's share.",
    )
    sparse_iterations: int = setting(
        2,
        "Solves with the filter per subspace: each multiplies the share of a direction of "
        "singular value s by about delta / s^2; two leave the modes less than about 1e-12 of "
        "every direction with s > 1000 sqrt(delta), far below ``lock_tol``.",
    )
    lock_tol: float = setting(
        1e-7,
        "A free crease is locked when the norm of its rotations over all modes is below this "
        "times the largest such norm (and its triangles are not coplanar).",
    )
    second_order_vertices: int = setting(
        800,
        "The second-order test of a shape in generation (:mod:`rigidfold.mechanism."
        "second_order`; dense below ``mechanism_sparse_analysis_vertices`` vertices, sparse "
        "from there on) and the dense recoveries of a stalled path trace "
        "(``path_reduce``, ``path_escape_tol``) are made up to this many vertices: above, "
        "the test is not made (the failed path stays in N_path).",
    )
    dof_count: str = setting(
        "auto",
        "How generation counts a shape's DOF. \"threshold\": the paper's, the singular values "
        'of the constraints below ``mechanism_rank_tol`` times the largest. "gap": those '
        "below ``dof_gap`` times that (1e-6 of the largest by default): a near-mechanism "
        "within the gap of the threshold is a mechanism of the built design (its stiffness "
        "goes with sigma^2 times the panels' bar stiffness: below 1e-12 of it, far below what "
        "a panel's weight asks; docs/deployability.md), so it is counted as a DOF and the "
        'search goes on until the DOF has a clear gap. "auto": "gap" with the '
        "deployability check, the paper's \"threshold\" with the paper's Step 5 (the study).",
    )
    dof_gap: float = setting(
        1e3,
        "The DOF of a design is *clear* when the smallest singular value counted as non-zero "
        "is at least this many times the rank threshold (``mechanism_rank_tol``) and the "
        "largest counted as zero at most 1/this of it; otherwise the verdict and the report "
        "say how many singular values lie near the threshold (near-mechanisms: very soft "
        "modes of the built design).",
    )

    def __post_init__(self) -> None:
        self._choice("dof_count", DOF_COUNTS)
        if not 0 < self.sparse_shift < 1:
            raise RigidfoldError(f"sparse_shift must lie in (0, 1), got {self.sparse_shift!r}")
        self._integer(sparse_analysis_vertices=3, sparse_oversampling=2, sparse_iterations=1)
