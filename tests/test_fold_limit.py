"""The restart with the fold limit (issue 40): where a run's chain dead-ends with the
deployability check, it starts again from the initial shape with bound (12) at
``Settings.generation.fold_limit`` on every solve."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import rigidfold.generate as generation
from rigidfold.case import make_case
from rigidfold.case_options import SettingsOptions
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import AttemptOutcome, Stop, generate, with_fold_limit
from rigidfold.generate_options import GenerateOptions
from rigidfold.mechanism.path import PathStatus


def _largest_fold_deg(pattern) -> float:
    free = ~pattern.fixed & ~pattern.is_boundary_edge
    return float(np.degrees(np.abs(pattern.fold_angles[free]).max()))


def test_the_restart_case_has_bound_12_at_the_limit():
    case = make_case("dome", "1", seed=1)
    bounded = with_fold_limit(case, GenerateOptions())
    assert bounded.settings.design.rho_bar == DEFAULTS.generation.fold_limit
    assert bounded.pattern is case.pattern and bounded.surface is case.surface
    # the paper's Step 5 (no check), the user's own bound (12), no limit: no restart
    assert with_fold_limit(case, GenerateOptions(deploy_check=False)) is case
    own = make_case("dome", "1", seed=1, settings=DEFAULTS.with_(rho_bar=math.radians(90)))
    assert with_fold_limit(own, GenerateOptions()) is own
    free = make_case("dome", "1", seed=1, settings=DEFAULTS.with_(fold_limit=None))
    assert with_fold_limit(free, GenerateOptions()) is free


def test_a_dead_end_restarts_the_chain_within_the_fold_limit(monkeypatch):
    """The first DOF-1 candidate's path is made to turn back; with ``restart_after`` 1 the
    chain is given up, its solutions after the initial one retracted, and the new chain
    keeps every free crease within a limit of 40 degrees (pattern 1 folds to about 50 on
    the way) down to a DOF-1 design that deploys."""
    real = generation.trace_path
    calls = []

    def first_turns_back(pattern, **kwargs):
        path = real(pattern, **kwargs)
        calls.append(path)
        if len(calls) == 1:
            return dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        return path

    monkeypatch.setattr(generation, "trace_path", first_turns_back)
    limit = 40.0
    settings = DEFAULTS.with_(restart_after=1, fold_limit=math.radians(limit))
    case = make_case("bezier", "1", seed=1, settings=settings)
    run = generate(case, criterion="s", seed=1, lookahead=True, deform=False)

    first = [a for a in run.attempts if not a.fold_bound]
    second = [a for a in run.attempts if a.fold_bound]
    # the made-up dead end (its second-order test may find it rigid too)
    assert first[-1].outcome in (AttemptOutcome.PATH, AttemptOutcome.RIGID)
    assert first[0].outcome is AttemptOutcome.ACCEPTED  # the initial shape is kept
    retracted = [a for a in first[1:] if a.outcome is AttemptOutcome.DEAD_END]
    assert len(retracted) == len(first) - 2 == run.n_backtrack
    assert second and all(a.index > first[-1].index for a in second)
    assert run.stop is Stop.TARGET_REACHED and run.final is not None
    assert run.final.path is not None and run.final.path.deploys
    tol = math.degrees(math.sqrt(2 * DEFAULTS.solver.constraint_tol)) + 1e-6
    for solution in run.solutions[1:]:  # the new chain's
        assert _largest_fold_deg(solution.result.pattern) <= limit + tol


def test_a_chain_that_deploys_is_not_restarted():
    run = generate(make_case("dome", "1", seed=1), target_dof=12, deform=False)
    assert run.final_dof == 12
    assert not any(a.fold_bound for a in run.attempts)


def test_the_command_line_limit_in_degrees():
    assert SettingsOptions().settings().generation.fold_limit == DEFAULTS.generation.fold_limit
    assert SettingsOptions(fold_limit=0).settings().generation.fold_limit is None
    assert SettingsOptions(fold_limit=90).settings().generation.fold_limit == pytest.approx(
        math.pi / 2
    )
    with pytest.raises(RigidfoldError, match="fold_limit must lie in"):
        SettingsOptions(fold_limit=200).settings()
