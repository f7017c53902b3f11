"""Tests of FOLD reading and writing (io/fold.py)."""

from __future__ import annotations

import copy
import json
import math
import re

import numpy as np
import pytest

from rigidfold.config import DEFAULTS
from rigidfold.io import FoldData, fold_dict, pattern_from_fold, read_fold, write_fold
from rigidfold.mesh import CreasePattern


# ---------------------------------------------------------------------------------- shapes
def folded_grid(seed: int = 0) -> CreasePattern:
    """A 3 x 3 vertex grid, triangulated, with random heights (a generic folded sheet)."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.arange(3.0), np.arange(3.0))
    coords = np.column_stack([x.ravel(), y.ravel(), 0.2 * rng.standard_normal(9)])
    faces = []
    for v in (0, 1, 3, 4):
        faces += [(v, v + 1, v + 4), (v, v + 4, v + 3)]
    return CreasePattern.from_faces(coords, faces)


def degree4_vertex() -> CreasePattern:
    """One interior vertex of degree 4 with its rim rising (all creases valleys)."""
    rim = [(1.0, 0.1, 0.3), (-0.1, 1.0, 0.2), (-1.0, -0.1, 0.35), (0.1, -1.0, 0.25)]
    coords = np.array([(0.0, 0.0, 0.0), *rim])
    return CreasePattern.from_faces(coords, [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 1)])


def hinge(lift: float) -> CreasePattern:
    """Two triangles hinged along the x axis, both far corners at height ``lift``."""
    coords = np.array([(0, 0, 0), (1, 0, 0), (0.5, 1, lift), (0.5, -1, lift)], dtype=float)
    return CreasePattern.from_faces(coords, [(0, 1, 2), (0, 3, 1)])


def miura_dict() -> dict:
    """A flat Miura-ori cell: 3 x 3 vertices in 2D, 4 parallelogram faces, 12 edges."""
    coords = [[i + (0.3 if j == 1 else 0.0), float(j)] for j in range(3) for i in range(3)]
    faces = [[v, v + 1, v + 4, v + 3] for v in (0, 1, 3, 4)]
    edges = [[0, 1], [1, 2], [3, 4], [4, 5], [6, 7], [7, 8]]
    edges += [[0, 3], [3, 6], [1, 4], [4, 7], [2, 5], [5, 8]]
    assignment = ["B", "B", "M", "M", "B", "B", "B", "B", "V", "M", "B", "B"]
    return {
        "file_spec": 1.2,
        "frame_classes": ["creasePattern"],
        "vertices_coords": coords,
        "faces_vertices": faces,
        "edges_vertices": edges,
        "edges_assignment": assignment,
    }


def pattern_key_sets(pattern: CreasePattern) -> tuple[set, set]:
    """Undirected edges and fixed edges of a pattern, as sets of frozensets."""
    edges = {frozenset(e) for e in pattern.edges.tolist()}
    fixed = {frozenset(e) for e in pattern.edges[pattern.fixed].tolist()}
    return edges, fixed


def grid_with_fixed_creases() -> CreasePattern:
    """The folded grid with every third crease fixed."""
    pattern = folded_grid(1)
    return pattern.with_fixed(~pattern.is_boundary_edge & (np.arange(pattern.n_edges) % 3 == 0))


SHAPES = {"grid": folded_grid, "grid_fixed": grid_with_fixed_creases, "degree4": degree4_vertex}


# ---------------------------------------------------------------------------------- writing
def test_fold_dict_keys_and_types():
    pattern = folded_grid()
    data = fold_dict(pattern, title="grid", metadata={"F": np.float64(1e-9)})
    assert data["file_spec"] == 1.2
    assert data["file_creator"] == "rigidfold"
    assert data["file_classes"] == ["singleModel"]
    assert data["frame_classes"] == ["foldedForm"]
    assert data["frame_title"] == "grid"
    assert data["frame_unit"] == "m"
    assert data["vertices_coords"] == pattern.coords.tolist()
    assert data["faces_vertices"] == pattern.faces.tolist()
    assert data["edges_vertices"] == pattern.edges.tolist()
    assert len(data["edges_assignment"]) == len(data["edges_foldAngle"]) == pattern.n_edges
    assert type(data["vertices_coords"][0][0]) is float
    assert type(data["faces_vertices"][0][0]) is int
    assert type(data["rigidfold:F"]) is float
    json.dumps(data, allow_nan=False)


@pytest.mark.parametrize(("lift", "letter"), [(0.4, "V"), (-0.4, "M"), (0.0, "F")])
def test_assignment_and_fold_angle_sign(lift, letter):
    """A trough seen from +z is a valley: "V" and a positive angle; a ridge is "M"."""
    data = fold_dict(hinge(lift))
    crease = data["edges_vertices"].index([0, 1])
    assert data["edges_assignment"][crease] == letter
    expected = 2 * math.degrees(math.atan2(lift, 1.0))
    assert data["edges_foldAngle"][crease] == pytest.approx(expected)
    others = [a for e, a in enumerate(data["edges_assignment"]) if e != crease]
    assert others == ["B"] * 4
    assert [a for e, a in enumerate(data["edges_foldAngle"]) if e != crease] == [0.0] * 4


def test_flat_angle_threshold():
    """A free crease folded by less than settings.geometry.flat_angle is flat ("F")."""
    tiny = hinge(1e-3)
    rho = tiny.fold_angles[0]
    assert fold_dict(tiny)["edges_assignment"][0] == "V"
    coarse = DEFAULTS.with_(flat_angle=2 * rho)
    assert fold_dict(tiny, settings=coarse)["edges_assignment"][0] == "F"


def test_fixed_creases_are_joins_with_their_actual_angle():
    pattern = grid_with_fixed_creases()
    data = fold_dict(pattern)
    letters = np.array(data["edges_assignment"])
    angles = np.array(data["edges_foldAngle"])
    assert (letters == "J").sum() == pattern.fixed.sum() > 0
    assert np.array_equal(letters == "J", pattern.fixed)
    assert np.array_equal(letters == "B", pattern.is_boundary_edge)
    np.testing.assert_array_equal(angles, np.degrees(pattern.fold_angles))
    assert np.all(angles[letters == "J"] != 0)
    free = ~pattern.fixed & ~pattern.is_boundary_edge
    assert np.all((letters[free] == "V") == (angles[free] > 0))


def test_degree4_vertex_all_valleys():
    data = fold_dict(degree4_vertex())
    creases = [a for a in data["edges_assignment"] if a != "B"]
    assert creases == ["V"] * 4


def test_metadata_is_prefixed_and_made_plain():
    meta = {
        "surface": {"name": "saddle", "size": np.array([1.0, 2.0])},
        "F": 1e-9,
        "n": np.int64(3),
        "ok": np.bool_(True),
        "pair": (1, 2),
        "F2": float("inf"),
    }
    data = fold_dict(folded_grid(), metadata=meta)
    assert data["rigidfold:surface"] == {"name": "saddle", "size": [1.0, 2.0]}
    assert data["rigidfold:F"] == 1e-9
    assert type(data["rigidfold:n"]) is int
    assert data["rigidfold:ok"] is True
    assert data["rigidfold:pair"] == [1, 2]
    assert data["rigidfold:F2"] is None
    assert "rigidfold:fixed" not in data


def test_metadata_must_be_json_data():
    with pytest.raises(ValueError, match="metadata 'x' holds a set"):
        fold_dict(folded_grid(), metadata={"x": {1, 2}})
    with pytest.raises(ValueError, match="metadata keys must be strings"):
        fold_dict(folded_grid(), metadata={1: 2})


def test_write_fold_is_compact_json(tmp_path):
    pattern = folded_grid()
    path = write_fold(tmp_path / "grid.fold", pattern, title="t", frame_class="creasePattern")
    assert path == tmp_path / "grid.fold"
    text = path.read_text()
    assert json.loads(text) == fold_dict(pattern, title="t", frame_class="creasePattern")
    rows = pattern.n_vertices + pattern.n_faces + pattern.n_edges
    assert len(text.splitlines()) < rows + 30
    assert "[0.0, 0.0," in text


def test_write_fold_is_atomic(tmp_path):
    path = tmp_path / "model.fold"
    path.write_text("old")
    write_fold(path, folded_grid())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.fold"]
    assert json.loads(path.read_text())["file_spec"] == 1.2


@pytest.mark.parametrize("where", ["missing_dir", "under_a_file", "a_directory"])
def test_write_fold_unwritable(tmp_path, where):
    (tmp_path / "file").write_text("x")
    (tmp_path / "dir").mkdir()
    path = {
        "missing_dir": tmp_path / "nope" / "a.fold",
        "under_a_file": tmp_path / "file" / "a.fold",
        "a_directory": tmp_path / "dir",
    }[where]
    with pytest.raises(ValueError, match=r"^cannot write .+: ") as info:
        write_fold(path, folded_grid())
    assert str(path) in str(info.value)
    assert "\n" not in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir", "file"]
    assert list((tmp_path / "dir").iterdir()) == []


# ---------------------------------------------------------------------------------- round trip
@pytest.mark.parametrize("name", list(SHAPES))
def test_round_trip(tmp_path, name):
    pattern = SHAPES[name]()
    meta = {"surface": {"name": "bezier", "seed": 1}, "F": 1.5e-9}
    data = read_fold(write_fold(tmp_path / "p.fold", pattern, metadata=meta))
    back = data.pattern
    np.testing.assert_array_equal(back.coords, pattern.coords)
    np.testing.assert_array_equal(back.faces, pattern.faces)
    np.testing.assert_array_equal(back.edges, pattern.edges)
    np.testing.assert_array_equal(back.fixed, pattern.fixed)
    assert data.n_file_edges == pattern.n_edges
    assert data.assignment == fold_dict(pattern)["edges_assignment"]
    assert data.metadata == meta
    assert data.frame_classes == ["foldedForm"]
    assert data.raw["file_creator"] == "rigidfold"
    assert (data.unit, data.scale, data.up, data.unitless) == ("m", 1.0, "z", False)


def test_round_trip_through_dict_and_pattern_from_fold():
    pattern = grid_with_fixed_creases()
    back = pattern_from_fold(fold_dict(pattern))
    np.testing.assert_array_equal(back.coords, pattern.coords)
    np.testing.assert_array_equal(back.edges, pattern.edges)
    np.testing.assert_array_equal(back.fixed, pattern.fixed)


# ---------------------------------------------------------------------------------- reading
def test_miura_quads_are_triangulated_with_joins():
    data = read_fold(miura_dict())
    p = data.pattern
    assert isinstance(data, FoldData)
    assert data.n_file_edges == 12
    assert p.n_faces == 8 and p.n_edges == 16
    assert data.assignment[:12] == miura_dict()["edges_assignment"]
    assert data.assignment[12:] == ["J"] * 4
    assert np.array_equal(p.fixed, np.arange(16) >= 12)
    np.testing.assert_array_equal(p.edges[:12], miura_dict()["edges_vertices"])
    assert np.array_equal(p.is_boundary_edge[:12], np.array(data.assignment[:12]) == "B")
    assert np.all(p.coords[:, 2] == 0)
    assert np.allclose(p.face_normals[:, 2], 1.0)
    assert p.n_facets == 4
    assert data.frame_classes == ["creasePattern"]
    assert data.metadata == {}
    assert (data.unit, data.scale, data.unitless) == ("unit", 1.0, True)


def test_miura_diagonals_are_the_shorter_ones():
    """Delaunay keeps the fatter triangles: each parallelogram is cut on its short diagonal."""
    p = read_fold(miura_dict()).pattern
    quads = np.array(miura_dict()["faces_vertices"])
    d1 = np.linalg.norm(p.coords[quads[:, 0]] - p.coords[quads[:, 2]], axis=1)
    d2 = np.linalg.norm(p.coords[quads[:, 1]] - p.coords[quads[:, 3]], axis=1)
    assert sorted(p.edge_lengths[12:]) == pytest.approx(sorted(np.minimum(d1, d2)))


def test_folded_quads_in_3d_are_triangulated_in_their_plane():
    """Two planar quads, tilted and hinged: the diagonals are joins, the hinge a valley."""
    c, s = math.cos(0.5), math.sin(0.5)
    coords = [[0, 0, 0], [1, 0, 0], [1, c, s], [0, c, s], [0, -c, s], [1, -c, s]]
    fold = {"vertices_coords": coords, "faces_vertices": [[0, 1, 2, 3], [0, 4, 5, 1]]}
    data = read_fold(fold)
    p = data.pattern
    assert p.n_faces == 4 and p.n_facets == 2
    assert data.n_file_edges == 0
    assert data.assignment.count("J") == 2 and data.assignment.count("B") == 6
    hinge_edge = next(e for e, uv in enumerate(p.edges.tolist()) if sorted(uv) == [0, 1])
    assert data.assignment[hinge_edge] == "U"
    assert p.fold_angles[hinge_edge] == pytest.approx(1.0)
    assert p.flatness_residuals == pytest.approx([0, 0], abs=1e-25)


@pytest.mark.parametrize(
    ("polygon", "area"),
    [
        # a U shape: non-convex; a fan from vertex 0 would overlap
        ([[0, 0], [3, 0], [3, 2], [2, 2], [2, 1], [1, 1], [1, 2], [0, 2]], 5.0),
        # a square with a vertex in the middle of a side (collinear corner)
        ([[0, 0], [1, 0], [2, 0], [2, 2], [0, 2]], 4.0),
        # an arrow head with a reflex vertex
        ([[0, 0], [2, 1], [0, 2], [0.5, 1]], 1.5),
    ],
)
def test_non_convex_polygon_triangulation(polygon, area):
    n = len(polygon)
    data = read_fold({"vertices_coords": polygon, "faces_vertices": [list(range(n))]})
    p = data.pattern
    assert p.n_faces == n - 2
    assert data.assignment.count("J") == n - 3
    assert data.assignment.count("B") == n
    assert np.all(p.face_normals[:, 2] > 0)
    assert p.n_facets == 1
    xy = p.coords[p.faces][:, :, :2]
    a, b = xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]
    assert np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 2 == pytest.approx(area)


def test_settings_reach_the_pattern_read():
    """corner_angle decides the corners of a pattern read from FOLD data (the boundary turns
    by 2 atan(0.02) = 2.3 degrees at vertex 1); triangulation_area_tol the ears."""
    fold = {
        "vertices_coords": [[0, 0], [1, -0.02], [2, 0], [2, 1], [1, 1], [0, 1]],
        "faces_vertices": [[0, 1, 4, 5], [1, 2, 3, 4]],
    }
    assert sorted(read_fold(fold).pattern.corners.tolist()) == [0, 1, 2, 3, 5]
    blunt = DEFAULTS.with_(corner_angle=math.radians(5.0))
    pattern = pattern_from_fold(fold, settings=blunt)
    assert pattern.settings is blunt
    assert sorted(pattern.corners.tolist()) == [0, 2, 3, 5]
    thin = {
        "vertices_coords": [[0, 0], [1, 0], [1, 0.01], [0, 0.01]],
        "faces_vertices": [[0, 1, 2, 3]],
    }
    assert read_fold(thin).pattern.n_faces == 2
    with pytest.raises(ValueError, match=r"faces_vertices\[0\]: the polygon is degenerate or"):
        read_fold(thin, settings=DEFAULTS.with_(triangulation_area_tol=0.1))


def test_missing_edges_are_derived():
    """Without edges_vertices, boundary edges get "B" and creases "U" (free)."""
    pattern = folded_grid()
    fold = fold_dict(pattern)
    del fold["edges_vertices"], fold["edges_assignment"], fold["edges_foldAngle"]
    data = read_fold(fold)
    assert data.n_file_edges == 0
    assert pattern_key_sets(data.pattern) == pattern_key_sets(pattern)
    letters = np.array(data.assignment)
    assert np.array_equal(letters == "B", data.pattern.is_boundary_edge)
    assert set(letters[~data.pattern.is_boundary_edge]) == {"U"}
    assert not data.pattern.fixed.any()


def test_partly_listed_edges_keep_file_order_first():
    fold = miura_dict()
    creases = [k for k, a in enumerate(fold["edges_assignment"]) if a != "B"]
    fold["edges_vertices"] = [fold["edges_vertices"][k] for k in creases][::-1]
    fold["edges_assignment"] = [fold["edges_assignment"][k] for k in creases][::-1]
    data = read_fold(fold)
    assert data.n_file_edges == 4
    np.testing.assert_array_equal(data.pattern.edges[:4], fold["edges_vertices"])
    assert data.assignment[:4] == fold["edges_assignment"]
    assert data.assignment[4:] == ["J"] * 4 + ["B"] * 8
    assert data.pattern.n_edges == 16


def test_edges_without_assignment_are_derived():
    fold = miura_dict()
    del fold["edges_assignment"]
    data = read_fold(fold)
    expected = ["U" if a != "B" else "B" for a in miura_dict()["edges_assignment"]]
    assert data.assignment[:12] == expected


def test_two_d_coords_are_flat():
    pattern = folded_grid()
    fold = fold_dict(pattern)
    fold["vertices_coords"] = [xyz[:2] for xyz in fold["vertices_coords"]]
    p = read_fold(fold).pattern
    np.testing.assert_array_equal(p.coords[:, :2], pattern.coords[:, :2])
    assert np.all(p.coords[:, 2] == 0)
    assert np.allclose(p.fold_angles, 0)


def test_clockwise_faces_are_reversed():
    """Faces listed clockwise seen from +z are all turned back to counter-clockwise."""
    pattern = folded_grid()
    fold = fold_dict(pattern)
    fold["faces_vertices"] = [f[::-1] for f in fold["faces_vertices"]]
    p = read_fold(fold).pattern
    np.testing.assert_array_equal(p.faces, pattern.faces)
    np.testing.assert_allclose(p.fold_angles, pattern.fold_angles)
    np.testing.assert_array_equal(p.edges, pattern.edges)


def test_join_is_fixed_whatever_its_angle():
    """ "J" fixes a crease even if folded; any other letter on a crease leaves it free."""
    fold = fold_dict(hinge(0.5))
    fold["edges_assignment"][0] = "J"
    assert read_fold(fold).pattern.fixed.tolist() == [True, False, False, False, False]
    for letter in "MVFU":
        fold["edges_assignment"][0] = letter
        assert not read_fold(fold).pattern.fixed.any()


def frames_dict() -> dict:
    """Top level: the flat Miura cell; frame 1 folds it, inheriting faces and edges; frame 2
    inherits frame 1's coordinates through it; frame 3 does not inherit."""
    top = miura_dict()
    folded = [[x, y, 0.1 * (x + y)] for x, y in top["vertices_coords"]]
    top["rigidfold:note"] = "top"
    top["file_frames"] = [
        {
            "frame_classes": ["foldedForm"],
            "frame_inherit": True,
            "frame_parent": 0,
            "vertices_coords": folded,
        },
        {"frame_inherit": True, "frame_parent": 1, "rigidfold:note": "frame 2"},
        {"frame_classes": ["foldedForm"], "vertices_coords": folded},
    ]
    return top


