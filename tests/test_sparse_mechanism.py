"""The sparse mechanism analysis against the dense reference (issue 19).

On every kind of shape the suite uses (paper patterns on the built-in surfaces, grid and mesh
specs, FOLD and SVG files, degree-n vertices, Miura-ori, random grids with fixed creases,
flat sheets, the shapes of a generation run): the same DOF, rank and locked creases, the same
span of the modes H (the sine of the largest principal angle), the same hinge rotations up to
an orthogonal change of basis, and the same basis-independent criterion values.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from conftest import degree_n_vertex, folded_grid
from conftest import paper_generate as generate
from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs
from rigidfold.io.fold import pattern_from_fold
from rigidfold.mechanism import (
    analysis_bytes,
    analysis_memory,
    analyze,
    check_analysis_size,
    chosen_method,
)
from rigidfold.mechanism import sparse as sparse_module
from rigidfold.mechanism.stiffness import hinge_stiffness
from rigidfold.mesh import CreasePattern
from rigidfold.patterns import grid, miura
from rigidfold.selection import score_creases

DATA = Path(__file__).parent / "data"
HEXAGON = ";".join(
    f"{3 * math.cos(k * math.pi / 3):.6f},{3 * math.sin(k * math.pi / 3):.6f}" for k in range(6)
)


def _with_random_fixed(shape: CreasePattern, count: int, seed: int) -> CreasePattern:
    rng = np.random.default_rng(seed)
    fixed = shape.fixed.copy()
    fixed[rng.choice(shape.interior_edges, count, replace=False)] = True
    return shape.with_fixed(fixed)


def _flat_grid(n: int) -> CreasePattern:
    xy, faces = grid(n, n, 1.0, 1.0, "alternate")
    return CreasePattern.from_faces(xy, faces)


SHAPES = {
    **{f"degree-{n}": (lambda n=n: degree_n_vertex(n, seed=n)) for n in range(4, 9)},
    "degree-4-one-fixed": lambda: _with_random_fixed(degree_n_vertex(4, seed=4), 1, 0),
    **{
        f"miura-{nx}x{ny}": (lambda nx=nx, ny=ny: miura(nx, ny))
        for nx, ny in [(2, 2), (3, 2), (3, 3), (4, 5), (6, 6)]
    },
    **{
        f"random-grid-fixed-{s}": (
            lambda s=s: _with_random_fixed(folded_grid(4 + s % 4, 0.3, s), 1 + s % 5, s)
        )
        for s in range(8)
    },
    "flat-sheet": lambda: _flat_grid(6),
    "bezier-1-seed-0": lambda: case_from_specs("bezier", "1", seed=0).pattern,
    "bezier-1-seed-1-fixed": lambda: _with_random_fixed(
        case_from_specs("bezier", "1", seed=1).pattern, 12, 1
    ),
    "bezier-1p": lambda: case_from_specs("bezier", "1p", seed=2).pattern,
    "bezier-2": lambda: case_from_specs("bezier", "2", seed=0).pattern,
    "dome-11": lambda: case_from_specs("dome", "11").pattern,
    "hp-11-fixed": lambda: _with_random_fixed(case_from_specs("hp", "11").pattern, 30, 3),
    "dome-grid-9x7": lambda: case_from_specs("dome", "grid:9x7", size="6x4").pattern,
    "hp-mesh-hexagon": lambda: case_from_specs("hp", f"mesh:{HEXAGON}", edge_length=1.0).pattern,
    "dome-sym-dof1.fold": lambda: pattern_from_fold(DATA / "dome_sym_dof1.fold"),
    "dome-sym-dof13.fold": lambda: pattern_from_fold(DATA / "dome_sym_dof13.fold"),
    "dome-miura-ori.svg": lambda: (
        case_from_specs(
            "dome", str(DATA / "origami_simulator" / "miura-ori.svg"), rigid_panels=True
        ).pattern
    ),
    "dome-squaretwist.svg": lambda: (
        case_from_specs("dome", str(DATA / "origami_simulator" / "singlesquaretwist.svg")).pattern
    ),
}


def assert_same_analysis(shape: CreasePattern, support_face: int | None = None) -> None:
    """The sparse analysis of ``shape`` agrees with the dense one (see the module's text)."""
    dense = analyze(shape, method="kinematic", support_face=support_face)
    sparse = analyze(shape, method="sparse", support_face=support_face)
    assert sparse.dof == dense.dof
    assert sparse.rank == dense.rank
    assert np.array_equal(sparse.locked, dense.locked)
    if dense.dof == 0:
        return
    # span of H: the part of the sparse modes outside the dense ones' span
    outside = sparse.H - dense.H @ (dense.H.T @ sparse.H)
    assert np.linalg.norm(outside, 2) < 1e-8
    assert np.allclose(sparse.H.T @ sparse.H, np.eye(sparse.dof), atol=1e-10)
    # hinge rotations: H_phi of one basis times an orthogonal d x d matrix
    T = dense.H.T @ sparse.H
    assert np.allclose(T.T @ T, np.eye(sparse.dof), atol=1e-8)
    assert np.allclose(dense.H_phi @ T, sparse.H_phi, atol=1e-8)
    assert np.allclose(sparse.rotation_norms, dense.rotation_norms, atol=1e-8)
    # the criteria (32)-(38) do not depend on the basis
    K = hinge_stiffness(dense.frame.n_hinges, 5)
    a, b = score_creases(dense, K=K), score_creases(sparse, K=K)
    for name in ("S_S", "S_F", "S_F_hat"):
        assert np.allclose(getattr(a, name), getattr(b, name), rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("name", list(SHAPES))
def test_sparse_analysis_matches_dense(name):
    assert_same_analysis(SHAPES[name]())


def test_sparse_analysis_matches_dense_for_another_support():
    shape = _with_random_fixed(folded_grid(6, 0.2, 4), 3, 4)
    assert_same_analysis(shape, support_face=0)


def test_sparse_analysis_matches_dense_along_a_generation():
    shapes: list[CreasePattern] = []
    generate(
        case_from_specs("bezier", "1", seed=1),
        criterion="s",
        on_solution=lambda run, sol: shapes.append(sol.result.pattern),
    )
    assert len(shapes) > 10 and shapes[-1].fixed.sum() > 10
    for shape in shapes:
        assert_same_analysis(shape)


def test_flat_sheet_grows_the_subspace():
    """A flat sheet has far more modes than n - k (every interior vertex moves out of its
    plane): the first subspace (n - k + oversampling columns) is too small and doubles."""
    shape = _flat_grid(6)
    mech = analyze(shape, method="sparse")
    assert mech.dof == 3 * shape.n_vertices - shape.n_edges - 6 + len(shape.interior_vertices)
    assert (
        mech.dof > 3 * shape.n_vertices - shape.n_edges - 6 + DEFAULTS.mechanism.sparse_oversampling
    )
    assert_same_analysis(shape)


def test_auto_method_by_size():
    small, large = (
        case_from_specs("dome", "11").pattern,
        case_from_specs("dome", "grid:21x21").pattern,
    )
    assert chosen_method(small, "auto") == "kinematic"
    assert chosen_method(large, "auto") == "sparse"
    assert chosen_method(large, "frame") == "frame"
    settings = DEFAULTS.with_(sparse_analysis_vertices=100)
    assert chosen_method(small, "auto", settings) == "sparse"
    auto, sparse = analyze(small, settings=settings), analyze(small, method="sparse")
    assert np.array_equal(auto.rank_values, sparse.rank_values)
    with pytest.raises(ValueError, match="unknown mechanism method 'qr'"):
        chosen_method(small, "qr")


def test_memory_estimate_follows_the_method():
    """A large grid that the dense analysis would refuse passes with the sparse one."""
    big = case_from_specs("dome", "grid:101x101").pattern
    rows = big.n_edges + 9
    assert analysis_memory(big, "kinematic") == analysis_bytes(rows, 3 * big.n_vertices)
    assert analysis_memory(big, "auto") == analysis_memory(big, "sparse") < 2 * 2**30
    check_analysis_size(big)
    with pytest.raises(ValueError, match=r"needs about 20\.8 GiB, more than the limit of 8 GiB"):
        check_analysis_size(big, method="kinematic")
    with pytest.raises(ValueError, match=r"Settings\.limits\.max_analysis_bytes"):
        check_analysis_size(big, DEFAULTS.with_(max_analysis_bytes=2**20))


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("sparse_shift", 0.0),
        ("sparse_shift", 1.0),
        ("sparse_oversampling", 1),
        ("sparse_iterations", 0),
        ("sparse_analysis_vertices", 2.5),
    ],
)
def test_sparse_settings_are_checked(field, value):
    with pytest.raises(ValueError, match=field):
        DEFAULTS.with_(**{field: value})


