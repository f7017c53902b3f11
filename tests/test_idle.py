"""Candidates forecast to remove no DOF (``Settings.generation.idle_last``, ``idle_gain``,
issue 49): tried once every other candidate of a shape failed; with ``idle_gain`` a
solution of one that keeps the shape's DOF is not kept (outcome NO_GAIN), as it is the same
shape with a crease that does not turn fixed, whose candidates are the shape's own."""

from __future__ import annotations

from dataclasses import replace

import pytest

import rigidfold.generate.steps as steps
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.selection import lock_forecast
from rigidfold.selection.lookahead import Choice

OPTIONS = GenerateOptions(deform=False, lookahead=True, time_limit=120)


def _shifted(choice: Choice) -> Choice:
    """``choice`` with its index (and those it passed) one further down the ranking."""
    return replace(choice, index=choice.index + 1, passed=tuple(_shifted(c) for c in choice.passed))


def _vault(idle_gain: bool):
    """A 5 x 3 grid lifted onto a barrel vault, some of whose free creases do not turn in
    any mechanism of its initial shape (``tests/test_lookahead.py``)."""
    settings = DEFAULTS.with_(idle_gain=idle_gain)
    return case_from_specs(
        "expr", "grid:5x3", seed=0, size="4x2", expr="0.1*x*(4-x)", settings=settings
    )


def _with_an_idle_first(monkeypatch, idle_gain: bool):
    """The vault, where at the initial shape a crease that turns in no mechanism (forecast
    to keep the DOF, :func:`rigidfold.selection.lock_forecast`) is ranked first and tried
    first as idle, as it would be once every other candidate failed: the run, and the DOF
    of that shape."""
    rank, at = steps._Steps.rank, {}

    def ranked_with_idle(self, current):
        ranked, order, forecast, t_sel = rank(self, current)
        if current.step != 0 or at:
            return ranked, order, forecast, t_sel
        mech = current.mechanism
        groups = [(int(e),) for e in mech.hinges]
        after = lock_forecast(mech, groups, settings=self.asettings).dof_after
        at["dof"] = mech.dof
        idle = next(g for g, n in zip(groups, after, strict=True) if n == mech.dof)

        def idle_first():
            yield Choice(0, idle=True)
            yield from (_shifted(c) for c in order)

        return [(idle, 0.0), *ranked], idle_first(), forecast, t_sel

    monkeypatch.setattr(steps._Steps, "rank", ranked_with_idle)
    return generate(_vault(idle_gain), OPTIONS), at["dof"]


def _chain(run):
    """The fixes and DOF of the run's accepted attempts, in order."""
    return [(a.fixed_added, a.dof) for a in run.attempts if a.outcome is AttemptOutcome.ACCEPTED]


def test_an_idle_fix_that_keeps_the_dof_is_not_kept(monkeypatch):
    """With ``idle_gain`` the idle fix solves to its shape's DOF and is refused (NO_GAIN);
    the shape goes on with its ranked candidates, and the run's chain is the one without
    the idle candidate, fix for fix. Without it, the fix is kept as a solution of the same
    DOF."""
    plain = generate(_vault(idle_gain=True), OPTIONS)
    run, dof = _with_an_idle_first(monkeypatch, idle_gain=True)
    refused = [a for a in run.attempts if a.outcome is AttemptOutcome.NO_GAIN]
    assert len(refused) == 1 and refused[0].dof == dof and refused[0].iterations <= 1
    assert _chain(run) == _chain(plain) and run.final_dof == plain.final_dof == 1

    run, dof = _with_an_idle_first(monkeypatch, idle_gain=False)
    assert not any(a.outcome is AttemptOutcome.NO_GAIN for a in run.attempts)
    kept = next(a for a in run.attempts if a.index > 0 and a.dof == dof and a.iterations <= 1)
    assert kept.outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END)


def test_idle_gain_is_a_boolean():
    with pytest.raises(RigidfoldError, match="idle_gain"):
        DEFAULTS.with_(idle_gain="yes")
