"""Backtracking in Step 7 (``Settings.generation.backtrack_max``): a shape after the first
whose candidates give no deployable solution retracts its solution, and generation resumes at
the shape before with that shape's remaining candidates; the run stays a chain, on disk too.

The case: pattern 1 on Bezier seed 102 (S-hat, look-ahead) with ``deploy_max_candidates = 1``,
so that one folding path that does not reach the flat state gives a shape up (seconds).
"""

from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest

import rigidfold.generate.deploy_check as deploy_check
import rigidfold.generate.final as final
from conftest import main_code, paper_generate
from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, GenerateOptions, Stop, generate
from rigidfold.generate.final import lowest_deploying
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.path import PathStatus
from rigidfold.pipeline import RunWriter, run
from rigidfold.rundir import load_run, read_log

SEED = 102
# one crease per solve: backtracking alone, not the end of the sets (tests/test_batch.py);
# the paper's solver, IPOPT alone, with which this case backtracks (GenerateOptions.projection)
OPTIONS = GenerateOptions(
    criterion="shat", seed=SEED, lookahead=True, deform=False, batch="off", projection="large"
)


def _case(backtrack_max: int):
    # backtracking alone: no restart with the fold limit (tests/test_fold_limit.py), one
    # round (tests/test_reseed.py)
    settings = DEFAULTS.with_(
        deploy_max_candidates=1, backtrack_max=backtrack_max, fold_limits=(), reseeds=0
    )
    return case_from_specs("bezier", "1", seed=SEED, settings=settings)


@pytest.fixture(scope="module")
def backtracked(tmp_path_factory):
    out = tmp_path_factory.mktemp("backtrack")
    case = _case(DEFAULTS.generation.backtrack_max)
    return out, run(case, OPTIONS, [RunWriter(out, case, OPTIONS)]).generation


def test_a_backtracking_run_ends_with_a_chain(backtracked):
    _, run = backtracked
    assert run.n_backtrack >= 1
    assert run.n_backtrack <= DEFAULTS.generation.backtrack_max
    outcomes = [a.outcome for a in run.attempts]
    assert outcomes.count(AttemptOutcome.DEAD_END) == run.n_backtrack
    assert outcomes.count(AttemptOutcome.ACCEPTED) == len(run.solutions)
    assert [s.step for s in run.solutions] == list(range(len(run.solutions)))
    for before, after in zip(run.solutions, run.solutions[1:], strict=False):
        fixed_before = before.result.pattern.fixed
        fixed_after = after.result.pattern.fixed
        assert np.all(fixed_after[fixed_before])  # every fix of the chain is kept
        assert fixed_after.sum() > fixed_before.sum()
        assert after.mechanism.dof <= before.mechanism.dof
    # the retracted solutions were accepted shapes of the run
    for attempt in run.attempts:
        if attempt.outcome is AttemptOutcome.DEAD_END:
            assert attempt.dof is not None and attempt.dof >= 1
    assert run.to_dict()["n_backtrack"] == run.n_backtrack


def test_the_run_directory_holds_only_the_chain(backtracked):
    out, run = backtracked
    summary = json.loads((out / "summary.json").read_text())
    log = read_log(out / "log.jsonl")  # the last line of each attempt
    assert summary["n_backtrack"] == run.n_backtrack
    assert sum(a.outcome == "dead_end" for a in log) == run.n_backtrack
    assert [a.outcome for a in log] == [a.outcome.value for a in run.attempts]
    names = [f"step_{s.step:02d}_dof_{s.mechanism.dof:02d}" for s in run.solutions]
    assert summary["solutions"] == [f"solutions/{n}.fold" for n in names]
    assert [r["step"] for r in summary["per_solution"]] == list(range(len(run.solutions)))
    on_disk = sorted(p.name for p in (out / "solutions").iterdir())
    final = names[summary["final_step"]]  # the development diagram of the final design only
    assert on_disk == sorted([f"{n}.fold" for n in names] + [f"{final}.svg"])
    assert summary["n_solutions"] == len(run.solutions)
    # it reads back, and the report (written by the run) is made again from it
    data = load_run(out)
    assert data.summary.n_backtrack == run.n_backtrack
    assert (out / "report.html").is_file()
    assert main_code(["report", str(out)]) == 0


