"""One honest DOF with a clear gap (issue 49, item 5): with the deployability check the
search counts the singular values of the constraints below ``dof_gap`` times the rank
threshold (near-mechanisms are mechanisms of the built design), one count everywhere; the
paper's Step 5 keeps the paper's count."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.frame.model import default_support_face
from rigidfold.generate import GenerateOptions, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.mechanism.margin import DofMargin, dof_margin
from rigidfold.selection import rank_candidates, score_creases


def _margin(**kw) -> DofMargin:
    base = dict(
        dof=1, zero_max=1e-16, nonzero_min=0.1, threshold=1e-9, gap=1e3, near=0, method="dense"
    )
    return DofMargin(**(base | kw))


def test_the_paper_count_with_a_near_value_is_not_clear_and_says_so():
    near = _margin(nonzero_min=1.7e-9, near=1, dof_with_gap=2)
    assert not near.clear
    assert "only without a clear gap" in near.message and "DOF 2" in near.message
    assert _margin(dof_with_gap=1).clear


def test_the_gap_count_is_clear_where_the_search_counted_the_same():
    counted = _margin(count="gap", dof=2, zero_max=9.4e-9, nonzero_min=1e-3, dof_with_gap=2)
    assert counted.limit == pytest.approx(1e-6)
    assert counted.clear and "clear gap" in counted.message
    other = _margin(count="gap", dof=2, zero_max=9.4e-9, dof_with_gap=2, counted=1)
    assert not other.clear and "the search counted DOF 1" in other.message


def test_the_dof_count_setting_is_checked():
    assert DEFAULTS.mechanism.dof_count == "auto"
    with pytest.raises(RigidfoldError, match="dof_count"):
        DEFAULTS.with_(dof_count="loose")


@pytest.fixture(scope="module")
def checked_run():
    return generate(case_from_specs("bezier", "1", seed=1), GenerateOptions(deform=False))


def test_one_count_everywhere_with_the_deployability_check(checked_run):
    """Every solution's DOF (its file name, final_dof) is the number of singular values of
    its constraints below dof_gap times the rank threshold, and the final design's margin
    says the same count with its gap."""
    run = checked_run
    assert run.dof_margin is not None and run.dof_margin["count"] == "gap"
    assert run.dof_margin["dof"] == run.final_dof == run.dof_margin["counted"]
    assert run.dof_margin["clear"]
    gap = DEFAULTS.mechanism.rank_tol * DEFAULTS.mechanism.dof_gap
    for solution in run.solutions:
        shape = solution.result.pattern
        m = dof_margin(shape, default_support_face(shape), count="gap")
        assert m.dof == solution.mechanism.dof == m.dof_with_gap
        assert m.nonzero_min >= gap  # the next singular value is past the gap


def test_the_papers_step_5_keeps_the_papers_count():
    run = generate(case_from_specs("bezier", "1", seed=1), deploy_check=False, target_dof=15)
    assert run.dof_margin is not None and run.dof_margin["count"] == "threshold"
    for solution in run.solutions:
        assert solution.mechanism.dof == analyze(solution.result.pattern).dof


def test_a_flat_vertex_is_a_mechanism_whose_creases_rank_first():
    """An interior vertex whose free creases are all flat moves out of its plane at first
    order (an infinitesimal mechanism); its creases, flat already, cost no change of shape
    to fix and are the criterion's first candidates."""
    case = case_from_specs("dome", "grid:4x4", size="3x3")
    shape = case.pattern
    coords = shape.coords.copy()
    interior = np.setdiff1d(np.arange(shape.n_vertices), shape.boundary_vertices)
    v = int(interior[0])
    spokes = np.flatnonzero((shape.edges == v).any(axis=1))
    star = np.unique(np.concatenate([shape.edges[spokes].ravel(), [v]]))
    coords[star, 2] = coords[v, 2]
    flat = shape.with_coords(coords)
    assert np.abs(flat.fold_angles[spokes]).max() < 1e-12
    settings = DEFAULTS.with_(mechanism_rank_tol=1e-6)  # the search's gap count
    mech = analyze(flat, settings=settings)
    ranked = rank_candidates(score_creases(mech, settings=settings), "s")
    moving = set(mech.hinges[mech.rotation_norms > 1e-6 * mech.rotation_norms.max()].tolist())
    first = [int(g[0]) for g, _ in ranked[: len(set(spokes.tolist()) & moving)]]
    assert set(first) <= set(spokes.tolist()) | {
        int(e) for e in mech.hinges if abs(flat.fold_angles[e]) < 1e-12
    }
    assert set(spokes.tolist()) & moving & set(first)


def test_the_command_line_chooses_the_count(tmp_path, capsys):
    """``--dof-count threshold`` reaches the run (the final design's margin says which count)
    and an unknown count is refused in one line, before anything is written."""
    pattern = Path(__file__).parent / "data" / "origami_simulator" / "test.svg"
    argv = ["generate", "--surface", "dome", "--pattern", str(pattern), "--quiet"]
    out = tmp_path / "t"
    assert main([*argv, "--no-report", "--dof-count", "threshold", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["dof_margin"]["count"] == "threshold" and summary["final_dof"] == 1
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:
        main([*argv, "--dof-count", "loose", "--out", str(tmp_path / "b")])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "--dof-count" in err and "loose" in err
    assert not (tmp_path / "b").exists()
