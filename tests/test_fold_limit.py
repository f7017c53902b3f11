"""The fold limit of a run with the deployability check (issue 40): bound (12) at
``Settings.generation.fold_limit`` on every solve, so that no solution folds panels onto
each other."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigidfold.case import make_case
from rigidfold.case_options import SettingsOptions
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import generate, with_fold_limit
from rigidfold.generate_options import GenerateOptions


def _largest_fold_deg(pattern) -> float:
    free = ~pattern.fixed & ~pattern.is_boundary_edge
    return float(np.degrees(np.abs(pattern.fold_angles[free]).max()))


def test_the_limit_is_bound_12_with_the_check_only():
    case = make_case("dome", "1", seed=1)
    bounded = with_fold_limit(case, GenerateOptions())
    assert bounded.settings.design.rho_bar == DEFAULTS.generation.fold_limit
    assert bounded.pattern is case.pattern and bounded.surface is case.surface
    # the paper's Step 5 (no check), the user's own bound (12), no limit: the case itself
    assert with_fold_limit(case, GenerateOptions(deploy_check=False)) is case
    own = make_case("dome", "1", seed=1, settings=DEFAULTS.with_(rho_bar=math.radians(90)))
    assert with_fold_limit(own, GenerateOptions()) is own
    free = make_case("dome", "1", seed=1, settings=DEFAULTS.with_(fold_limit=None))
    assert with_fold_limit(free, GenerateOptions()) is free


def test_every_solution_keeps_its_folds_within_the_limit():
    """Pattern 1 on the dome folds its creases to about 50 degrees on the way to DOF 12;
    with a limit of 25 degrees every solution stays within it (to the constraint
    tolerance of the solver) and the run still reaches its target."""
    limit = 25.0
    runs = {}
    for name, value in (("free", None), ("bounded", math.radians(limit))):
        case = make_case("dome", "1", seed=1, settings=DEFAULTS.with_(fold_limit=value))
        runs[name] = generate(case, target_dof=12, deform=False)
    assert max(_largest_fold_deg(s.result.pattern) for s in runs["free"].solutions) > limit
    bounded = runs["bounded"]
    assert bounded.final_dof == 12
    tol = math.degrees(math.sqrt(2 * DEFAULTS.solver.constraint_tol)) + 1e-6
    for solution in bounded.solutions:
        assert _largest_fold_deg(solution.result.pattern) <= limit + tol


def test_the_command_line_limit_in_degrees():
    assert SettingsOptions().settings().generation.fold_limit == DEFAULTS.generation.fold_limit
    assert SettingsOptions(fold_limit=0).settings().generation.fold_limit is None
    assert SettingsOptions(fold_limit=90).settings().generation.fold_limit == pytest.approx(
        math.pi / 2
    )
    with pytest.raises(RigidfoldError, match="fold_limit must lie in"):
        SettingsOptions(fold_limit=200).settings()
