"""--overwrite replaces only what the command writes (issue 39): in generate's own
directories too, a file it did not write keeps the directory (refused in one line)."""

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


@pytest.mark.parametrize("where", ["solutions/notes.txt", "figures/notes.txt", "final/thick/x.3dm"])
def test_a_users_file_in_a_run_directory_is_kept_and_the_overwrite_refused(
    first, tmp_path, capsys, where
):
    import shutil

    out = tmp_path / "out"
    shutil.copytree(first, out)
    precious = out / where
    precious.parent.mkdir(parents=True, exist_ok=True)
    precious.write_text("mine")
    code = main([*RUN, *QUIET, "--out", str(out), "--overwrite"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "did not write" in err, err
    assert where in err and precious.read_text() == "mine"
    assert (out / "summary.json").is_file()  # nothing of the earlier run was removed


def test_a_run_of_its_own_files_is_overwritten(first, tmp_path):
    import shutil

    out = tmp_path / "out"
    shutil.copytree(first, out)
    (out / "solutions" / ".step_01_dof_20.fold.0a1b2c3d4e5f.tmp").write_text("")  # killed run
    assert main([*RUN, *QUIET, "--out", str(out), "--overwrite"]) == 0
    assert not (out / "final" / "thick").exists()  # this run made no thick panels
