"""Unit tests of the crease-pattern model (mesh/)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import degree_n_vertex, folded_grid
from rigidfold.config import DEFAULTS
from rigidfold.mesh import CreasePattern, geometry

SHAPES = {
    "degree5": lambda: degree_n_vertex(5),
    "degree8": lambda: degree_n_vertex(8),
    "grid4": lambda: folded_grid(4),
    "grid6": lambda: folded_grid(6, 0.3),
}


@pytest.fixture(params=list(SHAPES))
def shape(request) -> CreasePattern:
    return SHAPES[request.param]()


def test_counts_and_euler(shape):
    assert shape.n_vertices - shape.n_edges + shape.n_faces == 1
    assert len(shape.boundary_edges) == len(shape.boundary_loop)
    assert len(shape.interior_edges) + len(shape.boundary_edges) == shape.n_edges
    assert set(shape.interior_vertices) | set(shape.boundary_vertices) == set(
        range(len(shape.coords))
    )


def test_edge_faces_orientation(shape):
    """Column 0 is the face that runs along the edge forwards."""
    for e, (u, v) in enumerate(shape.edges):
        fa, fb = shape.edge_faces[e]
        if fa >= 0:
            f = list(shape.faces[fa])
            assert f[(f.index(u) + 1) % 3] == v
        if fb >= 0:
            f = list(shape.faces[fb])
            assert f[(f.index(v) + 1) % 3] == u


def test_angle_sums_are_sum_of_sector_angles(shape):
    for v in range(shape.n_vertices):
        assert shape.angle_sums[v] == pytest.approx(shape.sector_angles(v).sum())
    assert np.allclose(shape.corner_angles.sum(axis=1), np.pi)


def test_flat_shape_has_no_defect_and_no_fold():
    flat = folded_grid(5, amplitude=0.0)
    assert np.allclose(flat.angle_defects, 0.0, atol=1e-12)
    assert np.allclose(flat.fold_angles, 0.0, atol=1e-12)
    assert np.allclose(flat.face_normals[:, 2], 1.0)


def test_fold_angle_sign_valley_positive():
    """A trough seen from +z (both sides rising from the crease) is a valley: rho > 0."""
    t = 0.4
    coords = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, t], [0.5, -1, t]], dtype=float)
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    valley = CreasePattern.from_faces(coords, faces)
    crease = int(valley.interior_edges[0])
    assert valley.fold_angles[crease] == pytest.approx(2 * np.arctan(t))
    mountain = valley.with_coords(coords * [1, 1, -1])
    assert mountain.fold_angles[crease] == pytest.approx(-2 * np.arctan(t))


def test_angles_use_atan2_accuracy():
    a = np.array([[1.0, 0.0, 0.0]])
    b = np.array([[1.0, 1e-9, 0.0]])
    assert geometry.angle_between(a, b)[0] == pytest.approx(1e-9, rel=1e-9)


def test_corners_and_sides_of_grid():
    g = folded_grid(5)
    assert sorted(g.corners.tolist()) == [0, 4, 20, 24]
    assert len(g.boundary_sides) == 4
    assert all(len(s.inner) == 3 for s in g.boundary_sides)
    for side in g.boundary_sides:
        b1, b2, b3 = side.line
        xy = g.coords[side.inner, :2]
        assert np.allclose(b1 * xy[:, 0] + b2 * xy[:, 1] + b3, 0.0)


def test_facets_join_fixed_creases(grid):
    assert grid.n_facets == grid.n_faces
    fixed = np.zeros(grid.n_edges, dtype=bool)
    fixed[grid.interior_edges[:2]] = True
    joined = grid.with_fixed(fixed)
    assert joined.n_facets == grid.n_faces - 2
    assert len(joined.fixed_creases) == 2
    assert joined.generic_dof == grid.generic_dof - 2


def test_arrays_are_read_only(grid):
    with pytest.raises(ValueError):
        grid.coords[0, 0] = 1.0


@pytest.mark.parametrize(
    ("coords", "faces", "message"),
    [
        (np.zeros((3, 3)), np.array([[0, 1, 2]]), "degenerate"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, np.nan]]), np.array([[0, 1, 2]]), "non-finite"),
        (np.eye(3), np.array([[0, 1, 3]]), "out of range"),
        (np.eye(3), np.array([[0, 1, 1]]), "repeats a vertex"),
        (np.eye(3), np.array([[0, 1, 2, 0]]), "triangles"),
        (np.zeros((3, 4)), np.array([[0, 1, 2]]), "(V, 3)"),
    ],
)
def test_invalid_input_names_the_problem(coords, faces, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        CreasePattern.from_faces(coords, faces)


def test_non_manifold_edge_refused():
    coords = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [1, 1, 1]], dtype=float)
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.raises(ValueError, match=r"more than two faces|inconsistent"):
        CreasePattern.from_faces(coords, faces)


def test_inconsistent_orientation_refused():
    coords = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, -1, 0]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 1, 3]])
    with pytest.raises(ValueError, match="inconsistent"):
        CreasePattern.from_faces(coords, faces)


def test_annulus_refused():
    """A ring of quads split into triangles has a hole: not a disc."""
    outer = [(0, 0), (3, 0), (3, 3), (0, 3)]
    inner = [(1, 1), (2, 1), (2, 2), (1, 2)]
    coords = np.array(outer + inner, dtype=float)
    faces = []
    for k in range(4):
        a, b, c, d = k, (k + 1) % 4, 4 + (k + 1) % 4, 4 + k
        faces += [(a, b, c), (a, c, d)]
    with pytest.raises(ValueError, match=r"disc|loop"):
        CreasePattern.from_faces(coords, np.array(faces))


def test_fixed_boundary_edge_refused(grid):
    mask = np.zeros(grid.n_edges, dtype=bool)
    mask[grid.boundary_edges[0]] = True
    with pytest.raises(ValueError, match="boundary"):
        grid.with_fixed(mask)


def test_clockwise_sheet_refused(grid):
    with pytest.raises(ValueError, match="counter-clockwise"):
        CreasePattern.from_faces(grid.coords, grid.faces[:, ::-1])


def test_error_messages_show_plain_numbers():
    with pytest.raises(ValueError) as info:
        CreasePattern.from_faces(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    assert "np.int64" not in str(info.value)


def test_settings_decide_corners_of_a_case():
    """DEFAULTS.with_(corner_angle=...) reaches the pattern that make_case builds."""
    from rigidfold.generate.specs import case_from_specs

    assert len(case_from_specs("dome", "1").pattern.corners) == 4
    blunt = DEFAULTS.with_(corner_angle=np.radians(100.0))  # the square's corners turn by 90
    case = case_from_specs("dome", "1", settings=blunt)
    assert case.pattern.settings is blunt
    assert case.pattern.corners.tolist() == []
    assert case.pattern.boundary_sides == ()
    moved = case.pattern.with_coords(case.pattern.coords + 0.01)
    assert moved.settings is blunt
    assert moved.with_fixed(moved.fixed).corners.tolist() == []


def test_mildly_bent_boundary_vertex_is_a_corner_below_corner_angle():
    """The plan boundary turns by 2 atan(0.02) = 2.3 degrees at vertex 1."""
    xy = np.array([[0, 0], [1, -0.02], [2, 0], [2, 1], [1, 1], [0, 1]])
    faces = np.array([[0, 1, 4], [0, 4, 5], [1, 2, 3], [1, 3, 4]])
    bent = CreasePattern.from_faces(xy, faces)
    assert sorted(bent.corners.tolist()) == [0, 1, 2, 3, 5]
    blunt = CreasePattern.from_faces(xy, faces, settings=DEFAULTS.with_(corner_angle=0.1))
    assert sorted(blunt.corners.tolist()) == [0, 2, 3, 5]
    assert sorted(s.inner.tolist() for s in blunt.boundary_sides) == [[], [], [1], [4]]


def test_settings_decide_degenerate_faces():
    """Grid triangles have area / (longest edge)^2 = 0.5 / 2 = 0.25."""
    g = folded_grid(3, amplitude=0.0)
    assert CreasePattern.from_faces(g.coords, g.faces, settings=DEFAULTS.with_(degenerate_area=0.2))
    with pytest.raises(ValueError, match=r"face 0 .* is degenerate"):
        CreasePattern.from_faces(g.coords, g.faces, settings=DEFAULTS.with_(degenerate_area=0.3))
    with pytest.raises(ValueError, match="settings must be a Settings, got dict"):
        CreasePattern(g.coords, g.faces, g.edges, g.fixed, {})


def test_crease_stencils_give_the_fold_angles(shape):
    """Stencil (u, v, a, b): a opposite u -> v on the left face, b on the right face."""
    from rigidfold.mechanism.kinematics import fold_angles_and_gradients

    creases = shape.interior_edges
    stencils = shape.crease_stencils(creases)
    assert stencils.shape == (len(creases), 4) and stencils.dtype == np.int64
    for (u, v, a, b), e in zip(stencils, creases, strict=True):
        assert (u, v) == tuple(shape.edges[e])
        left, right = shape.faces[shape.edge_faces[e]]
        assert {u, v, a} == set(left) and {v, u, b} == set(right)
    rho, grad, cols = fold_angles_and_gradients(shape.coords, stencils)
    assert np.allclose(rho, shape.fold_angles[creases], atol=1e-12)
    assert grad.shape == cols.shape == (len(creases), 12)
    assert np.array_equal(cols[:, 3:6], 3 * stencils[:, 1:2] + np.arange(3))
    empty = fold_angles_and_gradients(shape.coords, shape.crease_stencils([]))
    assert [x.shape for x in empty] == [(0,), (0, 12), (0, 12)]


def test_mirror_pairs():
    from rigidfold.surfaces.builtin import MirrorPlane

    g = folded_grid(4)
    mate = geometry.mirror_pairs(g.coords, MirrorPlane(1.0, 0.0, -1.5), tol=1e-9)
    assert mate.tolist() == [3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12]
    with pytest.raises(ValueError, match=r"not symmetric about the plane x = 1.4: vertex \d+ at"):
        geometry.mirror_pairs(g.coords, MirrorPlane(1.0, 0.0, -1.4), tol=1e-9)
