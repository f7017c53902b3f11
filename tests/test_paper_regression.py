"""Example regression tests against the paper's set-up (Section 6, Table 4).

The paper's own target surfaces are in missing figures, so these tests check the behaviour
the issue asks for: IPOPT accepts (F <= 1e-7, constraints met to 1e-8) on at least 18 of 20
random Bezier surfaces for each pattern, and on the dome and the HP with and without symmetry.
"""

from __future__ import annotations

import pytest

from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs

SEEDS = range(20)


@pytest.mark.slow
@pytest.mark.parametrize("pattern", ["1", "2"])
def test_ipopt_accepts_on_20_bezier_surfaces(pattern):
    accepted = []
    for seed in SEEDS:
        result = case_from_specs("bezier", pattern, seed=seed).problem().solve()
        ok = (
            result.F <= DEFAULTS.design.f_tol
            and result.max_violation <= DEFAULTS.solver.constraint_tol
        )
        assert ok == result.converged
        accepted.append(ok)
    assert sum(accepted) >= 18, f"accepted {sum(accepted)} of 20"


@pytest.mark.slow
@pytest.mark.parametrize("surface", ["dome", "hp"])
@pytest.mark.parametrize("symmetric", [True, False], ids=["sym", "asym"])
def test_ipopt_accepts_dome_and_hp(surface, symmetric):
    case = case_from_specs(surface, "11", symmetric=symmetric)
    result = case.problem().solve()
    assert result.converged, result.message
    assert result.n_variables == (83 if symmetric else 315)
    assert result.max_violation <= DEFAULTS.solver.constraint_tol


@pytest.mark.slow
def test_generate_shat_reaches_one_dof_on_20_bezier_surfaces():
    """Section 6.3 with S-hat: at least 18 of 20 runs reach DOF 1; saved shapes are sound."""
    from conftest import paper_generate as generate

    reached = 0
    for seed in SEEDS:
        run = generate(case_from_specs("bezier", "1", seed=seed), criterion="shat", seed=seed)
        reached += run.final_dof == 1
        for sol in run.solutions:
            assert sol.result.F <= DEFAULTS.design.f_tol
            assert sol.result.max_violation <= DEFAULTS.solver.constraint_tol
            assert not sol.mechanism.has_lock
            assert sol.mechanism.dof >= 1
    assert reached >= 18, f"DOF 1 reached on {reached} of 20"
