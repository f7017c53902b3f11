"""Frame model and mechanism analysis: DOF counts, modes, locks (Section 4.1, Appendix A)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import degree_n_vertex, folded_grid
from rigidfold.frame import FrameModel
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze, kinematics
from rigidfold.patterns import miura


def _same_subspace(a, b):
    return np.abs(a @ a.T - b @ b.T).max()


@pytest.mark.parametrize("n", [4, 5, 6, 7, 8])
@pytest.mark.parametrize("method", ["kinematic", "frame"])
def test_degree_n_vertex_has_n_minus_3_dof(n, method):
    mech = analyze(degree_n_vertex(n, seed=n), method=method)
    assert mech.dof == n - 3
    assert not mech.has_lock


@pytest.mark.parametrize(("nx", "ny"), [(2, 2), (3, 2), (4, 5), (6, 6)])
def test_folded_miura_ori_has_one_dof_and_no_lock(nx, ny):
    mech = analyze(miura(nx, ny))
    assert mech.dof == 1
    assert not mech.has_lock
    assert np.all(mech.rotation_norms > 0)


def test_miura_frame_method_agrees():
    shape = miura(3, 3)
    a, b = analyze(shape), analyze(shape, method="frame")
    assert a.dof == b.dof == 1
    assert _same_subspace(a.H, b.H) < 1e-10


@pytest.mark.parametrize(("pattern", "dof"), [("1", 21), ("2", 21), ("11", 37)])
def test_initial_dof_of_paper_patterns(pattern, dof):
    case = case_from_specs("bezier", pattern, seed=3)
    mech = analyze(case.pattern)
    assert mech.dof == dof == case.pattern.generic_dof
    assert not mech.has_lock


def test_fixing_one_crease_of_degree4_vertex_locks_the_others():
    shape = degree_n_vertex(4, seed=4)
    free = analyze(shape)
    assert free.dof == 1
    fixed = np.zeros(shape.n_edges, dtype=bool)
    fixed[shape.interior_edges[0]] = True
    mech = analyze(shape.with_fixed(fixed))
    assert mech.dof == 0
    assert mech.locked.sum() == 3
    assert set(mech.locked_creases) == set(shape.interior_edges[1:])


@pytest.mark.parametrize("seed", range(6))
def test_frame_dof_equals_independent_kinematic_count(seed):
    """Frame model (paper, SVD of S) against the vertex-velocity count, random shapes."""
    rng = np.random.default_rng(seed)
    shape = folded_grid(4 + seed % 2, amplitude=0.3, seed=seed)
    fixed = np.zeros(shape.n_edges, dtype=bool)
    fixed[rng.choice(shape.interior_edges, 1 + seed % 3, replace=False)] = True
    shape = shape.with_fixed(fixed)
    a, b = analyze(shape), analyze(shape, method="frame")
    assert a.dof == b.dof
    assert _same_subspace(a.H, b.H) < 1e-9
    assert np.array_equal(a.locked, b.locked)


def test_modes_are_orthonormal_and_compatible():
    shape = folded_grid(5, amplitude=0.2, seed=9)
    mech = analyze(shape)
    S = FrameModel.from_pattern(shape).compatibility_matrix()
    assert np.allclose(mech.H.T @ mech.H, np.eye(mech.dof), atol=1e-12)
    assert np.abs(S @ mech.H).max() < 1e-10
    assert mech.H.shape == (6 * mech.frame.n_nodes - 6 + mech.frame.n_hinges, mech.dof)
    assert np.allclose(mech.H_phi, mech.H[-mech.frame.n_hinges :])


def test_hinge_rotation_is_fold_angle_rate():
    """phi_j of a mode equals the rate of the FOLD fold angle (valley positive)."""
    shape = degree_n_vertex(5, seed=2)
    mech = analyze(shape)
    L = mech.frame
    C = kinematics.constraint_matrix(shape, L.support_face).toarray()
    _, _, vt = np.linalg.svd(C)
    xdot = vt[-1]
    Lmap = kinematics.frame_map(L)
    phi = (Lmap @ xdot)[-L.n_hinges :]
    h = 1e-6
    plus = shape.with_coords(shape.coords + h * xdot.reshape(-1, 3))
    minus = shape.with_coords(shape.coords - h * xdot.reshape(-1, 3))
    rate = (plus.fold_angles - minus.fold_angles)[L.hinges] / (2 * h)
    assert np.allclose(phi, rate, rtol=1e-5, atol=1e-8)
    assert np.abs(rate).max() > 0


def test_frame_sizes_and_hinges():
    shape = degree_n_vertex(6)
    frame = FrameModel.from_pattern(shape)
    assert frame.n_nodes == shape.n_edges + shape.n_faces
    assert frame.n_members == 3 * shape.n_faces
    assert frame.n_hinges == 6
    assert (frame.member_hinge >= 0).sum() == 6  # one hinged member end per free crease
    S = frame.compatibility_matrix()
    assert S.shape == (6 * frame.n_members, 6 * frame.n_nodes - 6 + 6)


def test_bad_method_and_support():
    shape = degree_n_vertex(5)
    with pytest.raises(ValueError, match="unknown mechanism method"):
        analyze(shape, method="magic")
    with pytest.raises(ValueError, match="support face 99"):
        FrameModel.from_pattern(shape, support_face=99)
