"""The paper's crease patterns: Table 4 and the layout properties stated in the docs."""

from __future__ import annotations

import numpy as np
import pytest

from rigidfold.generate import specs
from rigidfold.mesh import CreasePattern

# Table 4 (E of pattern 2 corrected from 117 to 129, see patterns.grids.pattern2)
TABLE4 = {
    "1": (49, 120, 72, 21),
    "1p": (49, 120, 72, 21),
    "2": (52, 129, 78, 21),
    "11": (121, 320, 200, 37),
}


@pytest.mark.parametrize("name", list(TABLE4))
def test_table4_sizes_and_initial_dof(name):
    plan = specs.parse_pattern(name)
    xy, faces = plan.xy, plan.faces
    shape = CreasePattern.from_faces(xy, faces)
    V, E, F, dof = TABLE4[name]
    assert (shape.n_vertices, shape.n_edges, shape.n_faces) == (V, E, F)
    assert len(shape.interior_edges) - 3 * len(shape.interior_vertices) == dof
    assert shape.generic_dof == dof
    assert sorted(map(tuple, shape.coords[shape.corners, :2].tolist())) == [
        (0, 0),
        (0, 3),
        (3, 0),
        (3, 3),
    ]
    assert np.all(shape.face_normals[:, 2] > 0)  # counter-clockwise seen from +z


def test_pattern2_side_angles_below_theta_min():
    plan = specs.parse_pattern("2")
    xy, faces = plan.xy, plan.faces
    shape = CreasePattern.from_faces(xy, faces)
    assert np.degrees(shape.corner_angles.min()) == pytest.approx(26.565, abs=1e-3)


@pytest.mark.parametrize("name", ["1", "11"])
def test_grid_mirror_symmetric_about_four_planes(name):
    plan = specs.parse_pattern(name)
    xy, faces = plan.xy, plan.faces
    tris = {tuple(sorted(map(tuple, np.round(xy[f], 9).tolist()))) for f in faces}
    for mirror in (
        lambda p: np.column_stack([3 - p[:, 0], p[:, 1]]),
        lambda p: np.column_stack([p[:, 0], 3 - p[:, 1]]),
        lambda p: p[:, ::-1],
        lambda p: np.column_stack([3 - p[:, 1], 3 - p[:, 0]]),
    ):
        image = {tuple(sorted(map(tuple, np.round(mirror(xy[f]), 9).tolist()))) for f in faces}
        assert image == tris


def test_unknown_pattern():
    with pytest.raises(ValueError, match="unknown pattern '7'"):
        specs.parse_pattern("7")


@pytest.mark.parametrize(("name", "flaps"), [("1", 0), ("1p", 2), ("2", 0), ("11", 0)])
def test_corner_flaps(name, flaps):
    """Boundary vertices of degree 2: triangles hinged on one crease (independent flaps)."""
    plan = specs.parse_pattern(name)
    xy, faces = plan.xy, plan.faces
    shape = CreasePattern.from_faces(xy, faces)
    degree = np.bincount(shape.edges.ravel(), minlength=shape.n_vertices)
    assert int((degree == 2).sum()) == flaps
