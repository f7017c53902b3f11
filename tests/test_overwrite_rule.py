"""--overwrite removes only what the earlier run wrote and recorded (issues 39 and 47): in
generate's own directories too, a file it did not record stays, whatever its name."""

from __future__ import annotations

import pytest

from rigidfold.cli.commands import main

RUN = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "1", "--target-dof", "19"]
QUIET = ["--no-deform", "--no-report", "--quiet"]


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "out"
    assert main([*RUN, *QUIET, "--thickness", "18mm", "--out", str(out)]) == 0
    return out


USERS = [
    "final/step_04_dof_01_my_notes.txt",  # issue 47, item 4: removed without a word
    "final/step_04_dof_01.obj.bak",
    "final/step_02_dof_19_my_notes.txt",  # named after this run's final design
    "final/step_02_dof_19.obj.bak",
    "figures/site_photo.png",
    "solutions/notes.txt",
    "solutions/step_07_dof_03.fold",  # not one the earlier run recorded
    "final/thick/x.3dm",
    "notes.txt",
]


def test_overwrite_removes_exactly_what_the_earlier_run_recorded(first, tmp_path):
    """Issue 47, item 4: ``--overwrite`` removes the files the earlier run's summary.json
    lists (its solutions and their diagrams, its exports, its thick panels' files), its own
    top files, the report's figures by name and a killed run's staging directory of the
    exports; a user's file stays wherever it is, whatever its name."""
    import json
    import shutil

    out = tmp_path / "out"
    shutil.copytree(first, out)
    summary = json.loads((out / "summary.json").read_text())
    thick = summary["per_solution"][-1]["fabrication"]["files"]
    assert thick and all((out / f).is_file() for f in thick)
    for where in USERS:
        (out / where).parent.mkdir(parents=True, exist_ok=True)
        (out / where).write_text("mine")
    (out / "figures" / "development.png").write_bytes(b"an earlier report's figure")
    staging = out / ".final.0a1b2c3d4e5f.tmp"  # a run killed while it exported
    staging.mkdir()
    (staging / "step_02_dof_19.obj").write_text("half")
    stale = out / "solutions" / ".step_00_dof_21.fold.0a1b2c3d4e5f.tmp"
    stale.write_text("")
    assert main([*RUN, *QUIET, "--out", str(out)]) == 2  # refused without --overwrite
    assert main([*RUN, *QUIET, "--out", str(out), "--overwrite"]) == 0
    for where in USERS:
        assert (out / where).read_text() == "mine", where
    assert not (out / "figures" / "development.png").exists()
    assert not staging.exists() and not stale.exists()
    assert not [f for f in thick if (out / f).exists()]  # this run made no thick panels
    assert sorted(p.name for p in (out / "final" / "thick").iterdir()) == ["x.3dm"]
    new = json.loads((out / "summary.json").read_text())
    listed = {*new["solutions"], *new["exports"]}
    listed |= {s.replace(".fold", ".svg") for s in new["solutions"]}
    ours = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert ours - listed == {*USERS, "summary.json", "log.jsonl"}


def test_a_tampered_summary_never_names_a_file_outside_the_runs_forms(first, tmp_path):
    """A name in summary.json that is not of a form the run writes (outside its
    directories, up a level, a directory) is not removed."""
    import json
    import shutil

    out = tmp_path / "out"
    shutil.copytree(first, out)
    (tmp_path / "outside.txt").write_text("keep")
    (out / "mine").mkdir()
    (out / "mine" / "a.txt").write_text("keep")
    summary = json.loads((out / "summary.json").read_text())
    summary["solutions"] += ["../outside.txt", "mine/a.txt", "solutions/../mine/a.txt"]
    summary["exports"] += ["final/../../outside.txt", "final/../mine/a.txt", "final", "final/.."]
    summary["exports"] += ["final/thick", "final/thick/.."]  # a directory: never removed
    (out / "summary.json").write_text(json.dumps(summary))
    assert main([*RUN, *QUIET, "--out", str(out), "--overwrite"]) == 0
    assert (tmp_path / "outside.txt").read_text() == "keep"
    assert (out / "mine" / "a.txt").read_text() == "keep"


def test_a_run_of_its_own_files_is_overwritten(first, tmp_path):
    import shutil

    out = tmp_path / "out"
    shutil.copytree(first, out)
    (out / "solutions" / ".step_01_dof_20.fold.0a1b2c3d4e5f.tmp").write_text("")  # killed run
    assert main([*RUN, *QUIET, "--out", str(out), "--overwrite"]) == 0
    assert not (out / "final" / "thick").exists()  # this run made no thick panels
