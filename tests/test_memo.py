"""Nothing solved twice (:mod:`rigidfold.generate.memo`): a candidate met again at bitwise
the same shape under the same bound repeats its earlier attempt (``Attempt.solve_from``)
instead of being solved, analysed and checked again, and the search decides as it did.

The case: a 4 x 4 grid on the Bezier surface of seed 3 (S-hat, look-ahead, the deployability
check), whose every round of the search walks the same shapes again (``reseeds = 1``: two
rounds; no fold limit, so no decision depends on seconds).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import main_code
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Attempt, AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.memo import AttemptMemo, attempt_key
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import Status
from rigidfold.rundir import read_log

OPTIONS = GenerateOptions(criterion="shat", seed=3, lookahead=True, deform=False)


def _run(reuse_max_dof: int):
    settings = DEFAULTS.with_(reseeds=1, fold_limits=(), reuse_max_dof=reuse_max_dof)
    case = case_from_specs("bezier", "grid:4x4", seed=3, size="1x1", settings=settings)
    return generate(case, OPTIONS)


@pytest.fixture(scope="module")
def runs():
    return _run(DEFAULTS.generation.reuse_max_dof), _run(0)


def _decisions(run) -> list[tuple]:
    return [(frozenset(a.fixed_added), a.outcome, a.dof, a.search_round) for a in run.attempts]


def test_repeats_decide_as_the_solves_they_repeat(runs):
    kept, computed = runs
    assert _decisions(kept) == _decisions(computed)
    assert kept.final_dof == computed.final_dof and kept.stop is computed.stop
    assert all(a.solve_from is None for a in computed.attempts)


def test_a_repeat_names_its_attempt_and_costs_no_solve(runs):
    kept, _ = runs
    repeats = [a for a in kept.attempts if a.solve_from is not None]
    assert repeats  # the second round walks the first one's shapes again
    assert all(a.search_round == 1 for a in repeats[:1])
    for a in repeats:
        first = kept.attempts[a.solve_from]
        assert first.solve_from is None and first.index < a.index
        assert set(first.fixed_added) == set(a.fixed_added)
        assert (first.F, first.iterations, first.status) == (a.F, a.iterations, a.status)
        assert a.solve_time == a.analysis_time == a.path_time == 0.0
    summary = kept.to_dict()
    assert summary["n_repeats"] == len(repeats)
    assert summary["n_solves"] == len(kept.attempts) - len(repeats)
    back = Attempt.from_dict(repeats[0].to_dict())
    assert back.solve_from == repeats[0].solve_from


def test_the_command_line_counts_the_repeats(tmp_path, capsys):
    """``generate`` says how many of its attempts repeated one; summary.json and log.jsonl
    agree with it."""
    out = tmp_path / "run"
    argv = "generate --surface bezier --pattern grid:4x4 --size 1x1 --seed 3 --lookahead"
    argv += " --no-deform --quiet --no-report --reseeds 1 --fold-limit 0 --out"
    main_code([*argv.split(), str(out)])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_repeats"] > 0
    attempts = read_log(out / "log.jsonl")
    assert len(attempts) == summary["n_solves"] + summary["n_repeats"]
    assert sum(a.solve_from is not None for a in attempts) == summary["n_repeats"]
    said = capsys.readouterr()
    text = said.out + said.err
    assert f"{summary['n_solves']} solves ({summary['n_repeats']} repeated)" in text


def _attempt(outcome: AttemptOutcome, dof: int | None, index: int = 0) -> Attempt:
    return Attempt(
        index=index,
        fixed_added=(3,),
        score=None,
        status=Status.CONVERGED,
        F=0.0,
        iterations=1,
        dof=dof,
        locked=[],
        outcome=outcome,
        solve_time=1.0,
        analysis_time=1.0,
    )


def test_the_key_is_the_shape_bitwise_the_fix_the_bound_and_the_polish():
    pattern = case_from_specs("bezier", "1", seed=102).pattern
    key = attempt_key(pattern, (5, 2), None, True)
    assert key == attempt_key(pattern, (2, 5), None, True)  # the fix as a set
    assert key != attempt_key(pattern, (2, 5), 2.0, True)
    assert key != attempt_key(pattern, (2, 5), None, False)
    moved = pattern.coords.copy()
    moved[0, 2] = np.nextafter(moved[0, 2], np.inf)
    assert key != attempt_key(pattern.with_coords(moved), (2, 5), None, True)


def test_what_the_memo_keeps():
    memo: AttemptMemo[str] = AttemptMemo(max_dof=2)
    memo.keep(("a", (1,), None, True), _attempt(AttemptOutcome.TIME_LIMIT, None), "cut")
    memo.keep(("b", (1,), None, True), _attempt(AttemptOutcome.ACCEPTED, 3), "high")
    memo.keep(("c", (1,), None, True), _attempt(AttemptOutcome.ACCEPTED, 2, index=4), "kept")
    memo.keep(("d", (1,), None, True), _attempt(AttemptOutcome.EXCEED, None), "failed")
    assert len(memo) == 2
    assert memo.repeat(("a", (1,), None, True), 9, 0) is None
    again = memo.repeat(("c", (1,), None, True), 9, 1)
    assert again is not None
    rec, trial = again
    assert (rec.index, rec.search_round, rec.solve_from, trial) == (9, 1, 4, "kept")
    assert rec.solve_time == 0.0 and rec.outcome is AttemptOutcome.ACCEPTED
    off: AttemptMemo[str] = AttemptMemo(max_dof=0)
    off.keep(("d", (1,), None, True), _attempt(AttemptOutcome.EXCEED, None), "failed")
    assert len(off) == 0


def test_the_setting_is_checked():
    with pytest.raises(RigidfoldError, match="reuse_max_dof"):
        DEFAULTS.with_(reuse_max_dof=-1)
