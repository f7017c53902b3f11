"""A child's solve in a design search ends at ``Settings.generation.child_max_iter``
(the first solve and the paper's Step 5 keep the solver's limit of the settings)."""

from __future__ import annotations

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.optimize import FormFindingProblem, Status


@pytest.fixture
def limits(monkeypatch):
    """The ``max_iter`` of every solve of (6), in order."""
    seen: list[int | None] = []
    solve = FormFindingProblem.solve

    def recording(self, *args, max_iter=None, **kwargs):
        seen.append(max_iter)
        return solve(self, *args, max_iter=max_iter, **kwargs)

    monkeypatch.setattr(FormFindingProblem, "solve", recording)
    return seen


@pytest.mark.parametrize("deploy_check", [True, False])
def test_children_are_solved_to_their_own_limit(limits, deploy_check):
    settings = DEFAULTS.with_(child_max_iter=77)
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    run = generate(case, GenerateOptions(criterion="shat", seed=1, deploy_check=deploy_check))
    assert run.solutions and len(limits) >= 3
    assert limits[0] is None  # the first solve, from the target surface
    assert set(limits[1:]) == ({77} if deploy_check else {None})


def test_a_child_at_its_limit_is_not_a_solution():
    """Children of IPOPT alone (``projection`` "large" on a small pattern) allowed two
    iterations: those it does not solve in two end at the limit, as attempts that fail
    (N_exceed), never as solutions."""
    settings = DEFAULTS.with_(child_max_iter=2)
    case = case_from_specs("bezier", "1", seed=1, settings=settings)
    run = generate(case, GenerateOptions(criterion="shat", seed=1, projection="large"))
    children = run.attempts[1:]
    limited = [a for a in children if a.status is Status.ITERATION_LIMIT]
    assert limited and all(a.iterations == 2 for a in limited)
    assert all(a.outcome is AttemptOutcome.EXCEED for a in limited)
    assert run.n_exceed >= len(limited)
    assert all(a.iterations <= 2 for a in children)
