"""Step 8: development diagrams (problem (13)) and the overlap / flip counters."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.distance import pdist

from conftest import degree_n_vertex, folded_grid
from conftest import paper_generate as generate
from rigidfold.config import DEFAULTS
from rigidfold.develop import Development, count_flipped, count_overlaps, develop
from rigidfold.develop import diagram as diagram_module
from rigidfold.generate.specs import case_from_specs
from rigidfold.patterns.miura import miura


def diagram_lengths_of(xy: np.ndarray, pattern) -> np.ndarray:
    d = xy[pattern.edges[:, 1]] - xy[pattern.edges[:, 0]]
    return np.hypot(d[:, 0], d[:, 1])


def diagram_lengths(dev: Development, pattern) -> np.ndarray:
    return diagram_lengths_of(dev.coords2d, pattern)


def assert_valid(dev: Development, pattern, D_max: float) -> None:
    assert dev.status == "converged", dev.message
    assert dev.D < D_max
    assert dev.flipped == 0
    assert dev.overlaps == 0
    assert dev.coords2d.shape == (pattern.n_vertices, 2)
    assert np.isfinite(dev.coords2d).all()


@pytest.fixture(scope="module")
def pattern1_shape():
    result = case_from_specs("bezier", "1", seed=1).problem().solve()
    assert result.F < 1e-10
    return result.pattern


# ------------------------------------------------------------------ Miura-ori
def flat_miura(nx: int, ny: int, height: float, length=1.0, width=1.0, offset=0.4):
    """The crease pattern (height 0) of ``miura(nx, ny, height=height)``.

    Folding changes the plan dimensions: the zigzag segments (length, 0, +-height) are
    straight in the flat state, with length L' = |(length, 0, height)|; the other sides keep
    their length |(offset, width)| and their dot product length * offset with them.
    """
    L = np.hypot(length, height)
    o = length * offset / L
    W = np.sqrt(offset**2 + width**2 - o**2)
    return miura(nx, ny, length=L, width=W, offset=o, height=0.0)


@pytest.mark.parametrize(
    ("nx", "ny", "height"), [(4, 3, 0.3), (6, 6, 0.5), (3, 5, 0.8), (2, 2, 0.1)]
)
def test_folded_miura_develops_to_the_flat_pattern(nx, ny, height):
    folded = miura(nx, ny, height=height)
    dev = develop(folded)
    assert_valid(dev, folded, 1e-10)
    np.testing.assert_allclose(diagram_lengths(dev, folded), folded.edge_lengths, rtol=1e-5)
    assert dev.max_length_error < 1e-5
    flat = flat_miura(nx, ny, height)
    np.testing.assert_allclose(flat.edge_lengths, folded.edge_lengths, rtol=1e-12)
    np.testing.assert_allclose(pdist(dev.coords2d), pdist(flat.coords[:, :2]), atol=1e-5)


def test_flat_pattern_is_its_own_diagram():
    flat = miura(3, 3, height=0.0)
    dev = develop(flat)
    assert_valid(dev, flat, 1e-14)
    np.testing.assert_allclose(pdist(dev.coords2d), pdist(flat.coords[:, :2]), atol=1e-6)


def test_gauge_fixes_the_reference_edge():
    pattern = miura(4, 3)
    dev = develop(pattern)
    k = dev.reference_edge
    assert pattern.is_boundary_edge[k]
    boundary = pattern.is_boundary_edge
    assert pattern.edge_lengths[k] == pattern.edge_lengths[boundary].max()
    a, b = pattern.edges[k]
    assert tuple(dev.coords2d[a]) == (0.0, 0.0)
    assert dev.coords2d[b, 1] == 0.0
    assert dev.coords2d[b, 0] > 0.0


def test_as_pattern_gives_the_flat_crease_pattern():
    folded = miura(3, 2, height=0.4)
    dev = develop(folded)
    flat = dev.as_pattern(folded)
    assert np.all(flat.coords[:, 2] == 0.0)
    np.testing.assert_array_equal(flat.faces, folded.faces)
    np.testing.assert_array_equal(flat.fixed, folded.fixed)
    np.testing.assert_allclose(flat.edge_lengths, folded.edge_lengths, rtol=1e-5)
    with pytest.raises(ValueError, match="vertices"):
        dev.as_pattern(miura(2, 2))


def test_result_is_read_only():
    dev = develop(miura(2, 2))
    with pytest.raises(ValueError):
        dev.coords2d[0, 0] = 1.0


# ------------------------------------------------------------------ optimised shapes
def test_optimised_pattern1_shape(pattern1_shape):
    dev = develop(pattern1_shape)
    assert_valid(dev, pattern1_shape, 1e-8)
    assert dev.max_length_error < 1e-3
    assert dev.iterations > 0
    assert dev.wall_time > 0


def test_shape_with_fixed_creases():
    run = generate(case_from_specs("bezier", "1", seed=1), target_dof=15)
    shape = run.solutions[-1].result.pattern
    assert shape.fixed.any()
    dev = develop(shape)
    assert_valid(dev, shape, 1e-8)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(("nx", "ny", "height"), [(3, 3, 0.5), (4, 2, 0.9)])
def test_unfolding_is_the_development_of_a_miura(nx, ny, height):
    folded = miura(nx, ny, height=height)
    xy = diagram_module.unfold(folded)
    assert np.isfinite(xy).all()
    np.testing.assert_allclose(diagram_lengths_of(xy, folded), folded.edge_lengths, rtol=1e-12)
    assert (count_flipped(xy, folded.faces, tol=1e-12)) == 0
    flat = flat_miura(nx, ny, height)
    np.testing.assert_allclose(pdist(xy), pdist(flat.coords[:, :2]), atol=1e-12)


def test_flipped_projection_falls_back_to_the_unfolding():
    """The DOF-13 shape of the symmetric dome (Sec. 6.5): from its xy projection IPOPT stops
    at a diagram with a zero-area facet (D = 3.6e-3); from the unfolding it converges."""
    from pathlib import Path

    from rigidfold.io.fold import pattern_from_fold

    shape = pattern_from_fold(Path(__file__).parent / "data" / "dome_sym_dof13.fold")
    dev = develop(shape)
    assert_valid(dev, shape, 1e-12)
    assert dev.start == "unfolding"
    assert "from the projection: flipped" in dev.message
    assert dev.max_length_error < 1e-6


def test_non_developable_vertex_returns_a_large_D():
    pattern = degree_n_vertex(6, lift=0.5)
    assert abs(pattern.angle_defects[pattern.interior_vertices]).max() > 1e-2
    dev = develop(pattern)
    assert dev.D > 1e-6
    assert dev.max_length_error > 1e-3
    assert dev.status in ("converged", "flipped", "overlap", "failed")
    assert dev.flipped == 0  # the area constraints hold


def test_folded_grid_is_not_developable():
    dev = develop(folded_grid(4, amplitude=0.3))
    assert dev.D > 1e-6
    assert dev.flipped == 0


def test_iteration_limit_is_a_failure():
    dev = develop(folded_grid(), settings=DEFAULTS.with_(ipopt_max_iter=1))
    assert dev.status == "failed"
    assert "Maximum_Iterations_Exceeded" in dev.message


def test_nan_from_the_solver_is_a_failure(monkeypatch):
    class NaNSolver:
        def __call__(self, **kwargs):
            return {"x": np.full(len(kwargs["x0"]), np.nan)}

        def stats(self):
            return {"return_status": "Invalid_Number_Detected", "iter_count": 3}

    monkeypatch.setattr(diagram_module.ca, "nlpsol", lambda *args, **kwargs: NaNSolver())
    pattern = miura(2, 2)
    dev = develop(pattern)
    assert dev.status == "failed"
    assert "non-finite" in dev.message
    assert dev.flipped == -1 and dev.overlaps == -1
    with pytest.raises(ValueError, match="invalid"):
        dev.as_pattern(pattern)


# ------------------------------------------------------------------ counters
TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def test_count_overlaps_disjoint():
    coords = np.vstack([TRI, TRI + np.array([3.0, 0.0])])
    assert count_overlaps(coords, np.array([[0, 1, 2], [3, 4, 5]])) == 0


def test_count_overlaps_shared_edge_and_vertex():
    coords = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, -0.5]])
    faces = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4]])
    assert count_overlaps(coords, faces) == 0


def test_count_overlaps_overlapping():
    coords = np.vstack([TRI, TRI + np.array([0.3, 0.2])])
    assert count_overlaps(coords, np.array([[0, 1, 2], [3, 4, 5]])) == 1


def test_count_overlaps_three_stacked_triangles():
    coords = np.vstack([TRI, TRI + 0.1, TRI + 0.2])
    faces = np.arange(9).reshape(3, 3)
    assert count_overlaps(coords, faces) == 3
    assert count_overlaps(coords, faces[:1]) == 0


def test_count_overlaps_nested_triangle():
    coords = np.vstack([TRI * 3, TRI + 0.2])
    assert count_overlaps(coords, np.array([[0, 1, 2], [3, 4, 5]])) == 1


def test_count_flipped():
    assert count_flipped(TRI, np.array([[0, 1, 2]])) == 0
    assert count_flipped(TRI, np.array([[0, 2, 1]])) == 1
    degenerate = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    assert count_flipped(degenerate, np.array([[0, 1, 2]])) == 1


def test_flat_miura_diagram_counters():
    flat = miura(4, 4, height=0.0)
    xy = flat.coords[:, :2]
    assert count_flipped(xy, flat.faces) == 0
    assert count_overlaps(xy, flat.faces) == 0
    mirrored = xy * [-1.0, 1.0]
    assert count_flipped(mirrored, flat.faces) == flat.n_faces
