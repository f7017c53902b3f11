"""Thick panels (issue 39): cut outlines, the cost of the pairing, motion frames as evidence,
the one frame reader, ``--overwrite``, limits, files written together, progress."""

from __future__ import annotations

import errno
import json
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code
from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError

AFRAME = Path(__file__).parent / "data" / "aframe.fold"


def curved_grid(n: int):
    """An n x n vertex grid of triangles (each its own panel) on a paraboloid, 3 m x 3 m:
    2 (n - 1)^2 panels, with its development diagram."""
    from rigidfold.develop import develop
    from rigidfold.mesh import CreasePattern
    from rigidfold.patterns.grids import grid

    xy, tri = grid(n, n, 3.0, 3.0)
    z = 0.15 * ((xy[:, 0] - 1.5) ** 2 + (xy[:, 1] - 1.5) ** 2)
    pattern = CreasePattern.from_faces(np.column_stack([xy, z]), tri)
    return pattern, develop(pattern).coords2d


@pytest.fixture(scope="module")
def large(tmp_path_factory):
    """The 512 panels of a 17 x 17 curved grid 20 mm thick, bevelled for 2.005 degrees of
    clearance (not checked over a motion: the outlines and the nesting need none), and its
    cut sheets written: (fabrication, files)."""
    from rigidfold.fabricate import Panels, fabricate_panels
    from rigidfold.fabricate.cutsheets import cut_sheet_data
    from rigidfold.io.files import write_together

    pattern, flat = curved_grid(17)
    fab = fabricate_panels(Panels(pattern, flat, "bottom"), None, 0.02, clearance_angle=0.035)
    out = tmp_path_factory.mktemp("large")
    data, _ = cut_sheet_data(fab, out, "grid", width=2440, height=1220, gap=10)
    files = write_together(data)
    return fab, files


def test_every_cut_outline_is_one_simple_polygon(large):
    """Item 1: in every sheet (SVG and DXF) each panel's cut line is one closed sub-path, a
    simple polygon without holes: no slit into a panel, no panel cut in two."""
    import ezdxf
    import shapely

    fab, files = large
    cuts = 0
    for path in files:
        if path.suffix == ".svg":
            text = path.read_text()
            for d in re.findall(r'<path d="([^"]*)" fill="none" stroke="#000"', text):
                cuts += 1
                assert d.count("M") == 1, path.name
                ring = np.array(
                    [[float(v) for v in p.split()] for p in d[2:-2].split(" L ")], dtype=float
                )
                polygon = shapely.Polygon(ring)
                assert polygon.is_valid and polygon.area > 0, path.name
        else:
            doc = ezdxf.readfile(path)
            for line in doc.modelspace().query('LWPOLYLINE[layer=="CUT"]'):
                assert line.closed
                polygon = shapely.Polygon([p[:2] for p in line.get_points()])
                assert polygon.is_valid and polygon.area > 0, path.name
    assert cuts == fab.panels.n


def test_pairing_costs_the_parts_times_the_window(large, monkeypatch):
    """Item 5: the pairing by boxes offers a part only to the window of parts next to it
    in the order of their longest sides (before: every pair, n (n - 1) / 2, each pair
    built and kept), and still pairs most of the triangles, each pair keeping the gap."""
    from rigidfold.fabricate import cutsheets

    fab, _ = large
    items = cutsheets.parts(fab)
    calls = []
    offered = cutsheets._joined_boxes

    def counted(*args, **kwargs):
        calls.append(1)
        return offered(*args, **kwargs)

    monkeypatch.setattr(cutsheets, "_joined_boxes", counted)
    window = 4
    groups = cutsheets.group(items, 2440, 1220, 10, window=window)
    pairs = sum(len(g) == 2 for g in groups)
    assert len(calls) <= len(items) * window
    assert sorted(p.panel for g in groups for p in g) == list(range(len(items)))
    assert pairs >= len(items) // 4
    for g in groups:
        if len(g) == 2:
            assert g[0].cut.distance(g[1].cut) >= 10 - 1e-6
            assert g[0].width == pytest.approx(g[1].width) and g[0].width >= g[0].height