def test_no_backtracking_is_the_run_without_it(backtracked):
    """backtrack_max = 0: the run ends where the backtracking run first retracted, with the
    same attempts up to there (the same F, to the last digit)."""
    _, run = backtracked
    plain = generate(_case(0), OPTIONS)
    assert plain.n_backtrack == 0 and plain.stop is Stop.NO_DEPLOYABLE
    assert AttemptOutcome.DEAD_END not in [a.outcome for a in plain.attempts]
    first = next(i for i, a in enumerate(run.attempts) if a.outcome is AttemptOutcome.DEAD_END)
    assert len(plain.attempts) > first
    for a, b in zip(plain.attempts, run.attempts, strict=False):
        assert a.F == b.F and a.fixed_added == b.fixed_added
        assert a.outcome == b.outcome or b.outcome is AttemptOutcome.DEAD_END


def test_without_the_check_nothing_is_retracted():
    run = paper_generate(_case(DEFAULTS.generation.backtrack_max), criterion="shat", seed=SEED)
    assert run.n_backtrack == 0 and run.final_dof == 1
    assert AttemptOutcome.DEAD_END not in [a.outcome for a in run.attempts]


def test_backtrack_max_is_checked():
    with pytest.raises(ValueError, match="backtrack_max"):
        DEFAULTS.with_(backtrack_max=-1)


def test_backtracking_that_finds_nothing_lower_ends_with_the_chain_it_had(tmp_path):
    """A 3 x 3 grid on the dome stops at DOF 3 (no candidate succeeds); backtracking finds no
    lower chain, so the run ends with the one it had, and the chains it tried since leave no
    file."""
    case = case_from_specs("dome", "grid:3x3")
    plain = generate(
        case_from_specs(
            "dome", "grid:3x3", settings=DEFAULTS.with_(backtrack_max=0, fold_limits=())
        )
    )
    options = GenerateOptions(deform=False)
    writer = RunWriter(tmp_path, case, options, report=False)
    generation = run(case, options, [writer]).generation
    assert plain.stop is generation.stop is Stop.NO_CANDIDATE
    dofs = [s.mechanism.dof for s in generation.solutions]
    assert dofs == [s.mechanism.dof for s in plain.solutions]
    for a, b in zip(plain.solutions, generation.solutions, strict=True):
        assert a.result.F == b.result.F
    assert len(generation.attempts) > len(plain.attempts)  # it went back and tried more
    outcomes = [a.outcome for a in generation.attempts]
    assert outcomes.count(AttemptOutcome.DEAD_END) == generation.n_backtrack >= 1
    assert outcomes.count(AttemptOutcome.ACCEPTED) == len(generation.solutions)
    summary = json.loads((tmp_path / "summary.json").read_text())
    names = [f"step_{k:02d}_dof_{d:02d}" for k, d in enumerate(dofs)]
    assert summary["solutions"] == [f"solutions/{n}.fold" for n in names]
    on_disk = sorted(p.name for p in (tmp_path / "solutions").iterdir())
    final = names[summary["final_step"]]  # the development diagram of the final design only
    assert on_disk == sorted([f"{n}.fold" for n in names] + [f"{final}.svg"])


