"""One pipeline for a design run (issue 46, item 1): ``rigidfold.pipeline.run`` tells its
sinks every attempt, solution and retraction in order, then the end; the final design's
folding path is traced once per run; a sink is one class; the result is one frozen record
with one ``to_dict``; an interrupt and a failed write end the run as the command's did.

The case: the 3 x 3 grid on the dome, which backtracks (solutions retracted) and stops at
DOF 3, in seconds.
"""

from __future__ import annotations

import importlib
import json
from dataclasses import FrozenInstanceError

import pytest

from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions, Stop
from rigidfold.generate.specs import case_from_specs
from rigidfold.pipeline import (
    AttemptEnded,
    FinalChecked,
    Interrupted,
    RunEnded,
    RunFailed,
    RunInterrupted,
    RunResult,
    Sink,
    SolutionAccepted,
    SolutionsRetracted,
    run,
)
from rigidfold.pipeline.verdict import RunOutcome

RUN = importlib.import_module("rigidfold.pipeline.run")  # the module, not the function
MOTION = importlib.import_module("rigidfold.deform.motion")


class Recorder:
    """A custom sink: one class, one method."""

    def __init__(self) -> None:
        self.events: list = []

    def on_event(self, event) -> None:
        self.events.append(event)


def _case():
    return case_from_specs("dome", "grid:3x3")


@pytest.fixture(scope="module")
def recorded():
    """The backtracking run (the deployability check), Step 8 and the motion of the final
    design only: (its result, the events a sink received)."""
    sink = Recorder()
    result = run(_case(), GenerateOptions(deform=False), [sink])
    return result, sink.events


def test_a_custom_sink_is_one_class_with_one_method():
    assert isinstance(Recorder(), Sink)
    assert [m for m in vars(Recorder) if not m.startswith("_")] == ["on_event"]


def test_a_sink_receives_the_attempts_solutions_retractions_and_end_in_order(recorded):
    result, events = recorded
    generation = result.generation
    kinds = [type(e) for e in events]
    assert kinds[0] is AttemptEnded  # the initial solve
    assert kinds[-2:] == [FinalChecked, RunEnded]  # the final design checked, then the end
    assert events[-1].result is result
    assert not {RunInterrupted, RunFailed} & set(kinds)
    # every attempt once, in the order solved
    attempts = [e.attempt.index for e in events if isinstance(e, AttemptEnded)]
    assert attempts == list(range(len(generation.attempts)))
    # solutions and retractions: the chain the run ended with, a record for each
    accepted = [e for e in events if isinstance(e, SolutionAccepted)]
    retracted = [e for e in events if isinstance(e, SolutionsRetracted)]
    assert generation.n_backtrack >= 1 and retracted
    assert len(accepted) - sum(len(e.taken) for e in retracted) == len(generation.solutions)
    chain: list[int] = []
    for e in events:
        if isinstance(e, SolutionAccepted):
            assert e.solution.step == len(chain)  # a chain: the next step
            chain.append(e.solution.step)
            assert e.record.step == e.solution.step
            assert len(e.result.records) == len(chain)
            assert e.checked is None  # --check final: not checked as it came
        elif isinstance(e, SolutionsRetracted):
            for s in e.taken:  # the last first
                assert chain.pop() == s.step
            assert len(e.result.records) == len(chain)
    assert chain == [s.step for s in generation.solutions]
    # an accepted attempt comes before its solution
    first = kinds.index(SolutionAccepted)
    assert isinstance(events[first - 1], AttemptEnded)
    assert events[first - 1].attempt.outcome is AttemptOutcome.ACCEPTED
    final = events[-2]
    assert final.solution is result.final and final.checked is result.final_checked