def test_frames_with_inheritance():
    fold = frames_dict()
    top = read_fold(fold)
    assert np.all(top.pattern.coords[:, 2] == 0)
    assert top.frame_classes == ["creasePattern"]
    assert top.metadata == {"note": "top"}
    first = read_fold(fold, frame=1)
    assert first.frame_classes == ["foldedForm"]
    assert first.pattern.coords[8, 2] == pytest.approx(0.1 * 4)
    assert first.assignment == top.assignment
    np.testing.assert_array_equal(first.pattern.edges[:12], top.pattern.edges[:12])
    second = read_fold(fold, frame=2)
    np.testing.assert_array_equal(second.pattern.coords, first.pattern.coords)
    assert second.frame_classes == ["foldedForm"]
    assert second.metadata == {"note": "frame 2"}
    with pytest.raises(ValueError, match="missing faces_vertices"):
        read_fold(fold, frame=3)


def test_frame_is_read_from_a_file(tmp_path):
    path = tmp_path / "frames.fold"
    path.write_text(json.dumps(frames_dict()))
    assert pattern_from_fold(path, frame=1).coords[8, 2] == pytest.approx(0.4)


# ---------------------------------------------------------------------------------- bad input
def edit(change) -> dict:
    fold = miura_dict()
    change(fold)
    return fold


