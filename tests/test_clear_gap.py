"""``Settings.generation.clear_gap`` (issue 49, item 5): a solution at the target DOF whose
DOF has no clear gap is a rejected candidate (``no_gap``); the search goes on for one with a
clear gap and delivers the first such solution only where it finds none.

The margins are replaced here by ones that say "not clear" where the test wants it, so the
test follows the search's rule, not a singular value that one machine's floating point puts
on one side of a threshold."""

from __future__ import annotations

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, GenerateOptions, Stop, generate
from rigidfold.generate import steps as steps_module
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.margin import DofMargin

OPTIONS = GenerateOptions(lookahead=True, deploy_check=True)


def _margins(monkeypatch, clear_after: int | None):
    """The search's margin checks say "not clear" for the first ``clear_after`` calls (None:
    always); the final design's margin is the real one. Returns the list of calls."""
    calls: list[int] = []
    real = steps_module.dof_margin

    def fake(pattern, support_face, settings, *, count, counted):
        calls.append(counted)
        margin = real(pattern, support_face, settings, count=count, counted=counted)
        if clear_after is None or len(calls) <= clear_after:
            return DofMargin(**{**margin.__dict__, "counted": margin.dof + 1})  # disagrees
        return margin

    monkeypatch.setattr(steps_module, "dof_margin", fake)
    return calls


@pytest.fixture(scope="module")
def case():
    return case_from_specs("bezier", "1", seed=1)


def test_a_solution_without_a_clear_gap_is_passed_over_for_one_with_it(case, monkeypatch):
    calls = _margins(monkeypatch, clear_after=1)
    run = generate(case, OPTIONS)
    outcomes = [a.outcome for a in run.attempts]
    assert outcomes.count(AttemptOutcome.NO_GAP) == 1 and len(calls) >= 2
    no_gap = next(a for a in run.attempts if a.outcome is AttemptOutcome.NO_GAP)
    assert no_gap.dof == 1  # a target-DOF solution, not taken
    assert run.stop is Stop.TARGET_REACHED and run.final is not None
    assert run.final.mechanism.dof == 1
    assert run.attempts[-1].outcome is AttemptOutcome.ACCEPTED  # a later one delivered
    assert all(s.mechanism.dof > 1 for s in run.solutions[:-1])


def test_without_a_clear_gap_anywhere_the_first_such_solution_is_delivered(case, monkeypatch):
    _margins(monkeypatch, clear_after=None)
    run = generate(case, OPTIONS, time_limit=30)
    at_target = [
        a
        for a in run.attempts
        if a.dof == 1 and a.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.NO_GAP)
    ]
    assert len(at_target) >= 2  # the search went on past the first
    first, *later = at_target
    assert first.outcome is AttemptOutcome.ACCEPTED  # the fallback, accepted again at the end
    assert all(a.outcome is AttemptOutcome.NO_GAP for a in later)
    assert run.stop is Stop.TARGET_REACHED
    assert run.final is not None and run.final.mechanism.dof == 1
    assert run.dof_margin is not None and not run.dof_margin["clear"]  # the verdict says so


def test_accept_no_gap_ends_at_the_first_target_solution(case, monkeypatch):
    calls = _margins(monkeypatch, clear_after=None)
    settings = DEFAULTS.with_(clear_gap=False)
    run = generate(case.__class__(**{**case.__dict__, "settings": settings}), OPTIONS)
    assert len(calls) == 1 and run.stop is Stop.TARGET_REACHED  # the final design's only
    assert AttemptOutcome.NO_GAP not in {a.outcome for a in run.attempts}


def test_the_papers_step_5_never_asks_for_a_gap(case, monkeypatch):
    calls = _margins(monkeypatch, clear_after=None)
    run = generate(case, GenerateOptions(deploy_check=False))
    assert len(calls) == 1 and run.final is not None  # the final design's only
