"""FOLD files of other tools: units, up axis, faithful round trip, flat crease patterns.

The examples in tests/data/fold_examples are those of the `fold` package (MIT, see the README
there).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.io import UNITS, fold_dict, read_fold, round_trip_dict, write_fold
from rigidfold.mesh import CreasePattern
from rigidfold.patterns import miura
from rigidfold.pipeline.workflows import FLAT_NOTE, UNITLESS_NOTE, analyze_file, develop_file

EXAMPLES = Path(__file__).parent / "data" / "fold_examples"
READABLE = {"simple": 3, "diagonal-cp": 1, "squaretwist": 1}  # example -> DOF
REFUSED = ["box", "diagonal-folded"]


def load(path: Path) -> dict:
    return json.loads(Path(path).read_text())


def rigidfold_frames(document: dict, source: dict) -> list[dict]:
    """The frames rigidfold appended after the input's."""
    return document["file_frames"][len(source.get("file_frames", [])) :]


def write(tmp_path: Path, name: str, document: dict) -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(document))
    return path


# ---------------------------------------------------------------------------------- round trip
@pytest.mark.parametrize("name", list(READABLE))
def test_develop_keeps_every_key_of_the_input(tmp_path, name):
    source = EXAMPLES / f"{name}.fold"
    checked = develop_file(source, tmp_path / "out")
    assert checked.verification.development.status == "converged"
    original, output = load(source), load(tmp_path / "out" / f"{name}.fold")
    for key, value in original.items():
        assert output[key] == value, key
    added = set(output) - set(original)
    assert all(k.startswith("rigidfold:") for k in added - {"file_frames"})
    assert output["rigidfold:input"] == {"unit": "unit", "metres_per_unit": 1.0, "up": "z"}
    diagram, folded = rigidfold_frames(output, original)
    assert diagram["frame_classes"] == ["creasePattern"] and diagram["frame_unit"] == "m"
    assert diagram["frame_title"].startswith("rigidfold: ")
    assert folded["frame_title"].startswith("rigidfold: ")
    assert (diagram["frame_parent"], diagram["frame_inherit"]) == (0, False)
    assert (folded["frame_parent"], folded["frame_inherit"]) == (1, True)
    # rigidfold's frames read back as its triangulated model, in metres
    pattern = read_fold(source).pattern
    flat = read_fold(tmp_path / "out" / f"{name}.fold", frame=1)
    again = read_fold(tmp_path / "out" / f"{name}.fold", frame=2)
    assert flat.unit == again.unit == "m"
    np.testing.assert_array_equal(flat.pattern.edges, pattern.edges)
    np.testing.assert_array_equal(flat.pattern.fixed, pattern.fixed)
    np.testing.assert_array_equal(again.pattern.coords, pattern.coords)
    assert np.allclose(flat.pattern.edge_lengths, pattern.edge_lengths, rtol=1e-6)
    assert analyze_file(source).mechanism.dof == READABLE[name]


def test_a_180_degree_crease_is_never_flat(tmp_path):
    """The flat crease pattern's valley (fold angle 180 in the file) stays "V" everywhere."""
    source = EXAMPLES / "diagonal-cp.fold"
    develop_file(source, tmp_path)
    output = load(tmp_path / "diagonal-cp.fold")
    assert output["edges_assignment"] == ["B", "B", "B", "B", "V"]
    assert output["edges_foldAngle"] == [0, 0, 0, 0, 180]
    diagram = rigidfold_frames(output, load(source))[0]
    assert diagram["edges_assignment"] == ["B", "B", "B", "B", "V"]
    assert "#1f77b4" in (tmp_path / "diagonal-cp.svg").read_text()  # drawn as a valley
    # a 3D form with 180-degree mountain folds keeps them "M"
    develop_file(EXAMPLES / "simple.fold", tmp_path)
    diagram = rigidfold_frames(load(tmp_path / "simple.fold"), {})[0]
    assert diagram["edges_assignment"][:3] == ["V", "M", "M"]


