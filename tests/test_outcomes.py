"""Outcome enums of the result types: values (what files and databases hold), messages,
the stop reasons of a generation run and the ``to_dict`` of every result type."""

from __future__ import annotations

import json

import pytest

from rigidfold.deform import DeformStatus, MotionStatus, verify
from rigidfold.develop import DevelopStatus
from rigidfold.generate import STOP_REASONS, Attempt, AttemptOutcome, Generation, Stop
from rigidfold.mechanism.path import PathStatus
from rigidfold.optimize import Status
from rigidfold.outcomes import Outcome
from rigidfold.patterns import miura

# the values that JSON files and study databases of every version hold
VALUES = {
    Status: [
        "converged",
        "tolerance_not_met",
        "infeasible",
        "iteration_limit",
        "stalled",
        "folded_back",
        "failed",
    ],
    AttemptOutcome: [
        "accepted",
        "exceed",
        "lock",
        "zero_dof",
        "path",
        "second_order_rigid",
        "time_limit",
        "no_gap",
        "no_gain",
        "initial_failed",
        "dead_end",
    ],
    PathStatus: [
        "flat",
        "turned_back",
        "stops_short",
        "collision",
        "stalled",
        "max_steps",
        "rigid",
    ],
    Stop: [
        "running",
        "target_reached",
        "zero_dof",
        "no_candidate",
        "no_deployable",
        "initial_failed",
        "interrupted",
        "time_limit",
    ],
    DevelopStatus: ["converged", "flipped", "overlap", "failed"],
    DeformStatus: ["reached_plane", "failed"],
    MotionStatus: ["ok", "failed", "cut"],
}


@pytest.mark.parametrize("enum", list(VALUES), ids=lambda e: e.__name__)
def test_members_are_their_values_and_carry_a_message(enum):
    assert issubclass(enum, Outcome)
    assert [m.value for m in enum] == VALUES[enum]
    for member in enum:
        assert member == member.value and enum(member.value) is member
        assert json.dumps(member) == json.dumps(member.value)
        assert member.message and member.message != member.value
    assert len({m.message for m in enum}) == len(enum)


def test_stop_reasons_are_their_texts():
    texts = {
        (Stop.TARGET_REACHED, "1"): "target DOF 1 reached",
        (Stop.ZERO_DOF, ""): "DOF 0 reached",
        (Stop.NO_CANDIDATE, ""): "no candidate crease succeeds",
        (Stop.NO_DEPLOYABLE, "30"): "no deployable solution in 30 candidates",
        (Stop.INITIAL_FAILED, "lock"): "no developable polyhedron from the initial shape (lock)",
        (Stop.RUNNING, ""): "running",
        (Stop.INTERRUPTED, ""): "interrupted",
        (Stop.TIME_LIMIT, "60"): "time limit of 60 s reached",
    }
    assert set(STOP_REASONS) == set(Stop)
    for (stop, detail), text in texts.items():
        run = Generation(stop=stop, stop_detail=detail)
        assert run.stop_reason == stop.reason(detail) == text
        d = run.to_dict()
        assert (d["stop"], d["stop_reason"]) == (stop.value, text)


def test_attempt_to_dict_holds_plain_values():
    a = Attempt(0, (3,), 0.5, Status.CONVERGED, 1e-9, 12, 4, [], AttemptOutcome.LOCK, 0.1, 0.2)
    d = a.to_dict()
    assert type(d["status"]) is str and type(d["outcome"]) is str
    assert (d["status"], d["outcome"]) == ("converged", "lock")
    assert a.outcome == "lock" and a.status is Status.CONVERGED  # the record keeps the enums


def test_development_figures_are_the_same_in_the_cli_and_the_check():
    shape = miura(3, 3)
    check = verify(shape, run_deform=False, run_motion=False)
    dev = check.development.to_dict()
    cli_keys = {"D", "max_length_error", "flipped", "overlaps", "status", "iterations", "start"}
    assert cli_keys | {"wall_time_s", "message"} <= set(dev)
    assert dev["status"] == "converged" and type(dev["status"]) is str
    out = check.to_dict()
    assert out["development"] == dev and out["deformation"] is None and out["motion"] is None
    json.dumps(out)


def test_the_report_draws_every_attempt_outcome():
    from rigidfold.reporting.figures import OUTCOME_STYLE

    assert set(OUTCOME_STYLE) == {o.value for o in AttemptOutcome}
    assert len({style[:2] for style in OUTCOME_STYLE.values()}) == len(OUTCOME_STYLE)