def test_the_result_is_frozen_and_has_one_to_dict(recorded):
    result, _ = recorded
    assert isinstance(result, RunResult)
    with pytest.raises(FrozenInstanceError):
        result.verdict = None  # type: ignore[misc]
    data = json.loads(json.dumps(result.to_dict()))
    generation = result.generation
    assert data["stop"] == generation.stop.value == Stop.NO_CANDIDATE.value
    assert data["n_backtrack"] == generation.n_backtrack
    assert data["verdict"]["outcome"] == result.verdict.outcome.value == "fell_short"
    assert data["solutions"] == [
        f"solutions/step_{s.step:02d}_dof_{s.mechanism.dof:02d}.fold" for s in generation.solutions
    ]
    assert [r["step"] for r in data["per_solution"]] == [s.step for s in generation.solutions]
    assert data["checked_steps"] == [result.final.step]
    assert set(data["time_s"]) >= {"build", "solve", "path", "develop", "deform", "motion"}
    assert data["exports"] == [] and data["write_error"] is None  # no run directory
    assert result.final_verdicts is None  # no Step 9: one verdict only
    assert result.verdict.final_design.name == data["solutions"][result.final.step].split("/")[1]


def _count_traces(monkeypatch) -> dict[str, int]:
    """Count trace_path in the pipeline and in the folding motion (Step 8's check)."""
    counts = {"pipeline": 0, "motion": 0}
    for name, module in (("pipeline", RUN), ("motion", MOTION)):
        real = module.trace_path

        def counted(*args, _real=real, _name=name, **kwargs):
            counts[_name] += 1
            assert kwargs.get("support_face") is None or _name == "motion"  # the run's
            return _real(*args, **kwargs)

        monkeypatch.setattr(module, "trace_path", counted)
    return counts


@pytest.mark.parametrize("motion", [True, False], ids=["command", "study"])
def test_the_final_designs_path_is_traced_once(monkeypatch, motion):
    """Without the deployability check the search traces no path: the pipeline traces the
    final design's, once, and its folding motion follows it (the command); the study
    traces it for its deployability alone."""
    counts = _count_traces(monkeypatch)
    options = GenerateOptions(deform=False, deploy_check=False, target_dof=4)
    result = run(_case(), options, motion=motion)
    assert result.final is not None and result.final.path is None  # not the search's
    assert counts == {"pipeline": 1, "motion": 0}
    assert result.final_path is not None and result.final_path_time > 0
    record = result.final_record
    if motion:  # the motion check ran along that path
        assert record.motion is not None and record.motion["path"] == result.final_path.to_dict()
    else:  # no check at all: Step 8 runs only with Step 9 in a study
        assert record.motion is None and not result.checked


def test_an_interrupt_ends_the_run_with_its_result(monkeypatch):
    """A signal anywhere (here: a sink, at the third attempt): every sink is told
    (RunInterrupted, last), and Interrupted (a KeyboardInterrupt) carries the result."""

    class Stops:
        def __init__(self) -> None:
            self.n = 0

        def on_event(self, event) -> None:
            if isinstance(event, AttemptEnded):
                self.n += 1
                if self.n == 3:
                    raise KeyboardInterrupt

    sink = Recorder()
    with pytest.raises(Interrupted) as caught:
        run(_case(), GenerateOptions(deform=False), [sink, Stops()])
    result = caught.value.result
    assert isinstance(caught.value, KeyboardInterrupt)
    assert result.interrupted and result.generation.stop is Stop.INTERRUPTED
    assert isinstance(sink.events[-1], RunInterrupted) and sink.events[-1].result is result
    assert result.verdict.outcome is RunOutcome.FELL_SHORT
    assert "interrupted" in result.verdict.message


def test_a_failed_write_at_the_end_is_the_verdicts_cause():
    """A sink that cannot write its files once the search has ended: the run ends with
    RunFailed to every sink, and its verdict names the cause."""

    class FullDisk:
        def on_event(self, event) -> None:
            if isinstance(event, RunEnded):
                raise RigidfoldError("cannot write 'summary.json' (the disk is full)")

    sink = Recorder()
    options = GenerateOptions(deform=False, deploy_check=False, target_dof=4)
    result = run(_case(), options, [sink, FullDisk()])
    assert isinstance(sink.events[-1], RunFailed) and sink.events[-1].result is result
    assert result.write_error == "cannot write 'summary.json' (the disk is full)"
    assert result.verdict.outcome is RunOutcome.FELL_SHORT
    assert "the disk is full" in result.verdict.message


def test_as_built_checks_need_a_run_directory():
    from rigidfold.structure.design import StructureOptions

    with pytest.raises(RigidfoldError, match="run directory"):
        run(_case(), GenerateOptions(deform=False, structure=StructureOptions()))
