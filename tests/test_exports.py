"""3D, CAD and cut-sheet exports of a design (rigidfold.exports, ``rigidfold export``)."""

from __future__ import annotations

import csv
import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import Counter

import ezdxf
import numpy as np
import pytest
import trimesh

from rigidfold.cli.commands import main
from rigidfold.develop import develop
from rigidfold.exports import (
    EXPORT_FORMATS,
    check_formats,
    export_design,
    layout_sheet,
    panel_loops,
    read_design,
)
from rigidfold.exports.mesh3d import Y_UP
from rigidfold.exports.sheet import polygon_area
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import crease_pattern_frame, read_fold, write_fold
from rigidfold.io.fold import edge_assignments
from rigidfold.mesh.geometry import face_areas

SVG = "{http://www.w3.org/2000/svg}"
FILES = [
    "design.obj",
    "design.stl",
    "design.ply",
    "design.glb",
    "design_cutsheet.dxf",
    "design_cutsheet.svg",
    "design_panels.csv",
    "design_creases.csv",
    "design.os.fold",
]


@pytest.fixture(scope="module")
def design():
    """A solved pattern-1 shape with a three-triangle panel and a two-triangle panel, and
    its development diagram."""
    case = case_from_specs("bezier", "1", seed=1)
    pattern = case.pattern
    inner = next(
        f
        for f in range(pattern.n_faces)
        if not pattern.is_boundary_edge[pattern.face_edges[f]].any()
    )
    fixed = np.zeros(pattern.n_edges, dtype=bool)
    fixed[pattern.face_edges[inner][:2]] = True
    fixed[pattern.interior_edges[40]] = True
    result = case.problem().solve(fixed=fixed)
    assert result.F < 1e-10
    shape = result.pattern
    dev = develop(shape)
    assert dev.status == "converged", dev.message
    assert shape.n_facets == shape.n_faces - 3
    return shape, dev.coords2d


@pytest.fixture(scope="module")
def exported(design, tmp_path_factory):
    out = tmp_path_factory.mktemp("exports")
    shape, coords2d = design
    written = export_design(shape, coords2d, out, title="test design")
    assert [p.name for p in written] == FILES
    return out


def counts(shape) -> Counter:
    return Counter(edge_assignments(shape))


def boundary_length(shape, coords2d) -> float:
    b = shape.edges[shape.boundary_edges]
    return float(np.sum(np.linalg.norm(coords2d[b[:, 1]] - coords2d[b[:, 0]], axis=1)))


# ------------------------------------------------------------------------------ DXF
def test_dxf_reads_back_with_layers_and_line_counts(design, exported):
    shape, coords2d = design
    doc = ezdxf.readfile(exported / "design_cutsheet.dxf")
    assert doc.header["$INSUNITS"] == 4  # millimetres
    names = {layer.dxf.name for layer in doc.layers}
    assert {"BOUNDARY", "MOUNTAIN", "VALLEY", "FLAT", "PANEL", "LABELS"} <= names
    entities = Counter((e.dxftype(), e.dxf.layer) for e in doc.modelspace())
    n = counts(shape)
    assert entities[("LINE", "BOUNDARY")] == n["B"] == len(shape.boundary_edges)
    assert entities[("LINE", "MOUNTAIN")] == n["M"] > 0
    assert entities[("LINE", "VALLEY")] == n["V"] > 0
    assert entities[("LINE", "FLAT")] == n["F"]
    # fixed creases are not drawn: every line is a boundary edge or a free crease
    lines = sum(v for (kind, _), v in entities.items() if kind == "LINE")
    assert lines == shape.n_edges - len(shape.fixed_creases)
    assert entities[("LWPOLYLINE", "PANEL")] == shape.n_facets
    assert entities[("TEXT", "LABELS")] == len(shape.free_creases)
    cut = sum(
        np.hypot(*(np.subtract(e.dxf.end, e.dxf.start)[:2]))
        for e in doc.modelspace().query('LINE[layer=="BOUNDARY"]')
    )
    assert cut == pytest.approx(1000 * boundary_length(shape, coords2d), rel=1e-9)


