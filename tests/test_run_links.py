"""No path leaves the run directory (issue 47, item 6).

Every reader of a run's files refuses a symbolic link that leads out of the run's
directory (a one-line error naming the path), the report embeds as an image only a file
that is a PNG, and nothing is written through a linked directory of the run. Before,
``final/structure/structure.png`` linked to a text file elsewhere had that file's bytes
embedded in report.html, and with ``figures/`` a link to another directory ``report`` wrote
its figures there.
"""

from __future__ import annotations

import shutil

import pytest

from conftest import main_code
from rigidfold.errors import RigidfoldError
from rigidfold.io import inside_dir, prepare_output_dir, read_png
from rigidfold.pipeline.workflows import report_run
from rigidfold.rundir import load_run

STRUCTURE_PNG = "final/structure/structure.png"


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A short run whose final design was checked as a structure (its figure a PNG)."""
    out = tmp_path_factory.mktemp("linked")
    argv = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "1"]
    argv += ["--target-dof", "18", "--quiet", "--no-deform", "--no-report", "--structure"]
    assert main_code([*argv, "--out", str(out)]) in (0, 1)
    assert (out / STRUCTURE_PNG).is_file()
    return out


@pytest.fixture
def copy(run_dir, tmp_path):
    return shutil.copytree(run_dir, tmp_path / "run")


@pytest.fixture
def secret(tmp_path):
    path = tmp_path / "secret.txt"
    path.write_text("a private note, not an image")
    return path


def test_the_run_reports_with_its_structure_figure(copy):
    report = report_run(copy)
    assert 'id="structure.png"' in report.html.read_text()


def test_a_figure_linked_out_of_the_run_is_refused(copy, secret):
    (copy / STRUCTURE_PNG).unlink()
    (copy / STRUCTURE_PNG).symlink_to(secret)
    with pytest.raises(RigidfoldError, match=r"structure\.png' leads to .*outside the directory"):
        report_run(copy)
    assert not (copy / "report.html").exists()
    assert main_code(["report", str(copy)]) == 2


def test_a_figure_that_is_no_png_is_not_embedded(copy):
    (copy / STRUCTURE_PNG).write_text("<script>alert(1)</script>")
    with pytest.raises(RigidfoldError, match=r"structure\.png' is not a PNG image"):
        report_run(copy)
    assert not (copy / "report.html").exists()


def test_report_writes_nothing_through_a_linked_figures_directory(copy, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    shutil.rmtree(copy / "figures", ignore_errors=True)
    (copy / "figures").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(RigidfoldError, match="figures' is a symbolic link"):
        report_run(copy)
    assert list(elsewhere.iterdir()) == []


@pytest.mark.parametrize("name", ["summary.json", "log.jsonl", "solutions"])
def test_a_run_file_linked_out_of_the_run_is_refused(copy, tmp_path, name):
    moved = tmp_path / f"moved_{name}"
    (copy / name).rename(moved)
    (copy / name).symlink_to(moved, target_is_directory=moved.is_dir())
    with pytest.raises(RigidfoldError, match=f"{name}.* leads to .*outside the directory"):
        load_run(copy)


def test_links_inside_the_run_and_a_linked_run_directory_are_read(copy, tmp_path):
    # a solution file that is a link to another file of the run stays inside: read
    solutions = sorted((copy / "solutions").glob("*.fold"))
    kept = copy / "kept.fold"
    solutions[0].rename(kept)
    solutions[0].symlink_to(kept)
    # the run directory itself reached through a link: the user's choice, read
    link = tmp_path / "link_to_run"
    link.symlink_to(copy, target_is_directory=True)
    run = load_run(link)
    assert len(run.designs) == len(solutions)
    assert run.structure_figure() is not None


def test_prepare_output_dir_within_refuses_a_linked_directory(tmp_path):
    root = tmp_path / "run"
    root.mkdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (root / "final").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(RigidfoldError, match="final' is a symbolic link"):
        prepare_output_dir(root / "final" / "thick", within=root)
    assert list(elsewhere.iterdir()) == []
    # the user's own output directory may be a link; directories below it are made
    linked_root = tmp_path / "linked_root"
    linked_root.symlink_to(elsewhere, target_is_directory=True)
    made = prepare_output_dir(linked_root / "figures", within=linked_root)
    assert made.is_dir() and (elsewhere / "figures").is_dir()


def test_inside_dir_and_read_png(tmp_path, secret):
    root = tmp_path / "run"
    root.mkdir()
    assert inside_dir(root, root / "missing.json") == root / "missing.json"
    (root / "out").symlink_to(secret)
    with pytest.raises(RigidfoldError, match="outside the directory"):
        inside_dir(root, root / "out")
    with pytest.raises(RigidfoldError, match="not a PNG image"):
        read_png(secret)
    with pytest.raises(RigidfoldError, match="cannot read"):
        read_png(root / "missing.png")
