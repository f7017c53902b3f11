"""Later rounds of the search (``Settings.generation.reseeds``): where every chain of a round
is spent without a design at the target DOF, the search starts again from the initial shape
with other seeds for the ranking. The first round is the search of one round, attempt for
attempt; every later round begins at the initial shape; a later round is kept where it
reaches the target or ends lower with a design known to deploy, otherwise the run ends as
its first round did; without the
deployability check there is one round (the paper's Step 7).

The case: pattern 1 on Bezier seed 102 (S-hat, look-ahead, one crease per solve) with
``deploy_max_candidates = 1``, no backtracking and no fold limit, so that a round ends at the
first path that does not reach the flat state (seconds).
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import main_code, paper_generate
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Attempt, AttemptOutcome, GenerateOptions, Stop, generate
from rigidfold.generate.specs import case_from_specs

SEED = 102
# the paper's solver, IPOPT alone, with which this case's first round falls short
OPTIONS = GenerateOptions(
    criterion="shat", seed=SEED, lookahead=True, deform=False, batch="off", projection="large"
)
ROUNDS = 2


def _case(reseeds: int):
    settings = DEFAULTS.with_(
        deploy_max_candidates=1, backtrack_max=0, fold_limits=(), reseeds=reseeds
    )
    return case_from_specs("bezier", "1", seed=SEED, settings=settings)


def _run(reseeds: int):
    """The run, and for each round the number of solutions when its first attempt ended
    (before that attempt's own solution is kept)."""
    starts: dict[int, int] = {}

    def on_attempt(run, attempt):
        starts.setdefault(attempt.search_round, len(run.solutions))

    return generate(_case(reseeds), OPTIONS, on_attempt=on_attempt), starts


@pytest.fixture(scope="module")
def one_round():
    return _run(0)


@pytest.fixture(scope="module")
def rounds():
    return _run(ROUNDS)


def test_the_first_round_is_the_search_of_one_round(one_round, rounds):
    plain, _ = one_round
    run, _ = rounds
    assert plain.stop is Stop.NO_DEPLOYABLE  # one round is not enough here
    assert {a.search_round for a in plain.attempts} == {0}
    first = [a for a in run.attempts if a.search_round == 0]
    assert len(first) == len(plain.attempts)
    for a, b in zip(first, plain.attempts, strict=True):
        assert a.fixed_added == b.fixed_added and a.F == b.F
        assert a.outcome == b.outcome or AttemptOutcome.DEAD_END in (a.outcome, b.outcome)


def test_every_later_round_starts_again_from_the_initial_shape(rounds):
    run, starts = rounds
    tags = [a.search_round for a in run.attempts]
    assert tags == sorted(tags)  # the rounds follow each other
    assert set(tags) == set(range(max(tags) + 1))
    assert max(tags) == ROUNDS or run.stop is Stop.TARGET_REACHED
    # the initial solve (round 0's first attempt) has no solution before it; each later
    # round's first attempt reduces the initial shape, the only solution kept
    assert starts[0] == 0
    assert all(starts[k] == 1 for k in range(1, max(tags) + 1))


def _lowest_deploying(run) -> dict[int, int]:
    """For each round, the lowest DOF of its solutions whose path reached the flat state
    (kept, retracted or kept aside without a clear gap)."""
    solutions = (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END, AttemptOutcome.NO_GAP)
    lows: dict[int, int] = {}
    for a in run.attempts:
        if a.outcome in solutions and a.path is not None and a.path["deploys"]:
            lows[a.search_round] = min(lows.get(a.search_round, a.dof), a.dof)
    return lows


def test_the_run_ends_with_its_lowest_round_whose_design_deploys(one_round, rounds):
    """A later round is kept where it reaches the target, or where it ends lower than the
    first round's design with a design known to deploy (its chain is one round's, the rounds
    share the initial shape alone); otherwise the run ends as its first round did: its
    chain, its stop and its final design. No design known to deploy is left for a higher
    one: with the tests' pinned numerics the first round names DOF 2 and the later rounds
    find DOF 1 without a clear gap, which before session 37 the run left for DOF 2."""
    plain, _ = one_round
    run, _ = rounds
    accepted = [a for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]
    assert len(accepted) == len(run.solutions)
    lows = _lowest_deploying(run)
    assert run.final is not None and run.final.path is not None and run.final.path.deploys
    assert run.final_dof <= min(lows.values())
    if {a.search_round for a in accepted} == {0}:
        assert (run.stop, run.stop_detail) == (plain.stop, plain.stop_detail)
        assert [s.result.F for s in run.solutions] == [s.result.F for s in plain.solutions]
        assert run.final_step == plain.final_step and run.final_dof == plain.final_dof
    else:
        assert len({a.search_round for a in accepted[1:]}) == 1
        assert accepted[-1].search_round >= 1
        assert run.final is run.solutions[-1]
        assert plain.final_dof is not None and run.final_dof < plain.final_dof
    assert [s.step for s in run.solutions] == list(range(len(run.solutions)))
    for before, after in zip(run.solutions, run.solutions[1:], strict=False):
        assert np.all(after.result.pattern.fixed[before.result.pattern.fixed])
    # the log's record keeps the round
    for a in run.attempts:
        assert Attempt.from_dict(a.to_dict()).search_round == a.search_round


def test_without_the_check_there_is_one_round():
    run = paper_generate(_case(ROUNDS), criterion="shat", seed=SEED)
    assert {a.search_round for a in run.attempts} == {0}
    assert run.n_backtrack == 0


@pytest.mark.parametrize("bad", [-1, 1.5, True])
def test_a_bad_number_of_rounds_is_refused(bad):
    with pytest.raises(RigidfoldError, match="reseeds"):
        DEFAULTS.with_(reseeds=bad)


def test_a_later_round_ranks_with_the_wider_spread(monkeypatch):
    """The K_j of the first round are the paper's (1e-3 +/- 0.5e-6 N m); a later round's
    spread by ``reseed_spread`` of the mean, drawn from a generator of its own."""
    import rigidfold.generate.steps as steps

    real, spreads = steps.hinge_stiffness, []

    def recorded(h, seed, settings):
        K = real(h, seed, settings)
        g = settings.generation
        assert np.all(np.abs(K - g.hinge_stiffness) <= g.hinge_stiffness_spread)
        spreads.append(g.hinge_stiffness_spread)
        return K

    monkeypatch.setattr(steps, "hinge_stiffness", recorded)
    run = generate(_case(1), OPTIONS)
    g = DEFAULTS.generation
    assert max(a.search_round for a in run.attempts) == 1
    paper, wide = g.hinge_stiffness_spread, g.reseed_spread * g.hinge_stiffness
    assert spreads[0] == paper and spreads[-1] == wide
    assert spreads == sorted(spreads)  # the paper's, then the later round's


def test_a_run_with_a_time_limit_makes_the_timed_rounds():
    """``reseeds`` bounds the rounds of a run without a time limit, ``reseeds_timed`` those
    of a run with one (the limit ends the last)."""
    settings = _case(0).settings.with_(reseeds_timed=1)
    case = case_from_specs("bezier", "1", seed=SEED, settings=settings)
    untimed = generate(case, OPTIONS)
    timed = generate(case, OPTIONS.replace(time_limit=600.0))
    assert {a.search_round for a in untimed.attempts} == {0}
    assert {a.search_round for a in timed.attempts} == {0, 1}


def test_the_command_line_sets_both_bounds(capsys, tmp_path):
    from rigidfold.generate.case_options import SettingsOptions

    g = SettingsOptions().settings().generation
    assert (g.reseeds, g.reseeds_timed) == (
        DEFAULTS.generation.reseeds,
        DEFAULTS.generation.reseeds_timed,
    )
    g = SettingsOptions(reseeds=0).settings().generation
    assert (g.reseeds, g.reseeds_timed) == (0, 0)
    argv = ["generate", "--surface", "dome", "--pattern", "grid:3x3", "--reseeds", "-1"]
    code = main_code([*argv, "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err.strip()
    assert code != 0 and "reseeds" in err and "-1" in err and "Traceback" not in err
    assert not (tmp_path / "run").exists()


class _Sink:
    """The chain as the callbacks see it (a run directory's files): solutions shown, those
    retracted taken off the end; at each attempt of a later round, the chain shown then."""

    def __init__(self, stop_at: tuple[int | str, int] | None = None) -> None:
        self.shown: list = []
        self.during: list[list] = []  # the chain shown at each attempt of a later round
        self.stop_at = stop_at  # (round, attempt of that round) to interrupt at
        self.seen: dict[int, int] = {}
        self.published = 0  # the later round's solutions shown
        self.run = None

    def on_attempt(self, run, attempt):
        self.run = run
        k = self.seen[attempt.search_round] = self.seen.get(attempt.search_round, 0) + 1
        if attempt.search_round >= 1:
            self.during.append(list(self.shown))
        if self.stop_at == (attempt.search_round, k):
            raise KeyboardInterrupt

    def on_solution(self, run, solution):
        assert solution.step == len(self.shown)
        if self.during:  # a later round began: this is its chain, published
            self.published += 1
            if self.stop_at == ("published", self.published):
                raise KeyboardInterrupt
        self.shown.append(solution)

    def on_retract(self, run, taken):
        for solution in taken:
            assert self.shown.pop() is solution


def _watched(sink: _Sink, reseeds: int = ROUNDS):
    return generate(
        _case(reseeds),
        OPTIONS,
        on_attempt=sink.on_attempt,
        on_solution=sink.on_solution,
        on_retract=sink.on_retract,
    )


def test_the_callbacks_keep_the_first_rounds_chain_while_later_rounds_go(one_round):
    """A later round is silent: what the callbacks have (a run directory's files) stays the
    first round's chain while it goes, and at the end is the run's chain."""
    plain, _ = one_round
    sink = _Sink()
    run = _watched(sink)
    assert sink.during, "no later round"
    first = [s.result.F for s in plain.solutions]
    for chain in sink.during:
        assert [s.result.F for s in chain] == first
    assert [s.step for s in sink.shown] == [s.step for s in run.solutions]
    assert all(a is b for a, b in zip(sink.shown, run.solutions, strict=True))


def test_an_interrupt_in_a_later_round_ends_with_the_first_rounds_chain(one_round):
    """Ctrl-C during a later round: the run's chain and named design are the first round's,
    as the callbacks have them; nothing is retracted or shown on the way out."""
    plain, _ = one_round
    sink = _Sink(stop_at=(1, 3))
    with pytest.raises(KeyboardInterrupt):
        _watched(sink)
    run = sink.run
    assert [s.result.F for s in run.solutions] == [s.result.F for s in plain.solutions]
    assert all(a is b for a, b in zip(sink.shown, run.solutions, strict=True))
    assert len(sink.shown) == len(run.solutions)
    assert run.final_step == plain.final_step and plain.final_step is not None
    accepted = [a for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]
    assert len(accepted) == len(run.solutions)
    assert {a.search_round for a in accepted} == {0}


def test_a_run_interrupted_in_a_later_round_keeps_the_first_rounds_files(tmp_path, one_round):
    """Through the pipeline and its run directory: the design named at the first round's
    end is the interrupted run's final design, and its file is on disk."""
    from rigidfold.pipeline import RunWriter, run
    from rigidfold.pipeline.events import AttemptEnded
    from rigidfold.pipeline.run import Interrupted
    from rigidfold.rundir.layout import solution_file

    plain, _ = one_round

    class Stopper:
        def on_event(self, event):
            if isinstance(event, AttemptEnded) and event.attempt.search_round == 1:
                raise KeyboardInterrupt

    out = tmp_path / "run"
    case = _case(ROUNDS)
    with pytest.raises(Interrupted) as stopped:
        run(case, OPTIONS, [RunWriter(out, case, OPTIONS, report=False), Stopper()])
    result = stopped.value.result
    final = result.generation.final
    assert final is not None and final.step == plain.final_step
    assert result.verdict is not None and result.verdict.final_design is not None
    on_disk = sorted(p.name for p in (out / "solutions").glob("*.fold"))
    expected = [solution_file(s.step, s.mechanism.dof).name for s in plain.solutions]
    assert on_disk == sorted(expected)
    assert solution_file(final.step, final.mechanism.dof).name in on_disk


WINS = 8  # rounds enough for the case to reach its target in a later round (round 5 with the
# pinned numerics the tests run with; the tests below check what a round that wins does)


def test_a_later_round_that_reaches_the_target_is_published():
    """The callbacks see the first round's chain retracted and the winning round's chain
    accepted once it reached the target, and have the run's chain at the end."""
    sink = _Sink()
    run = _watched(sink, WINS)
    if run.stop is not Stop.TARGET_REACHED:
        pytest.skip(f"no later round reached the target here: {run.stop.value}, {WINS} rounds")
    assert sink.published == len(run.solutions) - 1  # all but the initial shape
    assert all(a is b for a, b in zip(sink.shown, run.solutions, strict=True))
    assert len(sink.shown) == len(run.solutions)
    accepted = [a for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]
    assert len(accepted) == len(run.solutions) and accepted[-1].search_round >= 1


def test_an_interrupt_as_a_round_is_published_keeps_the_chain_the_callbacks_saw():
    sink = _Sink(stop_at=("published", 3))
    try:
        run = _watched(sink, WINS)
    except KeyboardInterrupt:
        run = sink.run
    else:
        assert run.stop is not Stop.TARGET_REACHED  # nothing published: no interrupt
        pytest.skip(f"no later round reached the target here: {run.stop.value}, {WINS} rounds")
    assert sink.published == 3 and len(sink.shown) == 3  # the initial shape and two
    assert all(a is b for a, b in zip(sink.shown, run.solutions, strict=True))
    assert len(run.solutions) == len(sink.shown)
    assert run.final_step is None