# ------------------------------------------------------------------------------ 3D
@pytest.mark.parametrize(("name", "rtol"), [("design.obj", 1e-15), ("design.stl", 1e-6)])
def test_obj_and_stl_load_with_the_folds_vertices_faces_and_bounds(design, exported, name, rtol):
    shape, _ = design
    mesh = trimesh.load(exported / name, force="mesh")
    assert mesh.vertices.shape == (shape.n_vertices, 3)
    assert mesh.faces.shape == (shape.n_faces, 3)
    bounds = np.array([shape.coords.min(axis=0), shape.coords.max(axis=0)])
    np.testing.assert_allclose(mesh.bounds, bounds, rtol=rtol, atol=rtol)
    assert mesh.area == pytest.approx(face_areas(shape.coords, shape.faces).sum(), rel=rtol)
    assert np.all(mesh.face_normals[:, 2] > 0)  # counter-clockwise seen from +z


def test_obj_has_one_group_per_panel_sharing_the_vertices(design, exported):
    shape, _ = design
    text = (exported / "design.obj").read_text()
    assert text.count("\nv ") == shape.n_vertices
    groups = re.split(r"^g (panel_\d+)$", text, flags=re.M)[1:]
    names, bodies = groups[::2], groups[1::2]
    assert len(names) == shape.n_facets
    sizes = [body.count("\nf ") for body in bodies]
    assert sizes == np.bincount(shape.facets).tolist()


def test_ply_has_the_panel_of_every_face(design, exported):
    shape, _ = design
    mesh = trimesh.load(exported / "design.ply", process=False)
    assert mesh.vertices.shape == (shape.n_vertices, 3)
    assert mesh.faces.shape == (shape.n_faces, 3)
    panel = mesh.metadata["_ply_raw"]["face"]["data"]["panel"]
    np.testing.assert_array_equal(panel.ravel(), shape.facets)


def test_glb_has_one_y_up_node_per_panel(design, exported):
    shape, _ = design
    scene = trimesh.load(exported / "design.glb")
    assert len(scene.geometry) == shape.n_facets
    assert sum(len(g.faces) for g in scene.geometry.values()) == shape.n_faces
    assert {f"panel_{k:02d}" for k in range(shape.n_facets)} <= set(scene.graph.nodes)
    up = shape.coords @ Y_UP[:3, :3].T  # rigidfold's z becomes glTF's y
    np.testing.assert_allclose(scene.bounds, [up.min(axis=0), up.max(axis=0)], atol=1e-6)


# ------------------------------------------------------------------------------ sheet
def test_sheet_is_turned_to_its_smallest_bounding_box(design):
    shape, coords2d = design
    sheet = layout_sheet(shape, coords2d, margin_mm=5.0)
    np.testing.assert_allclose(sheet.xy.min(axis=0), [5.0, 5.0], atol=1e-9)
    size = np.ptp(sheet.xy, axis=0)
    assert (sheet.width, sheet.height) == pytest.approx(tuple(size + 10.0))
    assert sheet.width >= sheet.height
    xy = 1000 * coords2d
    for phi in np.linspace(0, np.pi, 721):
        c, s = np.cos(phi), np.sin(phi)
        turned = xy @ np.array([[c, s], [-s, c]])
        assert np.prod(np.ptp(turned, axis=0)) >= np.prod(size) * (1 - 1e-12)
    # a rotation, not a mirror: every face keeps its area and its counter-clockwise turn
    from rigidfold.develop.diagram import signed_areas

    np.testing.assert_allclose(
        signed_areas(sheet.xy, shape.faces), 1e6 * signed_areas(coords2d, shape.faces), rtol=1e-9
    )


def test_panel_outlines_leave_out_the_fixed_creases(design):
    shape, coords2d = design
    loops = panel_loops(shape)
    assert len(loops) == shape.n_facets
    assert all(len(panel) == 1 for panel in loops)  # no panel with a hole
    assert sorted(len(panel[0]) for panel in loops)[-2:] == [4, 5]
    fixed = {tuple(sorted(shape.edges[e])) for e in shape.fixed_creases.tolist()}
    for (loop,) in loops:
        sides = {tuple(sorted(s)) for s in zip(loop, np.roll(loop, -1), strict=True)}
        assert not sides & fixed
    areas = [polygon_area(coords2d, panel[0]) for panel in loops]
    assert sum(areas) == pytest.approx(polygon_area(coords2d, shape.boundary_loop), rel=1e-12)


def parse_path(d: str) -> np.ndarray:
    """(k, 2) points of an 'M x y L x y ... Z' path."""
    numbers = [float(t) for t in re.findall(r"-?\d+(?:\.\d+)?", d)]
    return np.array(numbers).reshape(-1, 2)


