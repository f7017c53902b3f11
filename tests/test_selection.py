"""Pseudo stiffness, eigen-derivatives (27)-(30) and the selection scores (32)-(38)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import folded_grid
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.mechanism.stiffness import PseudoStiffness, hinge_stiffness
from rigidfold.selection import crease_groups, rank_candidates, score_creases


@pytest.fixture(scope="module")
def mechanism():
    return analyze(folded_grid(5, amplitude=0.25, seed=11))


def _aligned(A, B):
    """B's columns with signs flipped to match A's."""
    return B * np.sign(np.sum(A * B, axis=0))


def test_hinge_stiffness_range_and_seed():
    K = hinge_stiffness(1000, seed=1)
    assert np.all(np.abs(K - 1e-3) <= 0.5e-6)
    assert np.array_equal(K, hinge_stiffness(1000, seed=1))


def test_pseudo_stiffness_identities(mechanism):
    K = hinge_stiffness(mechanism.frame.n_hinges, seed=0)
    st = PseudoStiffness(mechanism.H_phi, K)
    lam, Phi = st.eigenvalues, st.Phi
    assert np.allclose(Phi.T @ (K[:, None] * Phi), np.diag(lam), atol=1e-15)  # Eq. (25)
    hat = st.normalised_modes()
    assert np.allclose(hat.T @ hat, np.eye(len(lam)), atol=1e-3)  # Eq. (35), K_j ~ K


@pytest.mark.parametrize("j", [0, 3, 7])
def test_eigen_derivatives_match_finite_differences(mechanism, j):
    K = hinge_stiffness(mechanism.frame.n_hinges, seed=2)
    base = PseudoStiffness(mechanism.H_phi, K)
    h = 1e-9
    dK = np.zeros_like(K)
    dK[j] = h
    plus, minus = PseudoStiffness(mechanism.H_phi, K + dK), PseudoStiffness(mechanism.H_phi, K - dK)
    fd_lam = (plus.eigenvalues - minus.eigenvalues) / (2 * h)
    assert np.allclose(base.eigenvalue_derivatives()[j], fd_lam, rtol=1e-5, atol=1e-9)  # (27)
    A = base.eigenvectors
    fd_alpha = (_aligned(A, plus.eigenvectors) - _aligned(A, minus.eigenvectors)) / (2 * h)
    assert np.allclose(base.eigenvector_derivatives(j), fd_alpha, rtol=1e-4, atol=1e-3)  # (28)
    fd_phi = mechanism.H_phi @ fd_alpha
    assert np.allclose(base.rotation_derivatives(j), fd_phi, rtol=1e-4, atol=1e-3)  # (29)
    # Eq. (30): the same derivative written with sqrt(d lambda / d K_j)
    lam, Phi = base.eigenvalues, base.Phi
    dl = base.eigenvalue_derivatives()[j]
    for i in range(len(lam)):
        other = np.arange(len(lam)) != i
        eq30 = (
            -np.sign(Phi[j, i])
            * np.sqrt(dl[i])
            * (
                (np.sign(Phi[j, other]) * np.sqrt(dl[other]) / (lam[other] - lam[i]))
                * Phi[:, other]
            ).sum(axis=1)
        )
        assert np.allclose(base.rotation_derivatives(j)[:, i], eq30, rtol=1e-8, atol=1e-12)


def test_scores_are_shares_and_ratios(mechanism):
    sc = score_creases(mechanism, seed=0)
    for s in (sc.S_S, sc.S_F, sc.S_F_hat):
        assert s.sum() == pytest.approx(1.0)
        assert np.all(s >= 0)
    assert np.allclose(sc.S, sc.S_S / sc.S_F)
    assert np.allclose(sc.S_hat, sc.S_S / sc.S_F_hat)
    rho = np.abs(mechanism.pattern.fold_angles[mechanism.hinges])
    assert np.allclose(sc.S_S, rho / rho.sum())


@pytest.mark.parametrize("criterion", ["shat", "s", "ss"])
def test_ranking_lowest_score_first(mechanism, criterion):
    sc = score_creases(mechanism, seed=0)
    ranked = rank_candidates(sc, criterion)
    values = [score for _, score in ranked]
    assert values == sorted(values)
    assert len(ranked) == mechanism.frame.n_hinges


def test_random_ranking_is_a_seeded_permutation(mechanism):
    sc = score_creases(mechanism, seed=0)
    a = rank_candidates(sc, "random", rng=np.random.default_rng(5))
    b = rank_candidates(sc, "random", rng=np.random.default_rng(5))
    assert [g for g, _ in a] == [g for g, _ in b]
    assert sorted(g for g, _ in a) == sorted((int(e),) for e in mechanism.hinges)


@pytest.mark.parametrize("surface", ["dome", "hp"])
def test_mirror_groups_have_two_or_four_creases(surface):
    case = case_from_specs(surface, "11", symmetric=True)
    groups = crease_groups(case.pattern, case.planes)
    assert {len(g) for g in groups} <= {1, 2, 4}
    assert sorted(e for g in groups for e in g) == case.pattern.interior_edges.tolist()
    mech = analyze(case.pattern)
    ranked = rank_candidates(score_creases(mech), "shat", groups=groups)
    assert len(ranked) == len(groups)


def test_unknown_criterion(mechanism):
    with pytest.raises(ValueError, match="unknown criterion"):
        score_creases(mechanism).of("best")