def test_unassigned_creases_get_the_letter_of_their_fold_angle():
    document = fold_dict(miura(3, 3))
    measured = list(document["edges_assignment"])
    document["edges_assignment"] = ["U" if a in "MV" else a for a in measured]
    assert set(measured) == {"B", "M", "V", "J"}
    assert read_fold(document).shape_assignment() == measured


def test_input_frames_and_custom_keys_are_kept(tmp_path):
    """Existing frames stay first, rigidfold's come after them with their parents shifted."""
    document = load(EXAMPLES / "squaretwist.fold")
    document["file_frames"] = [
        {"frame_title": "theirs", "frame_parent": 0, "frame_inherit": True, "x:tag": [1, 2]}
    ]
    document["faceOrders"] = [[0, 1, 1]]
    document["edges_x:weight"] = list(range(len(document["edges_vertices"])))
    path = write(tmp_path, "twist.fold", document)
    develop_file(path, tmp_path / "out")
    output = load(tmp_path / "out" / "twist.fold")
    for key, value in document.items():
        if key != "file_frames":
            assert output[key] == value, key
    assert output["file_frames"][0] == document["file_frames"][0]
    diagram, folded = output["file_frames"][1:]
    assert diagram["frame_classes"] == ["creasePattern"] and diagram["frame_parent"] == 0
    assert folded["frame_parent"] == 2
    assert read_fold(tmp_path / "out" / "twist.fold", frame=2).frame_classes == ["creasePattern"]
    np.testing.assert_array_equal(
        read_fold(tmp_path / "out" / "twist.fold", frame=3).pattern.coords,
        read_fold(path).pattern.coords,
    )


def test_deform_appends_the_motion_under_the_diagram(tmp_path):
    """A FOLD file of another tool (a Miura-ori, written as theirs) keeps every key; the
    development diagram and the folding motion are appended under it."""
    from rigidfold.patterns import miura

    src = write_fold(tmp_path / "theirs.fold", miura(3, 3))
    assert main(["deform", str(src), "--out", str(tmp_path / "out")]) == 0
    output = load(tmp_path / "out" / "theirs.fold")
    frames = output["file_frames"]
    assert frames[0]["frame_classes"] == ["creasePattern"]
    motion = frames[1:-1]
    assert 3 <= len(motion) <= DEFAULTS.deformation.motion_frames
    assert all(f["frame_parent"] == 1 and f["frame_inherit"] for f in motion)
    assert all(f["frame_title"].startswith("rigidfold: folding motion") for f in motion)
    first = read_fold(tmp_path / "out" / "theirs.fold", frame=2)  # the motion's flat frame
    assert first.unit == "m" and np.abs(first.pattern.coords[:, 2]).max() < 1e-9
    for key, value in load(src).items():
        if key != "file_frames":
            assert output[key] == value, key


def test_a_square_twist_is_not_rigidly_deployable(tmp_path):
    """The square twist of the FOLD examples (its quads rigid): its folding path does not reach
    the flat state (the square twist needs its panels to bend), so ``deform`` says the motion
    was not traced and keeps the traced part out of the file. The OpenSees frame, whose
    members may bend, gets to the plane (exit 0)."""
    assert main(["deform", str(EXAMPLES / "squaretwist.fold"), "--out", str(tmp_path)]) == 0
    output = load(tmp_path / "squaretwist.fold")
    assert not any("folding motion" in f.get("frame_title", "") for f in output["file_frames"])
    assert output["rigidfold:motion"]["status"] == "failed"
    assert output["rigidfold:motion"]["path"]["deploys"] is False


def test_round_trip_dict_does_not_modify_the_input():
    document = load(EXAMPLES / "squaretwist.fold")
    document["file_frames"] = [{"frame_title": "theirs"}]
    document["x:nan"] = float("nan")
    before = copy.deepcopy(document)
    data = read_fold(document)
    out = round_trip_dict(data, data.pattern.coords[:, :2], metadata={"a": 1})
    assert document.keys() == before.keys() and document["file_frames"] == before["file_frames"]
    assert out["x:nan"] is None  # JSON has no NaN
    assert out["rigidfold:a"] == 1
    assert len(out["file_frames"]) == 3
    json.dumps(out, allow_nan=False)