def test_svg_cut_sheet_measures_in_mm_and_keeps_the_boundary_length(design, exported):
    shape, coords2d = design
    root = ET.parse(exported / "design_cutsheet.svg").getroot()
    width, height = root.get("width"), root.get("height")
    assert width.endswith("mm") and height.endswith("mm")
    box = [float(v) for v in root.get("viewBox").split()]
    assert box == [0.0, 0.0, float(width[:-2]), float(height[:-2])]
    groups = {g.get("id"): g for g in root.iter(f"{SVG}g")}
    assert {"BOUNDARY", "MOUNTAIN", "VALLEY", "PANEL", "LABELS", "LEGEND", "SCALE"} <= set(groups)
    (path,) = groups["BOUNDARY"].iter(f"{SVG}path")
    ring = parse_path(path.get("d"))
    assert len(ring) == len(shape.boundary_loop)
    perimeter = np.sum(np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1))
    assert perimeter == pytest.approx(1000 * boundary_length(shape, coords2d), rel=1e-6)
    n = counts(shape)
    for group, letter in (("MOUNTAIN", "M"), ("VALLEY", "V")):
        assert len(list(groups[group].iter(f"{SVG}line"))) == n[letter]
    assert len(list(groups["PANEL"].iter(f"{SVG}path"))) == shape.n_facets
    labels = [t.text for t in groups["LABELS"].iter(f"{SVG}text")]
    assert len(labels) == len(shape.free_creases)
    e = int(shape.free_creases[0])
    assert f"{e}: {np.degrees(shape.fold_angles[e]):+.1f}°" in labels
    assert any(t.text.endswith(" mm") for t in groups["SCALE"].iter(f"{SVG}text"))


def test_origami_simulator_svg_uses_its_colours_and_opacities(design, tmp_path):
    shape, coords2d = design
    (path,) = export_design(
        shape, coords2d, tmp_path, ("svg",), name="os", convention="origami-simulator"
    )
    root = ET.parse(path).getroot()
    assert root.get("width").endswith("mm")
    drawn = [el for el in root if el.tag not in (f"{SVG}title", f"{SVG}desc")]
    assert all(el.tag == f"{SVG}line" for el in drawn)
    assert len(drawn) == shape.n_edges
    letters = edge_assignments(shape)
    colours = {"B": "#000000", "M": "#ff0000", "V": "#0000ff", "J": "#ffff00", "F": "#ff00ff"}
    for line in drawn:
        e = int(line.get("id").removeprefix("crease-"))
        assert line.get("stroke") == colours[letters[e]]
        if letters[e] in "MV":
            opacity = float(line.get("stroke-opacity"))
            assert opacity == pytest.approx(abs(np.degrees(shape.fold_angles[e])) / 180, rel=1e-5)
        else:
            assert line.get("stroke-opacity") is None


# ------------------------------------------------------------------------------ CSV
def read_csv(path) -> list[dict]:
    with path.open(newline="") as file:
        return list(csv.DictReader(file))


def test_schedule_has_one_row_per_panel_and_crease(design, exported):
    shape, coords2d = design
    panels = read_csv(exported / "design_panels.csv")
    creases = read_csv(exported / "design_creases.csv")
    assert [int(r["panel"]) for r in panels] == list(range(shape.n_facets))
    assert [int(r["crease"]) for r in creases] == list(range(shape.n_edges))
    area = polygon_area(coords2d, shape.boundary_loop)
    assert sum(float(r["area_m2"]) for r in panels) == pytest.approx(area, rel=1e-12)
    assert sum(int(r["triangles"]) for r in panels) == shape.n_faces
    words = {"M": "M", "V": "V", "J": "fixed", "B": "boundary", "F": "flat"}
    assert Counter(r["assignment"] for r in creases) == Counter(
        words[letter] for letter in edge_assignments(shape)
    )
    d = coords2d[shape.edges[:, 1]] - coords2d[shape.edges[:, 0]]
    np.testing.assert_allclose(
        [float(r["length_m"]) for r in creases], np.hypot(d[:, 0], d[:, 1]), rtol=1e-12
    )
    np.testing.assert_allclose(
        [float(r["fold_angle_deg"]) for r in creases], np.degrees(shape.fold_angles), atol=1e-12
    )
    row = creases[int(shape.fixed_creases[0])]
    assert row["panel_left"] == row["panel_right"] != "-1"


# ------------------------------------------------------------- FOLD for Origami Simulator
# What Origami Simulator takes, from its source (github.com/amandaghassaei/OrigamiSimulator;
# the file and function are named at each check; rigidfold.exports.fold_os says the same).