def _with_motion(source: Path, target: Path, frames: np.ndarray) -> Path:
    """``source`` written to ``target`` with ``frames`` (K, V, 3) as its motion frames."""
    from rigidfold.io import motion_frames, read_fold

    data = read_fold(source)
    raw = json.loads(source.read_text())
    fraction = np.linspace(0.0, 1.0, len(frames))
    raw["file_frames"] = motion_frames(data.pattern, frames, fraction)
    target.write_text(json.dumps(raw))
    return target


def test_frames_that_do_not_fold_are_not_trusted(tmp_path, capsys):
    """Item 2: a design whose 11 motion frames all equal the design (nothing folds) is not
    taken for its motion (the first frame is not flat): the path is traced, and the A-frame
    at 80 mm on the top side collides as with its true motion (exit 1)."""
    from rigidfold.exports.design import read_design
    from rigidfold.fabricate import Panels
    from rigidfold.fabricate.motion import design_motion, motion_evidence

    pattern = read_design(AFRAME).pattern
    fake = _with_motion(AFRAME, tmp_path / "fake.fold", np.repeat(pattern.coords[None], 11, 0))
    design = read_design(fake)
    panels = Panels(design.pattern, design.coords2d, "top")
    assert "first frame is not flat" in motion_evidence(
        panels, design.frames.motion, design.frames.fraction
    )
    motion, source = design_motion(panels, design)
    assert motion is not None and "traced" in source and "not its motion" in source
    args = ["fabricate", str(fake), "--thickness", "80mm", "--side", "top"]
    assert main_code([*args, "--out", str(tmp_path / "o")]) == 1
    assert "collide" in capsys.readouterr().out


def test_a_rigid_motion_is_evidence(tmp_path):
    """The traced motion written into the file is taken as it is (used when fine enough);
    a frame with a panel stretched is not."""
    from rigidfold.exports.design import read_design
    from rigidfold.fabricate import Panels
    from rigidfold.fabricate.motion import motion_evidence
    from rigidfold.mechanism.path import trace_path

    design = read_design(AFRAME)
    pattern = design.pattern
    frames, fraction = trace_path(pattern).frames(pattern, 11)
    panels = Panels(pattern, design.coords2d, "top")
    assert motion_evidence(panels, frames, fraction) == ""
    stretched = frames.copy()
    stretched[5] *= 1.01
    assert "does not move rigidly" in motion_evidence(panels, stretched, fraction)
    assert "not the design" in motion_evidence(panels, frames[:-1], fraction[:-1] / 0.9)


def test_frames_are_read_from_one_parse(tmp_path, monkeypatch):
    """Item 7 (issue 38): a design with 300 motion frames is parsed once, not once a frame
    (before: ``read_fold`` per frame), and its frames come back as written."""
    import rigidfold.io.fold as fold
    from rigidfold.exports.design import read_design
    from rigidfold.fabricate.motion import file_frames

    pattern = read_design(AFRAME).pattern
    frames = np.repeat(pattern.coords[None], 300, 0)
    frames[:, :, 2] *= np.linspace(0.0, 1.0, 300)[:, None]
    path = _with_motion(AFRAME, tmp_path / "many.fold", frames)
    parsed = []
    parse = fold._parse
    monkeypatch.setattr(fold, "_parse", lambda *a, **k: parsed.append(1) or parse(*a, **k))
    design = read_design(path)
    got = file_frames(design)
    assert len(parsed) == 1
    assert got is not None
    np.testing.assert_allclose(got[0], frames)
    np.testing.assert_allclose(got[1], np.linspace(0.0, 1.0, 300))


def test_frames_in_millimetres_are_read_in_metres():
    """A frame's own ``frame_unit`` converts its coordinates; a malformed frame is named."""
    from rigidfold.io import read_frames

    raw = {
        "file_frames": [
            {"frame_classes": ["foldedForm"], "frame_unit": "mm", "vertices_coords": [[1000, 0]]},
            {"frame_classes": ["foldedForm"], "vertices_coords": [[1, 2, 3]]},
        ]
    }
    frames = read_frames(raw, 1, "test")
    np.testing.assert_allclose(frames.motion[:, 0], [[1, 0, 0], [1, 2, 3]])
    raw["file_frames"][1]["vertices_coords"] = [[1, 2], [3, 4]]
    with pytest.raises(RigidfoldError, match=r"file_frames\[1\]"):
        read_frames(raw, 1, "test")