# ---------------------------------------------------------------------------------- units
def scaled(document: dict, unit: str) -> dict:
    """``document`` (in metres) written in ``unit``."""
    copy_ = copy.deepcopy(document)
    copy_["frame_unit"] = unit
    copy_["vertices_coords"] = [
        [c / UNITS[unit] for c in row] for row in document["vertices_coords"]
    ]
    return copy_


@pytest.mark.parametrize("unit", list(UNITS))
def test_every_unit_is_read_in_metres(unit):
    metres = load(EXAMPLES / "squaretwist.fold")
    data = read_fold(scaled(metres, unit))
    assert (data.unit, data.scale) == (unit, UNITS[unit])
    assert data.unitless == (unit == "unit")
    np.testing.assert_allclose(data.pattern.coords, read_fold(metres).pattern.coords, atol=1e-12)


def test_a_mm_file_gives_the_answers_of_its_metre_copy(tmp_path):
    metres = load(EXAMPLES / "squaretwist.fold") | {"frame_unit": "m"}
    m_path = write(tmp_path, "twist_m.fold", metres)
    mm_path = write(tmp_path, "twist_mm.fold", scaled(metres, "mm"))
    a, b = analyze_file(m_path).to_dict(), analyze_file(mm_path).to_dict()
    assert (a["unit"], b["unit"]) == ("m", "mm")
    assert a["dof"] == b["dof"] == 1
    assert {k: v for k, v in a.items() if k not in ("file", "unit")} == {
        k: v for k, v in b.items() if k not in ("file", "unit")
    }
    dev_m = develop_file(m_path, tmp_path / "m").to_dict()
    dev_mm = develop_file(mm_path, tmp_path / "mm").to_dict()
    assert dev_m["status"] == dev_mm["status"] == "converged"
    assert dev_mm["D"] == pytest.approx(dev_m["D"], abs=1e-12)
    out_m, out_mm = load(tmp_path / "m" / "twist_m.fold"), load(tmp_path / "mm" / "twist_mm.fold")
    # the input comes back as it was (in mm); rigidfold's frames are in metres
    assert out_mm["frame_unit"] == "mm"
    assert out_mm["vertices_coords"] == scaled(metres, "mm")["vertices_coords"]
    assert out_mm["rigidfold:input"] == {"unit": "mm", "metres_per_unit": 0.001, "up": "z"}
    for k in (1, 2):
        frame_m = read_fold(tmp_path / "m" / "twist_m.fold", frame=k)
        frame_mm = read_fold(tmp_path / "mm" / "twist_mm.fold", frame=k)
        assert frame_mm.unit == "m"
        np.testing.assert_allclose(frame_mm.pattern.coords, frame_m.pattern.coords, atol=1e-9)
    assert out_mm["file_frames"][0]["frame_unit"] == out_m["file_frames"][0]["frame_unit"] == "m"


@pytest.mark.parametrize("unit", ["furlong", "MM", 3, None, ["m"]])
def test_unknown_unit_is_one_line(unit):
    document = load(EXAMPLES / "diagonal-cp.fold") | {"frame_unit": unit}
    with pytest.raises(ValueError, match=r"frame_unit .* is not a unit rigidfold knows") as info:
        read_fold(document)
    text = str(info.value)
    assert "\n" not in text and "use one of unit, m, cm, mm, um, nm, in, pt" in text


def test_unknown_unit_on_the_command_line(tmp_path):
    path = write(tmp_path, "u.fold", load(EXAMPLES / "diagonal-cp.fold") | {"frame_unit": "ft"})
    proc = run_cli("analyze", str(path))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "'ft'" in proc.stderr


def test_a_frame_inherits_its_parents_unit():
    document = scaled(load(EXAMPLES / "squaretwist.fold"), "cm")
    document["file_frames"] = [{"frame_parent": 0, "frame_inherit": True}]
    assert read_fold(document, frame=1).unit == "cm"


# ---------------------------------------------------------------------------------- up axis
def y_up(document: dict) -> dict:
    """``document`` drawn y-up: rigidfold's (x, y, z) is the file's (x, z, -y)."""
    turned = copy.deepcopy(document)
    points = [[*xyz, 0.0][:3] for xyz in document["vertices_coords"]]
    turned["vertices_coords"] = [[x, z, -y] for x, y, z in points]
    return turned