def os_fold_angle(coords: np.ndarray, faces: list, v1: int, v2: int) -> float:
    """Origami Simulator's fold angle (degrees) of the crease from vertex v1 to v2: its two
    faces ordered as js/pattern.js (getFacesAndVerticesForEdges) orders them (face 1 runs
    v1 -> v2 in its vertex order), their normals as the normalCalc shader of index.html
    computes them (cross(b - a, c - a)), the angle as its thetaCalcShader does:
    atan2(dot(cross(n1, c), n2), dot(n1, n2)) with c the unit vector from v1 to v2."""
    found = [
        (f, face.index(v2) - face.index(v1))
        for f, face in enumerate(faces)
        if {v1, v2} <= set(face)
    ]
    (first, _), (second, step) = found
    if step in (1, -2):  # the second face runs v1 -> v2: it is face 1
        first, second = second, first

    def normal(f: int) -> np.ndarray:
        a, b, c = coords[faces[f]]
        n = np.cross(b - a, c - a)
        return n / np.linalg.norm(n)

    n1, n2 = normal(first), normal(second)
    c = (coords[v2] - coords[v1]) / np.linalg.norm(coords[v2] - coords[v1])
    return float(np.degrees(np.arctan2(np.cross(n1, c) @ n2, n1 @ n2)))


def test_origami_simulator_fold_is_what_its_importer_takes(design, exported):
    shape, _ = design
    path = exported / "design.os.fold"
    doc = json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    # js/importer.js, openFile: a file without one of these four is refused
    assert {"vertices_coords", "edges_vertices", "edges_assignment", "faces_vertices"} <= set(doc)
    # js/pattern.js, processFold: the top-level frame is the model, file_frames are not read
    assert "file_frames" not in doc and doc["frame_classes"] == ["foldedForm"]
    # js/model.js, sync: one line list per letter U V M B F C, any other letter fails
    letters = np.asarray(doc["edges_assignment"])
    assert set(letters) <= {"M", "V", "F", "B"}
    expected = np.asarray(edge_assignments(shape))
    assert np.array_equal(letters == "B", expected == "B")
    assert np.array_equal(np.isin(letters, ["M", "V"]), np.isin(expected, ["M", "V"]))
    assert np.array_equal(letters == "F", np.isin(expected, ["J", "F"]))  # fixed: panels
    # js/model.js, sync: faces are vertex triangles indexed with a Uint16Array
    faces = doc["faces_vertices"]
    assert all(len(face) == 3 for face in faces) and len(doc["vertices_coords"]) < 2**16
    # js/pattern.js, getFacesAndVerticesForEdges: every M, V and F edge needs an angle (null is
    # skipped); js/importer.js: degrees, M negative, V positive; js/model.js, sync: a crease
    # whose angle is 0 is a stiff panel crease
    angles = np.asarray(doc["edges_foldAngle"], dtype=float)
    assert len(angles) == shape.n_edges and np.isfinite(angles).all()
    assert (angles[letters == "M"] < 0).all() and (angles[letters == "V"] > 0).all()
    assert (angles[np.isin(letters, ["F", "B"])] == 0).all()
    # js/pattern.js, processFold puts a 2D file's (x, y) at (x, 0, y); js/saveFOLD.js writes
    # y up: the design's height is the file's y, the model turned, not mirrored
    coords = np.asarray(doc["vertices_coords"], dtype=float)
    assert coords.shape == (shape.n_vertices, 3)
    np.testing.assert_array_equal(coords[:, 1], shape.coords[:, 2])
    # at 100% folding the design is at rest: Origami Simulator's angle of every crease is the
    # target the file gives it
    creases = np.flatnonzero(np.isin(letters, ["M", "V"]))
    assert len(creases) > 0
    for e in creases:
        v1, v2 = doc["edges_vertices"][e]
        assert os_fold_angle(coords, faces, v1, v2) == pytest.approx(angles[e], abs=1e-9)


def test_origami_simulator_fold_reads_back_as_the_same_design(design, exported):
    shape, _ = design
    data = read_fold(exported / "design.os.fold", up="y")
    back = data.pattern
    np.testing.assert_array_equal(back.coords, shape.coords)
    np.testing.assert_array_equal(back.faces, shape.faces)
    np.testing.assert_array_equal(back.edges, shape.edges)
    np.testing.assert_array_equal(back.fixed, shape.fixed)  # edges_rigidfold:fixed
    np.testing.assert_allclose(back.fold_angles, shape.fold_angles, atol=1e-12)


