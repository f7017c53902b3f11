"""Thick panels (rigidfold fabricate): solids, the check over the motion, files, exit codes."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code
from rigidfold.config import DEFAULTS
from rigidfold.fabricate import FabricateOptions
from rigidfold.structure import MATERIALS

DESIGN_ARGS = [
    "generate",
    "--surface",
    "bezier",
    "--seed",
    "1",
    "--pattern",
    "grid:5x5",
    "--size",
    "3x3",
    "--lookahead",
    "--no-deform",
    "--quiet",
    "--no-report",
]


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    """A small generated design (5 x 5 grid on 3 m x 3 m) with its motion frames."""
    out = tmp_path_factory.mktemp("design")
    assert main_code([*DESIGN_ARGS, "--out", str(out)]) == 0
    (final,) = sorted((out / "solutions").glob("*_dof_01.fold"))
    return final


@pytest.fixture(scope="module")
def built(design, tmp_path_factory):
    """``rigidfold fabricate`` at 20 mm and 50 mm: {thickness: (exit code, out dir, summary)}."""
    from rigidfold.pipeline.workflows import fabricate_file

    runs = {}
    for t in (0.02, 0.05):
        out = tmp_path_factory.mktemp(f"fab{int(t * 1e3)}")
        code = main_code(
            ["fabricate", str(design), "--thickness", f"{t * 1e3:g}mm", "--out", str(out)]
        )
        summary = json.loads((out / f"{design.stem}_fabricate.json").read_text())
        runs[t] = (code, out, summary)
    runs["result"] = fabricate_file(
        design, tmp_path_factory.mktemp("lib"), FabricateOptions(thickness=0.02)
    )
    return runs


@pytest.mark.parametrize("t", [0.02, 0.05])
def test_deploys_collision_free(built, t):
    code, _, summary = built[t]
    assert code == 0
    assert summary["status"] == "collision_free"
    check = summary["check"]
    assert check["collision_free"]
    assert check["proven_gap_m"] >= check["required_gap_m"]
    assert check["hinge_margin_deg"] >= 0
    assert summary["motion"]["frames"] >= 2


@pytest.mark.parametrize("t", [0.02, 0.05])
def test_solids_watertight_one_per_panel(built, t):
    import trimesh

    _, out, summary = built[t]
    scene = trimesh.load(next(out.glob("*_solids.glb")), force="scene")
    names = sorted(scene.geometry)
    assert len(names) == summary["panels"]
    for name in names:
        mesh = scene.geometry[name]
        assert mesh.is_watertight and mesh.is_winding_consistent, name
        assert mesh.volume > 0
    area, volume = summary["area_m2"], summary["volume_m3"]
    assert abs(volume - area * t) <= 0.4 * area * t
    assert summary["trimming_loss"] == pytest.approx(1 - volume / (area * t))
    assert 0 <= summary["trimming_loss"] < 0.4


def test_independent_no_interpenetration(built):
    """Every solid moved rigidly onto every motion frame (its vertices fitted by least
    squares, here, not by the code under test) overlaps no other solid: manifold3d
    intersection volumes are round-off only."""
    import manifold3d as mf

    fab = built["result"].fabrication
    panels = fab.panels
    pattern = panels.pattern
    from rigidfold.fabricate.motion import file_frames

    carried = file_frames(built["result"].design)
    from rigidfold.mechanism.path import trace_path

    path = trace_path(pattern)
    assert path.deploys
    frames, _ = path.frames(pattern, 15)
    if carried is not None:
        frames = np.concatenate([frames, carried[0]])
    solids = [
        mf.Manifold(
            mf.Mesh64(vert_properties=np.ascontiguousarray(v), tri_verts=f.astype(np.uint64))
        )
        for v, f in fab.solids.meshes
    ]
    worst = 0.0
    for frame in frames:
        moved = []
        for k, solid in enumerate(solids):
            idx = panels.vertices[k]
            src, dst = pattern.coords[idx], frame[idx]
            cs, cd = src.mean(axis=0), dst.mean(axis=0)
            u, _, vt = np.linalg.svd((src - cs).T @ (dst - cd))
            d = np.sign(np.linalg.det(vt.T @ u.T))
            rot = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
            moved.append(solid.transform(np.hstack([rot, (cd - rot @ cs)[:, None]])))
        boxes = np.array([m.bounding_box() for m in moved])
        for a in range(len(moved)):
            for b in range(a + 1, len(moved)):
                if np.any(boxes[a, 3:] < boxes[b, :3]) or np.any(boxes[b, 3:] < boxes[a, :3]):
                    continue
                worst = max(worst, (moved[a] ^ moved[b]).volume())
    smallest = float(fab.solids.volumes.min())
    assert worst <= 1e-9 * smallest


def test_collision_reported_with_panels_and_fraction(design, tmp_path, capsys):
    """Without reliefs at the vertices, panels that meet at a vertex only touch there all the
    way: the check names them and the fraction (exit 1), and a thinner try is reported."""
    from rigidfold.config import DEFAULTS
    from rigidfold.fabricate import FabricationStatus
    from rigidfold.pipeline.workflows import fabricate_file

    settings = DEFAULTS.with_(
        fabricate_vertex_relief=0.0, fabricate_relief_rounds=0, fabricate_thickness_tries=2
    )
    done = fabricate_file(design, tmp_path, FabricateOptions(thickness=0.05), settings=settings)
    fab = done.fabrication
    assert fab.status is FabricationStatus.COLLISION
    meeting = fab.clearance.meetings[0]
    assert meeting.panels[0] < meeting.panels[1]
    assert 0.0 <= meeting.fraction <= 1.0
    line = fab.last_line()
    assert f"panels {meeting.panels[0]} and {meeting.panels[1]}" in line
    assert "% folded" in line
    assert (tmp_path / f"{design.stem}_fabricate.json").exists()


def test_cli_exit_1_too_thick(design, tmp_path, capsys):
    """Panels too thick for their bevels and reliefs: exit 1, the files written all the
    same, and the last line names a panel and a thinner thickness that passes."""
    code = main_code(["fabricate", str(design), "--thickness", "400mm", "--out", str(tmp_path)])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert code == 1
    assert "at 400 mm" in last and "panel" in last and "would pass" in last
    assert any(tmp_path.glob("*_solids.3dm"))
    summary = json.loads(next(tmp_path.glob("*_fabricate.json")).read_text())
    assert summary["status"] in ("panel_trimmed_away", "too_thin", "collision")
    assert 0 < summary["passing_thickness_m"] < 0.4


def test_rhino_model(built):
    import rhino3dm

    _, out, summary = built[0.02]
    model = rhino3dm.File3dm.Read(str(next(out.glob("*_solids.3dm"))))
    layers = {model.Layers[i].Name: i for i in range(len(model.Layers))}
    assert set(layers) >= {"PANELS", "HINGES", "CREASES", "LABELS"}
    on = {name: [] for name in layers}
    for obj in model.Objects:
        on[model.Layers[obj.Attributes.LayerIndex].Name].append(obj)
    panels = on["PANELS"]
    assert len(panels) == summary["panels"]
    assert len({o.Attributes.Name for o in panels}) == summary["panels"]
    assert all(isinstance(o.Geometry, rhino3dm.Mesh) for o in panels)
    assert len(on["HINGES"]) == summary["hinges"]
    assert len(on["LABELS"]) == summary["panels"]


def test_cut_sheets_every_panel_once_within_stock(built):
    import ezdxf

    _, out, summary = built[0.02]
    width, height = summary["cut_sheets"]["stock_mm"]
    seen = []
    for path in sorted(out.glob("*_sheet_*.dxf")):
        doc = ezdxf.readfile(path)
        msp = doc.modelspace()
        (sheet,) = msp.query('LWPOLYLINE[layer=="SHEET"]')
        pts = np.array([p[:2] for p in sheet.get_points()])
        assert np.ptp(pts[:, 0]) <= width + 1e-6 and np.ptp(pts[:, 1]) <= height + 1e-6
        for poly in msp.query('LWPOLYLINE[layer=="CUT"]'):
            q = np.array([p[:2] for p in poly.get_points()])
            assert q.min() >= -1e-6 and q[:, 0].max() <= width + 1e-6
            assert q[:, 1].max() <= height + 1e-6
        seen += [
            t.dxf.text for t in msp.query('TEXT[layer=="LABELS"]') if t.dxf.text.startswith("P")
        ]
    oversize = summary["cut_sheets"]["oversize_panels"]
    for path in sorted(out.glob("*_oversize_*.dxf")):  # a part larger than the stock
        msp = ezdxf.readfile(path).modelspace()
        (poly,) = msp.query('LWPOLYLINE[layer=="SHEET"]')
        pts = np.array([p[:2] for p in poly.get_points()])
        w, h = np.ptp(pts, axis=0)
        assert max(w, h) > min(width, height) and (max(w, h) > width or min(w, h) > height)
        seen += [
            t.dxf.text for t in msp.query('TEXT[layer=="LABELS"]') if t.dxf.text.startswith("P")
        ]
    assert len(oversize) == len(list(out.glob("*_oversize_*.dxf")))

    assert sorted(seen) == sorted(f"P{k}" for k in range(summary["panels"]))
    assert len(list(out.glob("*_sheet_*.svg"))) == summary["cut_sheets"]["sheets"]


def test_nesting_keeps_the_gap(built):
    """Parts nested onto one sheet (by outlines, or by boxes joined in pairs or not) keep the
    gap between them and from the sheet's edges, are turned and never mirrored, and every
    panel is placed once; the sheets kept are no more than the boxes take, and the same
    every time."""
    from rigidfold.fabricate.cutsheets import Stock, nest, nest_boxes, nest_by_outlines, parts
    from test_fabricate_nesting import check_nesting

    fab = built["result"].fabrication
    items = parts(fab)
    sheets = nest(items, Stock(2440, 1220, 10))
    placed = sorted(p.part.panel for s in sheets for p in s.parts)
    assert placed == list(range(fab.panels.n))
    check_nesting(sheets, items, 2440, 1220, 10)
    boxes = nest_boxes(items, Stock(2440, 1220, 10))
    check_nesting(boxes, items, 2440, 1220, 10)
    on_stock = {p.part.panel for s in boxes if not s.oversize for p in s.parts}
    fitting = [p for p in items if p.panel in on_stock]  # not the oversize ones
    outlines = nest_by_outlines(fitting, Stock(2440, 1220, 10))
    assert outlines is not None
    check_nesting(outlines, fitting, 2440, 1220, 10)
    assert sum(not s.oversize for s in sheets) <= sum(not s.oversize for s in boxes)
    again = nest(items, Stock(2440, 1220, 10))
    assert [[(p.part.panel, p.cut.wkt) for p in s.parts] for s in again] == [
        [(p.part.panel, p.cut.wkt) for p in s.parts] for s in sheets
    ]


def test_schedules(built):
    _, out, summary = built[0.02]
    hinges = list(csv.DictReader(next(out.glob("*_hinges.csv")).read_text().splitlines()))
    assert len(hinges) == summary["hinges"]
    for row in hinges:
        bevel = float(row["bevel_deg"])
        assert 0 < bevel < 90
        assert float(row["fold_max_deg"]) + summary["clearance_angle_deg"] <= (
            float(row["fold_limit_deg"]) + 1e-6
        )
        assert math.isclose(bevel, (180 - max(float(row["fold_max_deg"]), 0) - 2) / 2, abs_tol=1e-3)
    vertices = list(csv.DictReader(next(out.glob("*_vertices.csv")).read_text().splitlines()))
    assert vertices and {"x_m", "flat_x_m", "relief_mm"} <= set(vertices[0])
    per_panel = summary["per_panel"]
    assert len(per_panel) == summary["panels"]
    rho = MATERIALS[DEFAULTS.structure.material].density  # the default panels' material
    assert all(p["mass_kg"] == pytest.approx(rho * p["volume_m3"]) for p in per_panel)


@pytest.mark.parametrize(
    "args",
    [
        ["--thickness", "-3mm"],
        ["--thickness", "abc"],
        ["--thickness", "20mm", "--sheet", "2440by1220"],
        ["--thickness", "20mm", "--clearance-angle", "95"],
    ],
)
def test_bad_input_exits_2(design, tmp_path, capsys, args):
    code = main_code(["fabricate", str(design), "--out", str(tmp_path), *args])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err


def test_missing_file_exits_2(tmp_path, capsys):
    code = main_code(
        [
            "fabricate",
            str(tmp_path / "none.fold"),
            "--thickness",
            "20mm",
            "--out",
            str(tmp_path / "o"),
        ]
    )
    assert code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_parse_length():
    from rigidfold.cli.units import parse_length, parse_sheet

    assert parse_length("18mm") == pytest.approx(0.018)
    assert parse_length("1.8cm") == pytest.approx(0.018)
    assert parse_length("0.018") == pytest.approx(0.018)
    assert parse_sheet("2440x1220") == (2440.0, 1220.0)
    with pytest.raises(ValueError, match="thickness"):
        parse_length("0")
    with pytest.raises(ValueError, match="at most"):
        parse_sheet("1e308x10")
    with pytest.raises(ValueError, match="thickness must be a positive length"):
        FabricateOptions("18mm")  # the library takes metres; the command line reads text


def test_earlier_fabricate_refused_unless_overwrite(design, tmp_path, capsys):
    """A second fabricate into the same DIR is refused (exit 2, one line naming the files,
    nothing touched); with --overwrite the earlier run's files that its NAME_fabricate.json
    recorded go (a recorded sheet 98 that the new run does not write is not left behind);
    every other file stays, a sheet the earlier run did not record (99) too (issue 47)."""
    out = tmp_path / "out"
    args = ["fabricate", str(design), "--thickness", "20mm", "--out", str(out)]
    assert main_code(args) == 0
    stem = design.stem
    summary = out / f"{stem}_fabricate.json"
    before = summary.read_bytes()
    stale = out / f"{stem}_sheet_99.svg"
    stale.write_text("<svg/>")
    recorded = out / f"{stem}_sheet_98.svg"  # as if the earlier run had written 98 sheets
    recorded.write_text("<svg/>")
    record = json.loads(summary.read_text())
    record["written"].append(str(recorded))
    summary.write_text(json.dumps(record))
    before = summary.read_bytes()
    other = out / "notes.txt"
    other.write_text("mine")
    capsys.readouterr()
    assert main_code(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--overwrite" in err and f"{stem}_solids.glb" in err
    assert summary.read_bytes() == before and stale.exists()
    assert main_code([*args, "--overwrite"]) == 0
    assert not recorded.exists() and stale.read_text() == "<svg/>"
    assert other.read_text() == "mine"
    done = json.loads(summary.read_text())
    assert len(list(out.glob(f"{stem}_sheet_*.svg"))) == done["cut_sheets"]["sheets"] + 1


def test_a_failed_overwrite_keeps_the_earlier_files_and_names_the_cause(design, tmp_path):
    """Issue 47, item 5: under ``ulimit -f 100`` ``fabricate --overwrite`` removed the 17
    files of the earlier run, wrote none and blamed rhino3dm. The new files are written
    aside first: a write past the file size limit leaves every earlier file as it was, no
    temporary file, and the message names the limit."""
    from conftest import files_of, run_cli_size_limited

    out = tmp_path / "out"
    args = ["fabricate", str(design), "--thickness", "20mm", "--out", str(out)]
    assert main_code(args) == 0
    before = files_of(out)
    biggest = max(len(b) for b in before.values())
    res = run_cli_size_limited(biggest // 2, *args, "--overwrite")
    err = res.stderr.strip()
    assert res.returncode == 2 and len(err.splitlines()) == 1, err
    assert "file size limit" in err and "rhino3dm" not in err, err
    assert files_of(out) == before


def test_only_a_stale_sheet_counts_as_earlier(design, tmp_path, capsys):
    """A cut sheet alone of an earlier fabricate of the same design is an earlier run's file;
    another design's files are not."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "other_sheet_01.dxf").write_text("x")
    args = ["fabricate", str(design), "--thickness", "20mm", "--out", str(out)]
    (out / f"{design.stem}_oversize_03.dxf").write_text("x")
    assert main_code(args) == 2
    assert f"{design.stem}_oversize_03.dxf" in capsys.readouterr().err
    (out / f"{design.stem}_oversize_03.dxf").unlink()
    assert main_code(args) == 0
    assert (out / "other_sheet_01.dxf").read_text() == "x"