def set_key(key, value):
    return lambda fold: fold.__setitem__(key, value)


def set_item(key, index, value):
    return lambda fold: fold[key].__setitem__(index, value)


def cyclic_frames(fold):
    fold["file_frames"] = [
        {"frame_inherit": True, "frame_parent": 2},
        {"frame_inherit": True, "frame_parent": 1},
    ]


BAD_DICTS = {
    "no coords": (lambda fold: fold.pop("vertices_coords"), "missing vertices_coords"),
    "no faces": (lambda fold: fold.pop("faces_vertices"), "missing faces_vertices"),
    "coords not a list": (set_key("vertices_coords", 3), "vertices_coords must be a non-empty"),
    "empty coords": (set_key("vertices_coords", []), "vertices_coords must be a non-empty"),
    "1D point": (set_item("vertices_coords", 2, [1.0]), r"vertices_coords\[2\] must be 2 or 3"),
    "4D point": (set_item("vertices_coords", 2, [1, 2, 3, 4]), r"vertices_coords\[2\]"),
    "string coord": (set_item("vertices_coords", 0, ["0", 0]), r"vertices_coords\[0\]"),
    "bool coord": (set_item("vertices_coords", 0, [True, 0]), r"vertices_coords\[0\]"),
    "null coord": (set_item("vertices_coords", 0, [None, 0]), r"vertices_coords\[0\]"),
    "point not a list": (set_item("vertices_coords", 0, 5), r"vertices_coords\[0\]"),
    "nan coord": (set_item("vertices_coords", 1, [math.nan, 0.0]), "not finite"),
    "inf coord": (set_item("vertices_coords", 1, [0.0, math.inf, 0]), "not finite"),
    "huge int coord": (set_item("vertices_coords", 1, [10**400, 0]), "not finite"),
    "faces not a list": (set_key("faces_vertices", {"a": 1}), "faces_vertices must be"),
    "face not a list": (set_item("faces_vertices", 1, 7), r"faces_vertices\[1\] must be"),
    "face of 2": (set_item("faces_vertices", 1, [0, 1]), r"faces_vertices\[1\] must be"),
    "float index": (set_item("faces_vertices", 1, [0, 1.5, 4]), r"faces_vertices\[1\]"),
    "face index too big": (
        set_item("faces_vertices", 3, [4, 5, 9, 7]),
        r"faces_vertices\[3\] refers to vertex 9, but there are 9 vertices",
    ),
    "negative face index": (set_item("faces_vertices", 0, [0, 1, -1, 3]), "vertex -1"),
    "face repeats vertex": (set_item("faces_vertices", 0, [0, 1, 1, 3]), "repeats a vertex"),
    "edges not a list": (set_key("edges_vertices", "x"), "edges_vertices must be a list"),
    "edge of 3": (set_item("edges_vertices", 0, [0, 1, 2]), r"edges_vertices\[0\] must be"),
    "edge index too big": (
        set_item("edges_vertices", 5, [8, 12]),
        r"edges_vertices\[5\] refers to vertex 12",
    ),
    "assignment too short": (
        lambda fold: fold["edges_assignment"].pop(),
        "edges_assignment must be a list of 12 letters",
    ),
    "assignment not a list": (set_key("edges_assignment", "BBMM"), "edges_assignment must be"),
    "unknown letter": (set_item("edges_assignment", 2, "X"), r"edges_assignment\[2\] is 'X'"),
    "lower-case letter": (set_item("edges_assignment", 2, "m"), r"edges_assignment\[2\]"),
    "list as letter": (set_item("edges_assignment", 2, ["M"]), r"edges_assignment\[2\]"),
    "cut": (set_item("edges_assignment", 3, "C"), r'edge 3 is a cut \("C"\)'),
    "boundary join": (
        set_item("edges_assignment", 0, "J"),
        r'edge 0 is a fixed crease \("J" or rigidfold:fixed\) but lies on the boundary',
    ),
    "fixed marks not booleans": (
        set_key("edges_rigidfold:fixed", [1] * 12),
        "edges_rigidfold:fixed must be a list of 12 booleans",
    ),
    "fixed marks too short": (
        set_key("edges_rigidfold:fixed", [False] * 11),
        "edges_rigidfold:fixed must be a list of 12 booleans",
    ),
    "boundary marked fixed": (
        set_key("edges_rigidfold:fixed", [True] + [False] * 11),
        "edge 0 is a fixed crease",
    ),
    "duplicate edge": (set_item("edges_vertices", 1, [1, 0]), "contains edge .* twice"),
    "edge in no face": (set_item("edges_vertices", 1, [0, 4]), "belongs to no face"),
    "non-manifold": (
        lambda fold: fold["faces_vertices"].append([1, 4, 0]),
        "more than two faces",
    ),
    "inconsistent orientation": (
        set_item("faces_vertices", 0, [3, 4, 1, 0]),
        "inconsistent orientation",
    ),
    "disconnected": (
        lambda fold: fold.update(
            vertices_coords=[*fold["vertices_coords"], [5, 5], [6, 5], [5, 6]],
            faces_vertices=[*fold["faces_vertices"], [9, 10, 11]],
        ),
        "disconnected",
    ),
    "degenerate polygon": (
        lambda fold: fold.update(
            vertices_coords=[[0, 0], [1, 0], [2, 0], [3, 0]],
            faces_vertices=[[0, 1, 2, 3]],
            edges_vertices=[],
            edges_assignment=[],
        ),
        r"faces_vertices\[0\]: the polygon is degenerate",
    ),
    "bowtie": (
        lambda fold: fold.update(
            vertices_coords=[[0, 0], [1, 1], [1, 0], [0, 1]],
            faces_vertices=[[0, 1, 2, 3]],
            edges_vertices=[],
            edges_assignment=[],
        ),
        r"faces_vertices\[0\]",
    ),
    "frame_classes not a list": (set_key("frame_classes", "x"), "frame_classes must be"),
    "file_frames not a list": (set_key("file_frames", {}), "file_frames must be a list"),
    "frame cycle": (cyclic_frames, "cycle"),
}