# ------------------------------------------------------------------------------ API
def test_parse_formats():
    from rigidfold.cli.units import parse_formats

    assert parse_formats("SVG, obj,obj") == ("obj", "svg")
    assert check_formats(["csv", "dxf"]) == ("dxf", "csv")
    assert parse_formats(",".join(EXPORT_FORMATS)) == EXPORT_FORMATS
    with pytest.raises(ValueError, match="sequence of format names"):
        check_formats("obj")
    with pytest.raises(ValueError, match="unknown export format 'xyz'"):
        parse_formats("obj,xyz")
    with pytest.raises(ValueError, match="no export format"):
        parse_formats(" , ")


def test_bad_arguments_are_refused(design, tmp_path):
    shape, coords2d = design
    with pytest.raises(ValueError, match=r"coords2d must be a \(49, 2\) array"):
        export_design(shape, coords2d[:-1], tmp_path)
    with pytest.raises(ValueError, match="convention must be one of"):
        export_design(shape, coords2d, tmp_path, convention="inkscape")
    with pytest.raises(ValueError, match="plain file name"):
        export_design(shape, coords2d, tmp_path, name="../x")
    assert not any(tmp_path.iterdir())


def test_an_existing_link_is_replaced_not_followed(design, tmp_path):
    shape, coords2d = design
    target = tmp_path / "elsewhere.txt"
    target.write_text("keep")
    out = tmp_path / "out"
    out.mkdir()
    (out / "design.obj").symlink_to(target)
    export_design(shape, coords2d, out, ("obj",))
    assert target.read_text() == "keep"
    assert not (out / "design.obj").is_symlink()


def test_importing_the_package_loads_neither_trimesh_nor_ezdxf():
    code = "import sys, rigidfold.exports; print(sorted({'trimesh', 'ezdxf'} & set(sys.modules)))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip() == "[]"


# ------------------------------------------------------------------------------ CLI
@pytest.fixture(scope="module")
def solution_file(design, tmp_path_factory):
    """A FOLD file as ``rigidfold generate`` writes it: folded form + creasePattern frame."""
    shape, coords2d = design
    path = tmp_path_factory.mktemp("solution") / "design.fold"
    return write_fold(path, shape, frames=[crease_pattern_frame(coords2d)])


def test_export_command_writes_every_format(solution_file, design, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["export", str(solution_file), "--out", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["diagram"] == "frame 1"
    assert report["formats"] == list(EXPORT_FORMATS)
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)
    assert report["written"] == [str(out / name) for name in FILES]
    np.testing.assert_array_equal(read_design(solution_file).coords2d, design[1])


def test_export_command_computes_a_missing_diagram(design, tmp_path, capsys):
    shape, coords2d = design
    bare = write_fold(tmp_path / "bare.fold", shape)
    out = tmp_path / "out"
    options = ["--to", "svg,obj", "--convention", "origami-simulator"]
    assert main(["export", str(bare), "--out", str(out), *options]) == 0
    text = capsys.readouterr().out
    assert "development diagram: computed (converged" in text
    assert sorted(p.name for p in out.iterdir()) == ["bare.obj", "bare_cutsheet.svg"]
    assert 'stroke="#ff0000"' in (out / "bare_cutsheet.svg").read_text()
    design_read = read_design(bare)
    assert design_read.diagram == "computed"
    np.testing.assert_allclose(
        layout_sheet(shape, design_read.coords2d).lengths,
        layout_sheet(shape, coords2d).lengths,
        rtol=1e-6,
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["MISSING"], "missing.fold: No such file"),
        (["SOLUTION", "--to", "obj,xyz"], "unknown export format 'xyz'"),
    ],
)
def test_export_command_bad_input(solution_file, tmp_path, args, message):
    files = {"SOLUTION": str(solution_file), "MISSING": str(tmp_path / "missing.fold")}
    args = [files.get(a, a) for a in args]
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", "export", *args, "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and message in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""


def test_export_command_refuses_to_replace_its_input(solution_file, tmp_path, capsys):
    """An input named like one of the exports in --out, or a link to one, is refused before
    anything is written (issue 30)."""
    folder = tmp_path / "x"
    folder.mkdir()
    given = folder / "design.obj"
    given.write_bytes(solution_file.read_bytes())
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (folder / "design_cutsheet.dxf").write_bytes(solution_file.read_bytes())
    link = elsewhere / "design.fold"
    link.symlink_to(folder / "design_cutsheet.dxf")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    for path, to in ((given, "obj,stl"), (link, "dxf"), (link, ",".join(EXPORT_FORMATS))):
        capsys.readouterr()
        assert main(["export", str(path), "--out", str(folder), "--to", to]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"would replace the input file '{path}'" in err[0]
        assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