def test_never_replaces_its_input(design, tmp_path, capsys):
    """An input named like one of the outputs is refused, with or without --overwrite, and
    stays as it was."""
    out = tmp_path / "out"
    out.mkdir()
    # an input whose name is one of the files fabricate of a design named "d" writes
    source = out / "d_solids.glb"
    source.write_bytes(design.read_bytes())
    link = out / "d.fold"
    link.symlink_to(source.name)
    for extra in ([], ["--overwrite"]):
        code = main_code(["fabricate", str(link), "--thickness", "20mm", "--out", str(out), *extra])
        err = capsys.readouterr().err.strip()
        assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
        assert source.read_bytes() == design.read_bytes()


AFRAME = Path(__file__).parent / "data" / "aframe.fold"
"""An A-frame shelter: a 1 m x 1 m floor and two 0.9 m walls folded up 120 degrees."""

AFRAME_THRESHOLD = 0.1 / (2 * math.sin(math.radians(60)) + DEFAULTS.fabricate.clearance_share)
"""The thickest walls of ``aframe.fold`` that keep the clearance (5 % of the thickness) at the
ridge (metres): the walls' top edges are 100 mm apart in the design, each wall leans 60
degrees from the floor, so a wall's inner top corner moves ``t sin(60)`` towards the other:
``0.1 - 2 t sin(60) >= 0.05 t``."""