@pytest.mark.parametrize("name", list(BAD_DICTS))
def test_bad_fold_dict(name):
    change, message = BAD_DICTS[name]
    frame = 1 if name == "frame cycle" else 0
    with pytest.raises(ValueError, match=message) as info:
        read_fold(edit(change), frame=frame)
    text = str(info.value)
    assert text.startswith("FOLD data: ")
    assert "\n" not in text


GARBAGE = [None, 3, "x", [], {}, [None], [[]], [["a", 1]], [[1, 2, 3, 4, 5]], [[0.5, 1]], [{}]]


@pytest.mark.parametrize(
    "key",
    ["vertices_coords", "faces_vertices", "edges_vertices", "edges_assignment", "file_frames"],
)
@pytest.mark.parametrize("frame", [0, 1])
def test_garbage_values_give_one_line_value_errors(key, frame):
    """Whatever a key holds, reading gives a pattern or a one-line ValueError, nothing else."""
    for value in GARBAGE:
        fold = frames_dict()
        fold[key] = value
        try:
            read_fold(fold, frame=frame)
        except ValueError as exc:
            assert "\n" not in str(exc)


@pytest.mark.parametrize(
    ("frame", "message"),
    [(5, "frame 5 does not exist"), (-1, "non-negative integer"), ("1", "non-negative integer")],
)
def test_bad_frame_index(frame, message):
    with pytest.raises(ValueError, match=message):
        read_fold(miura_dict(), frame=frame)


