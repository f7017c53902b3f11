"""Step 9's frame model with the user's panels (``rigidfold deform --material --thickness``):
the members as strips of the panel; the paper's tubes when no material is given."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidfold.cli.commands import main
from rigidfold.deform import deform, panel_section
from rigidfold.io import write_fold
from rigidfold.mesh.geometry import face_areas
from rigidfold.patterns import miura
from rigidfold.structure import MATERIALS
from test_deform import locked_miura


@pytest.fixture(scope="module")
def shape():
    return miura(3, 3)


def test_panel_section_shares_each_triangle_among_its_members(shape):
    """The triangles' members hold the panels' area (sum of b l = area), one rectangle
    b x t each, bending out of the plane as b t^3 / 12."""
    t = 0.018
    sec = panel_section(shape, MATERIALS["plywood"], t)
    F = shape.n_faces
    x = shape.coords
    bary = x[shape.faces].mean(axis=1)
    ends = 0.5 * (x[shape.edges[shape.face_edges, 0]] + x[shape.edges[shape.face_edges, 1]])
    length = np.linalg.norm(ends - bary[:, None], axis=2).ravel()
    area = face_areas(x, shape.faces)
    assert np.allclose((sec.width[: 3 * F] * length).reshape(F, 3).sum(axis=1), area)
    assert np.allclose(sec.A, sec.width * t) and np.allclose(sec.I_out, sec.width * t**3 / 12)
    assert np.allclose(sec.I_in, t * sec.width**3 / 12)
    assert len(sec.width) == 3 * F + 2 * len(shape.free_creases)
    assert np.allclose(np.linalg.norm(sec.normal, axis=1), 1)


def test_plywood_frame_reaches_the_plane_and_a_locked_one_does_not(shape):
    """The Miura-ori folds flat in a frame of 18 mm plywood strips as in the paper's tubes;
    with one crease made rigid it must deform at least ten times more and stops short."""
    ply = MATERIALS["plywood"]
    free = deform(shape, material=ply, thickness=0.018)
    locked = deform(locked_miura(shape), material=ply, thickness=0.018)
    assert free.reached_plane and free.mean_dl_mm < 0.1
    assert locked.mean_dl_mm >= 10 * max(free.mean_dl_mm, 1e-6)
    assert not locked.reached_plane


def test_no_material_is_the_papers_tubes(shape):
    a, b = deform(shape), deform(shape, material=None, thickness=None)
    assert a.mean_dl_mm == b.mean_dl_mm and a.max_drho_fix_deg == b.max_drho_fix_deg


def test_deform_cli_material_and_thickness(shape, tmp_path, capsys):
    src = write_fold(tmp_path / "miura.fold", shape)
    out = tmp_path / "out"
    args = ["--material", "plywood", "--thickness", "0.018", "--json"]
    code = main(["deform", str(src), "--out", str(out), *args])
    report = json.loads(capsys.readouterr().out)
    assert code == 0 and report["reached_plane"]
    assert report["frame_section"]["kind"] == "panel"
    assert report["frame_section"]["material"]["name"] == "plywood"
    saved = json.loads((out / "miura_deform.json").read_text())
    assert saved["frame_section"]["thickness_m"] == 0.018
    for flag, bad, name in (("--thickness", "-1", "x"), ("--material", "cheese", "y")):
        with pytest.raises(SystemExit) as refused:  # refused by the parser, in one line
            main(["deform", str(src), "--out", str(tmp_path / name), flag, bad])
        assert refused.value.code == 2 and f"argument {flag}" in capsys.readouterr().err
    args = ["--thickness", "18mm", "--json"]  # a unit, as the other commands take it
    assert main(["deform", str(src), "--out", str(tmp_path / "mm"), *args]) == 0
    section = json.loads(capsys.readouterr().out)["frame_section"]
    assert section["thickness_m"] == pytest.approx(0.018)
    assert not (tmp_path / "x").exists() or not any((tmp_path / "x").iterdir())