@pytest.fixture(scope="module")
def aframe(tmp_path_factory):
    """``fabricate`` of the A-frame shelter (tests/data/aframe.fold: a 1 m floor and two
    0.9 m walls folded up 120 degrees, their top edges 100 mm apart) with 80 mm panels on
    the side the walls fold towards: (exit code, last line, out dir, summary)."""
    out = tmp_path_factory.mktemp("aframe")
    args = ["fabricate", str(AFRAME), "--thickness", "80mm", "--side", "top", "--out", str(out)]
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main_code(args)
    last = buf.getvalue().strip().splitlines()[-1]
    return code, last, out, json.loads((out / "aframe_fabricate.json").read_text())


def test_aframe_walls_collide_at_the_ridge(aframe):
    """Two panels that are not neighbours (the walls, joined only through the floor) truly
    collide at 80 mm while no panel is trimmed: exit 1, the last line names them, the
    fraction folded where they meet and a thickness that would pass; that thickness lies
    just below the ridge's exact limit 0.1 m / (2 sin 60 degrees + 0.05) = 56.1 mm."""
    code, last, out, summary = aframe
    assert code == 1
    assert summary["status"] == "collision"
    assert all(p["depth_m"] == pytest.approx(0.08) for p in summary["per_panel"])
    assert summary["trimming_loss"] < 0.2
    meeting = summary["check"]["meetings"][0]
    assert meeting["panels"] == [1, 2] and meeting["kind"] == "gap"
    assert meeting["vertex"] == -1  # no vertex in common: no relief can help
    assert 0 < meeting["fraction"] <= meeting["worst_fraction"] <= 1
    assert last.startswith("thick panels collide during the deployment at 80 mm")
    assert "panels 1 and 2 meet at" in last and "% folded" in last and "would pass" in last
    passing = summary["passing_thickness_m"]
    assert 0.05 <= passing <= AFRAME_THRESHOLD
    hinges = list(csv.DictReader(next(out.glob("*_hinges.csv")).read_text().splitlines()))
    assert [row["side"] for row in hinges] == ["closes", "closes"]