def test_bad_frame_parent():
    fold = miura_dict()
    fold["file_frames"] = [{"frame_inherit": True, "frame_parent": 4}]
    with pytest.raises(ValueError, match="frame 1 has an invalid frame_parent 4"):
        read_fold(fold, frame=1)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"vertices_coords": [[0, 0]],\n "faces_vertices": [}', "invalid JSON at line 2 column"),
        ("", "invalid JSON at line 1 column 1"),
        ("[1, 2]", "the top level is an array of 2 items, not a JSON object"),
        ('"fold"', "the top level is 'fold', not a JSON object"),
    ],
)
def test_not_a_fold_file(tmp_path, text, message):
    path = tmp_path / "bad.fold"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as info:
        read_fold(path)
    assert str(info.value).startswith(f"not a FOLD file: {path}: ")
    assert "\n" not in str(info.value)


def test_nan_in_file_is_rejected(tmp_path):
    fold = miura_dict()
    fold["vertices_coords"][4] = [float("nan"), 1.0]
    path = tmp_path / "nan.fold"
    path.write_text(json.dumps(fold))  # Python writes NaN, which its reader accepts
    with pytest.raises(ValueError, match=r"nan\.fold: vertices_coords\[4\] is not finite"):
        read_fold(path)


def test_non_utf8_file(tmp_path):
    path = tmp_path / "binary.fold"
    path.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match=r"not a FOLD file: .*not UTF-8"):
        read_fold(path)


def test_missing_file(tmp_path):
    path = tmp_path / "absent.fold"
    with pytest.raises(
        ValueError, match=f"^cannot read {re.escape(str(path))}: No such file or directory$"
    ):
        read_fold(path)
    with pytest.raises(ValueError, match=r"cannot read .*: Is a directory"):
        read_fold(tmp_path)


def test_source_must_be_path_or_dict():
    with pytest.raises(ValueError, match="needs a file path or a dict, got list"):
        read_fold([1, 2])


def test_errors_name_the_file(tmp_path):
    path = tmp_path / "model.fold"
    path.write_text(json.dumps(edit(set_item("faces_vertices", 3, [4, 5, 9, 7]))))
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))}: faces_vertices") as info:
        read_fold(path)
    assert "\n" not in str(info.value)


def test_unknown_keys_are_ignored():
    fold = miura_dict()
    fold |= {1: "not a string key", "faces_edges": "x", "rigidfold:seed": 7}
    assert read_fold(fold).metadata == {"seed": 7}


def test_read_does_not_modify_the_dict():
    fold = frames_dict()
    before = copy.deepcopy(fold)
    read_fold(fold, frame=2)
    assert fold == before
