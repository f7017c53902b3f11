"""`rigidfold develop`: FOLD with a creasePattern frame, SVG, JSON figures, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import run_cli
from rigidfold.cli.commands import main
from rigidfold.io import read_fold, svg_text, write_fold
from rigidfold.patterns import miura


@pytest.fixture
def miura_file(tmp_path):
    return write_fold(tmp_path / "miura.fold", miura(4, 3))


def test_develop_writes_frame_and_svg(miura_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["develop", str(miura_file), "--out", str(out), "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["D"] < 1e-10
    assert figures["flipped"] == 0 and figures["overlaps"] == 0
    raw = json.loads((out / "miura.fold").read_text())
    frame = raw["file_frames"][0]
    assert frame["frame_classes"] == ["creasePattern"]
    assert np.asarray(frame["vertices_coords"]).shape == (len(raw["vertices_coords"]), 2)
    # the crease-pattern frame reads back as the flat sheet with the same edge lengths
    flat = read_fold(out / "miura.fold", frame=1).pattern
    folded = read_fold(out / "miura.fold").pattern
    assert np.allclose(flat.coords[:, 2], 0.0)
    assert np.allclose(flat.edge_lengths, folded.edge_lengths, rtol=1e-5)
    svg = (out / "miura.svg").read_text()
    assert svg.startswith("<svg") and svg.count("<line") == folded.n_edges


def test_svg_colours_by_assignment():
    shape = miura(3, 3)
    svg = svg_text(shape, shape.coords[:, :2])
    assert "#000000" in svg  # boundary
    assert "stroke-dasharray" in svg  # fixed diagonals
    assert "#d62728" in svg and "#1f77b4" in svg  # mountains and valleys


def test_develop_bad_input(tmp_path):
    bad = tmp_path / "bad.fold"
    bad.write_text("{oops")
    proc = run_cli("develop", str(bad), "--out", str(tmp_path / "o"))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "invalid JSON" in proc.stderr


def test_develop_reads_a_y_up_file(miura_file, tmp_path, capsys):
    """--up y turns a file drawn y-up (its (x, y, z) is rigidfold's (x, -z, y)) z-up."""
    raw = json.loads(miura_file.read_text())
    raw["vertices_coords"] = [[x, z, -y] for x, y, z in raw["vertices_coords"]]
    turned = tmp_path / "miura_y.fold"
    turned.write_text(json.dumps(raw))
    assert main(["develop", str(turned), "--out", str(tmp_path / "y"), "--up", "y", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["D"] < 1e-10
    out = json.loads((tmp_path / "y" / "miura_y.fold").read_text())
    assert out["vertices_coords"] == raw["vertices_coords"]  # the input as it was
    assert out["rigidfold:input"]["up"] == "y"
    folded = read_fold(tmp_path / "y" / "miura_y.fold", frame=2).pattern  # rigidfold's, z up
    np.testing.assert_allclose(folded.coords, read_fold(miura_file).pattern.coords, atol=1e-15)


def test_develop_refuses_to_replace_its_input(miura_file, tmp_path):
    before = miura_file.read_bytes()
    proc = run_cli("develop", str(miura_file), "--out", str(miura_file.parent))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "would replace the input" in proc.stderr
    assert miura_file.read_bytes() == before


def test_deform_refuses_to_replace_its_input(miura_file):
    """deform writes NAME.fold too: into the input's folder it is refused before any work."""
    before = miura_file.read_bytes()
    proc = run_cli("deform", str(miura_file), "--out", str(miura_file.parent))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "would replace the input" in proc.stderr
    assert miura_file.read_bytes() == before
    assert sorted(p.name for p in miura_file.parent.iterdir()) == [miura_file.name]