def test_aframe_collision_independent(aframe):
    """The collision is real: the walls' solids as written (GLB) overlap in the design
    (manifold3d intersection volume > 0)."""
    import manifold3d as mf
    import trimesh

    _, _, out, _ = aframe
    scene = trimesh.load(next(out.glob("*_solids.glb")), force="scene")
    walls = []
    for name in ("panel_1", "panel_2"):
        mesh = scene.geometry[name]
        verts = np.asarray(mesh.vertices, dtype=np.float64)
        walls.append(
            mf.Manifold(
                mf.Mesh64(
                    vert_properties=np.ascontiguousarray(verts),
                    tri_verts=np.asarray(mesh.faces, dtype=np.uint64),
                )
            )
        )
    assert (walls[0] ^ walls[1]).volume() > 1e-6


def test_aframe_passes_thinner_or_on_the_other_side(tmp_path):
    """Just below the ridge's limit the same walls pass (exit 0), and so do 80 mm panels
    on the side the walls fold away from."""
    thin = f"{math.floor(AFRAME_THRESHOLD * 1e3) - 1}mm"
    for args in (["--thickness", thin, "--side", "top"], ["--thickness", "80mm"]):
        out = tmp_path / args[1]
        assert main_code(["fabricate", str(AFRAME), "--out", str(out), *args]) == 0