def test_lowest_deploying_probes_from_the_end_or_bisects():
    """``lowest_deploying`` names a solution that deploys whose next one does not, from a
    known deploying solution (or none, -1): galloping back from the chain's end, in about
    2 log2(d) traces for one d solutions above the last, never probing below the known one;
    bisecting, in about log2 of the chain's length."""
    chain = [SimpleNamespace(step=k) for k in range(33)]
    for last_good in (-1, 0, 3, 9, 29, 31, 32):
        for gallop in (True, False):
            asked: list[int] = []

            def deploys(solution, last_good=last_good, asked=asked):
                asked.append(solution.step)
                return solution.step <= last_good

            found = lowest_deploying(chain, -1 if last_good < 0 else 0, deploys, gallop=gallop)
            assert found == last_good
            assert all(step > 0 for step in asked) or last_good < 0
            d = len(chain) - last_good
            most = 2 * int(np.ceil(np.log2(d))) + 1 if gallop else 6  # ceil(log2(34))
            assert len(asked) <= most, (last_good, gallop, asked)
    never = lambda s: pytest.fail("no trace below a known deploying solution")  # noqa: E731
    assert lowest_deploying(chain, 32, never, gallop=True) == 32


def test_a_dead_end_whose_shape_does_not_deploy_rewinds_to_the_lowest_that_does(monkeypatch):
    """``Settings.generation.rewind``: every DOF-1 candidate's path is made to turn back, so
    the chain dead-ends at a DOF-2 shape; the shapes' own paths (traced by the rewind) are
    made to deploy from DOF ``ABOVE`` up and to turn back below. Backtracking then retracts,
    in one step of its budget, every solution below DOF ``ABOVE`` (not only the last): the
    chain goes on from the lowest shape that deploys, without the fix that led below it;
    the run, short of its target, names that shape (its path known) as its design.
    Without the rewind, backtracking retracts one solution."""
    above = 4
    traced: list[int] = []

    def candidates_turn_back(pattern, **kwargs):
        return dataclasses.replace(real(pattern, **kwargs), status=PathStatus.TURNED_BACK)

    def by_dof(pattern, *, dof, **kwargs):
        traced.append(dof)
        path = real(pattern, dof=dof, **kwargs)
        status = PathStatus.FLAT if dof >= above else PathStatus.TURNED_BACK
        return dataclasses.replace(path, status=status)

    real = deploy_check.trace_path
    monkeypatch.setattr(deploy_check, "trace_path", candidates_turn_back)
    monkeypatch.setattr(final, "trace_path", by_dof)
    for rewind in (True, False):
        settings = DEFAULTS.with_(
            deploy_max_candidates=1, backtrack_max=1, fold_limits=(), reseeds=0, rewind=rewind
        )
        case = case_from_specs("bezier", "1", seed=SEED, settings=settings)
        retractions: list[tuple[int, list[int], int]] = []
        traced.clear()

        def on_retract(run, taken, retractions=retractions):
            dofs = [s.mechanism.dof for s in taken]
            retractions.append((run.solutions[-1].mechanism.dof, dofs, len(traced)))

        run = generate(case, OPTIONS, on_retract=on_retract)
        kept, taken, n_traced = retractions[0]
        if not rewind:
            assert len(taken) == 1 and taken[0] == 2 and n_traced == 0
            continue
        assert taken[-1] >= 2 and taken[0] < above  # the dead end first, the lowest last
        assert all(dof < above for dof in taken)
        assert len(taken) >= 2, "the case's chain has more than one solution below DOF 4"
        assert kept >= above  # the lowest deploying shape: the chain's solution kept
        assert traced[0] == 2  # the dead end's own shape first
        assert n_traced <= 1 + 2 * int(np.ceil(np.log2(len(taken) + 1)))
        after = [a for a in run.attempts if a.index > 0 and a.outcome.value != "dead_end"]
        dead = {a.fixed_added for a in run.attempts if a.outcome is AttemptOutcome.DEAD_END}
        assert run.stop is Stop.NO_DEPLOYABLE
        assert run.final is not None and run.final.mechanism.dof >= above
        assert run.final.path is not None and run.final.path.deploys
        assert after  # the chain went on from the kept shape
        first_dead = min(
            (a for a in run.attempts if a.outcome is AttemptOutcome.DEAD_END),
            key=lambda a: a.index,
        )
        assert first_dead.fixed_added in dead