@pytest.mark.parametrize("name", ["hp-11-fixed", "dome-sym-dof13.fold"])
def test_a_narrow_span_grows_by_what_it_needs(name, monkeypatch):
    """With an oversampling of 6, the first subspace of these shapes has one or two columns
    fewer than it needs to spare half the oversampling, but not a full span: it grows by what
    leaves room for its span and the oversampling (not twice), and agrees with the dense."""
    spans: list[tuple[int, int]] = []
    real = sparse_module._span

    def recording(W: np.ndarray) -> np.ndarray:
        Y = real(W)
        spans.append((W.shape[1], Y.shape[1]))
        return Y

    monkeypatch.setattr(sparse_module, "_span", recording)
    settings = DEFAULTS.with_(sparse_oversampling=6)
    shape = SHAPES[name]()
    sparse = analyze(shape, method="sparse", settings=settings)
    dense = analyze(shape, method="kinematic", settings=settings)
    (m, span), (grown, _) = spans
    assert m - 3 < span < m
    assert grown == span + 6
    assert sparse.dof == dense.dof and sparse.rank == dense.rank
    assert np.array_equal(sparse.locked, dense.locked)
    outside = sparse.H - dense.H @ (dense.H.T @ sparse.H)
    assert np.linalg.norm(outside, 2) < 1e-8