def test_overwrite_never_removes_a_directory(tmp_path, capsys):
    """Item 4: a directory where fabricate writes a file (with a user's file in it) is
    refused with or without --overwrite, in one line, and stays as it was."""
    out = tmp_path / "out"
    precious = out / "aframe_solids.glb" / "precious.txt"
    precious.parent.mkdir(parents=True)
    precious.write_text("mine")
    args = ["fabricate", str(AFRAME), "--thickness", "18mm", "--out", str(out)]
    for extra in ([], ["--overwrite"]):
        capsys.readouterr()
        assert main_code([*args, *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "aframe_solids.glb" in err
        assert precious.read_text() == "mine"


def test_no_solid_left_still_writes_its_files(tmp_path):
    """Item 9: with every panel trimmed away, the GLB and STL are written (valid, empty)
    instead of trimesh's "Can't export empty scenes"."""
    from types import SimpleNamespace

    import trimesh

    from rigidfold.fabricate.files import glb_bytes, stl_bytes
    from rigidfold.io import read_fold

    pattern = read_fold(AFRAME).pattern
    empty = (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    fab = SimpleNamespace(
        panels=SimpleNamespace(pattern=pattern), solids=SimpleNamespace(meshes=[empty] * 3)
    )
    (tmp_path / "a.glb").write_bytes(glb_bytes(fab))
    scene = trimesh.load(tmp_path / "a.glb", force="scene")
    assert len(scene.geometry) == 0
    stl = stl_bytes(fab)
    assert len(stl) == 84 and stl[80:] == b"\0\0\0\0"


def test_sheet_too_large_refused(tmp_path, capsys):
    """Item 8: a stock sheet beyond ``Settings.limits.max_sheet_size`` is refused in one
    line (exit 2), not an OverflowError or overflowing coordinates."""
    from rigidfold.fabricate import FabricateOptions

    with pytest.raises(RigidfoldError, match="max_sheet_size"):
        FabricateOptions(thickness=0.02, sheet=(1e308, 1e308))
    args = ["fabricate", str(AFRAME), "--thickness", "18mm", "--sheet", "1e308x1e308"]
    assert main_code([*args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err


def test_too_many_panels_refused():
    """A design of more panels than ``Settings.limits.max_fabricate_panels`` is refused in
    one line before anything is built."""
    from rigidfold.exports.design import read_design
    from rigidfold.fabricate import Panels, design_motion, fabricate_panels

    design = read_design(AFRAME)
    panels = Panels(design.pattern, design.coords2d, "top")
    settings = DEFAULTS.with_(max_fabricate_panels=2)
    for call in (
        lambda: design_motion(panels, design, settings=settings),
        lambda: fabricate_panels(panels, None, 0.02, settings=settings),
    ):
        with pytest.raises(RigidfoldError, match="3 panels is too large"):
            call()


def test_full_disk_leaves_no_partial_run(tmp_path, monkeypatch):
    """Item 12: a disk that fills up while the files are written leaves none of them (and
    no temporary file); the error says so in one line."""
    import rigidfold.io.files as files
    from rigidfold.fabricate import FabricateOptions
    from rigidfold.pipeline.workflows import fabricate_file

    synced = []
    fsync = files.os.fsync

    def full(fd):
        synced.append(fd)
        if len(synced) == 5:
            raise OSError(errno.ENOSPC, "No space left on device")
        fsync(fd)

    monkeypatch.setattr(files.os, "fsync", full)
    out = tmp_path / "out"
    with pytest.raises(RigidfoldError, match="none written") as caught:
        fabricate_file(AFRAME, out, FabricateOptions(thickness=0.018))
    assert "\n" not in str(caught.value)
    assert list(out.iterdir()) == []


def test_progress_on_stderr(tmp_path, capsys):
    """A design of at least ``fabricate_progress_panels`` panels gets a line on stderr as
    each long step begins; a smaller one none."""
    from rigidfold.fabricate import FabricateOptions
    from rigidfold.pipeline.workflows import fabricate_file

    settings = DEFAULTS.with_(fabricate_progress_panels=3)
    fabricate_file(AFRAME, tmp_path / "a", FabricateOptions(thickness=0.018), settings=settings)
    err = capsys.readouterr().err
    for step in ("tracing the folding path", "solids of 3 panels", "nesting", "writing"):
        assert step in err
    fabricate_file(AFRAME, tmp_path / "b", FabricateOptions(thickness=0.018))
    assert capsys.readouterr().err == ""


def test_sheets_have_a_legend_and_labels_apart(large):
    """Item 14: every nested sheet explains its lines and labels (a legend with the red
    dashed far face) and has a scale bar, below the stock; the labels of a part (its edges'
    and its number) do not overlap, each edge's along its edge."""
    import shapely

    from rigidfold.fabricate.cutsheets import Stock, _label_box, nest, parts

    fab, files = large
    for path in files:
        if path.suffix == ".svg":
            text = path.read_text()
            assert 'id="LEGEND"' in text and "far face" in text and " mm</text>" in text
    for sheet in nest(parts(fab), Stock(2440, 1220, 10)):
        for placed in sheet.parts:
            boxes = [_label_box(lab) for lab in placed.labels]
            mark = placed.part.mark
            assert mark is not None and placed.cut.contains(shapely.Point(placed.centre))
            number = shapely.Point(placed.centre).buffer(0.31 * mark.size * len(mark.text))
            for i, box in enumerate(boxes):
                assert not box.intersects(number), placed.part.panel
                assert not any(box.intersects(other) for other in boxes[i + 1 :])


def test_whole_pattern_labels_fill_their_creases():
    """Item 14: the whole-pattern cut sheet's crease labels are as large as their creases
    allow (never below the sheet's text height, larger where the crease is long), and
    none of the enlarged ones overlaps another label."""
    import shapely

    from rigidfold.exports.cutsheet import _box, crease_labels
    from rigidfold.exports.sheet import layout_sheet

    pattern, flat = curved_grid(9)
    sheet = layout_sheet(pattern, flat)
    labels = crease_labels(sheet)
    least = sheet.text_height
    assert all(label.size >= least * (1 - 1e-9) for label in labels)
    assert np.mean([label.size for label in labels]) > 1.2 * least
    boxes = [_box(label) for label in labels]
    first, second = shapely.STRtree(boxes).query(boxes, predicate="intersects")
    for i, j in zip(first, second, strict=True):
        if i != j:
            assert labels[i].size <= least * (1 + 1e-9), labels[i].text


def test_collision_pairs_from_a_kd_tree():
    """Item 5 (the check): the pairs of solids checked come from a k-d tree per frame, not
    from every pair; every pair left out has bounding spheres farther apart than the
    clearance and the thickness over every interval (the bound of the check itself,
    computed here for every pair by brute force), and the check's verdict holds."""
    from rigidfold.develop import develop
    from rigidfold.fabricate import Panels, design_motion, fabricate_panels
    from rigidfold.fabricate.collision import _move_bound, _near_pairs, _turn
    from rigidfold.patterns.miura import miura

    shape = miura(8, 8, length=0.3, width=0.3, offset=0.12, height=0.09)
    panels = Panels(shape, develop(shape).coords2d, "bottom")
    motion, _ = design_motion(panels)
    assert motion is not None
    fab = fabricate_panels(panels, motion, 0.02, search=False)
    assert fab.ok
    solids = fab.solids
    reach = DEFAULTS.fabricate.clearance(solids.thickness) + solids.thickness
    ia, ib = _near_pairs(solids, motion, reach)
    n = panels.n
    assert len(ia) < n * (n - 1) // 4
    kept = set(zip(ia.tolist(), ib.tolist(), strict=True))
    a, b = np.triu_indices(n, 1)
    centres = np.einsum("kpij,pj->kpi", motion.rotations, solids.centres) + motion.translations
    lower = (
        np.linalg.norm(centres[:, a] - centres[:, b], axis=2) - solids.radii[a] - solids.radii[b]
    )
    turn = np.linalg.norm(_turn(motion.rotations[:-1], motion.rotations[1:]), axis=-1)
    eps = _move_bound(np.linalg.norm(np.diff(centres, axis=0), axis=2), turn, solids.radii[None])
    proven = np.minimum(lower[:-1], lower[1:]) - eps[:, a] - eps[:, b]
    near = (proven < reach).any(axis=0)
    assert {(int(x), int(y)) for x, y in zip(a[near], b[near], strict=True)} <= kept
