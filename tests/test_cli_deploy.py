"""``rigidfold deploy``: the drive of a DOF-1 design from the command line (issue 48): its
files, its last line, its exit codes, and --overwrite that keeps a user's other files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rigidfold.cli.commands import main

DATA = Path(__file__).parent / "data"
ROOF = DATA / "roof_12x8_dof1.fold"  # the 15 x 9 roof grid's DOF-1 design


@pytest.fixture(scope="module")
def roof_drive(tmp_path_factory):
    out = tmp_path_factory.mktemp("deploy")
    code = main(["deploy", str(ROOF), "--out", str(out), "--thickness", "18mm", "--json"])
    return code, out


def test_deploy_names_a_drive_and_writes_its_files(roof_drive, capsys):
    code, out = roof_drive
    assert code == 0
    data = json.loads((out / "deploy.json").read_text())
    assert data["drive"]["kind"] in {"crease", "pair", "cable"}
    assert data["drive"]["peak_Nm"] > 0
    s = [state["s"] for state in data["states"]]
    assert s[0] == 0.0 and s[-1] == 1.0 and s == sorted(s)
    peaks = [row["peak_Nm"] for row in data["ranking"]]
    assert peaks == sorted(peaks)  # lowest first
    assert data["drive"]["peak_Nm"] == pytest.approx(peaks[0]) or data["drive"]["kind"] != "crease"
    fold = json.loads((out / "deploy.fold").read_text())
    assert len(fold["file_frames"]) == len(data["states"])  # one frame per state, in order
    header = (out / "deploy.csv").read_text().splitlines()[0]
    assert "torque" in header
    assert (out / "deploy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_last_line_names_the_drive_and_its_brake_zones(tmp_path, capsys):
    out = tmp_path / "d"
    assert main(["deploy", str(ROOF), "--out", str(out), "--no-check"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("drive crease ") or last.startswith("drive pair ")
    assert "peak" in last and "at s =" in last


def test_an_earlier_drive_is_refused_without_overwrite_and_other_files_kept(tmp_path, capsys):
    out = tmp_path / "d"
    assert main(["deploy", str(ROOF), "--out", str(out), "--no-check"]) == 0
    (out / "site_photo.png").write_bytes(b"mine")
    assert main(["deploy", str(ROOF), "--out", str(out), "--no-check"]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert main(["deploy", str(ROOF), "--out", str(out), "--no-check", "--overwrite"]) == 0
    assert (out / "site_photo.png").read_bytes() == b"mine"


def test_a_design_of_dof_above_one_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "d"
    assert main(["deploy", str(DATA / "dome_sym_dof13.fold"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not 1" in err
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--base", "panel:100000"), ("--thickness", "-5mm"), ("--friction", "nan"), ("--cable", "0")],
)
def test_bad_drive_options_are_one_line_errors(tmp_path, capsys, flag, value):
    out = tmp_path / "d"
    try:
        code = main(["deploy", str(ROOF), "--out", str(out), flag, value])
    except SystemExit as exc:  # refused by the parser
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "error:" in err and flag.lstrip("-").split("-")[0] in err
    assert not (out / "deploy.json").exists()