@pytest.mark.parametrize("name", ["squaretwist", "diagonal-cp"])
def test_y_up_file_read_with_up_y(name):
    document = load(EXAMPLES / f"{name}.fold")
    data = read_fold(y_up(document), up="y")
    assert data.up == "y"
    np.testing.assert_array_equal(data.pattern.coords, read_fold(document).pattern.coords)


def test_y_up_flat_sheet_read_z_up_is_refused_with_the_reason(tmp_path):
    path = write(tmp_path, "vertical.fold", y_up(load(EXAMPLES / "diagonal-cp.fold")))
    with pytest.raises(ValueError, match="projection onto the xy plane has zero area") as info:
        read_fold(path)
    assert "(--up y)" in str(info.value) and "reverse" not in str(info.value)
    proc = run_cli("develop", str(path), "--out", str(tmp_path / "o"))
    assert proc.returncode == 2 and "zero area" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert main(["analyze", str(path), "--up", "y", "--json"]) == 0


def test_bad_up_axis():
    with pytest.raises(ValueError, match="up must be one of z, y, got 'x'"):
        read_fold(load(EXAMPLES / "diagonal-cp.fold"), up="x")
    assert run_cli("analyze", str(EXAMPLES / "diagonal-cp.fold"), "--up", "x").returncode == 2


@pytest.mark.parametrize("name", REFUSED)
def test_zero_plan_area_examples_are_refused_without_reversal_advice(name):
    with pytest.raises(ValueError, match="zero area") as info:
        read_fold(EXAMPLES / f"{name}.fold")
    assert "reverse" not in str(info.value) and "\n" not in str(info.value)


def test_up_y_still_zero_says_so():
    """A sheet lying in the file's xy plane read y-up stands on its edge."""
    with pytest.raises(ValueError, match=r"file's xz plane has zero area.*--up z"):
        read_fold(load(EXAMPLES / "diagonal-cp.fold"), up="y")


def test_crease_pattern_tells_zero_from_negative_plan_area():
    coords = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], dtype=float)
    faces = [(0, 1, 2), (0, 2, 3)]
    with pytest.raises(ValueError, match="reverse the vertex order"):
        CreasePattern.from_faces(coords, [f[::-1] for f in faces])
    vertical = coords[:, [0, 2, 1]]
    with pytest.raises(ValueError, match="projection onto the xy plane has zero area") as info:
        CreasePattern.from_faces(vertical, faces)
    assert "reverse" not in str(info.value)


# ---------------------------------------------------------------------------------- flat sheets
def test_analyze_flat_crease_pattern_says_its_dof_is_first_order(tmp_path, capsys):
    flat = EXAMPLES / "diagonal-cp.fold"
    analysis = analyze_file(flat)
    assert analysis.flat and analysis.notes == [UNITLESS_NOTE, FLAT_NOTE]
    assert main(["analyze", str(flat), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["flat"] is True and report["dof"] == 1
    assert report["notes"] == [UNITLESS_NOTE, FLAT_NOTE]
    assert main(["analyze", str(flat)]) == 0
    text = capsys.readouterr().out
    assert text.count("first-order DOF overstates") == 1
    assert text.count("read as metres") == 1
    # a folded form in metres: neither note
    folded = write_fold(tmp_path / "miura.fold", miura(3, 3))
    assert main(["analyze", str(folded), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["flat"] is False and report["notes"] == [] and report["unit"] == "m"


def test_flat_miura_crease_pattern_overstates_its_dof(tmp_path):
    """The flat Miura-ori sheet's first-order DOF exceeds its folded state's 1."""
    shape = miura(4, 3)
    flat = write_fold(tmp_path / "flat.fold", shape.with_coords(shape.coords * [1, 1, 0]))
    folded = write_fold(tmp_path / "folded.fold", shape)
    flat_dof, folded_dof = analyze_file(flat), analyze_file(folded)
    assert flat_dof.flat and not folded_dof.flat
    assert flat_dof.mechanism.dof > folded_dof.mechanism.dof == 1
