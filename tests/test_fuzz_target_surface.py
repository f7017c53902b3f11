"""Fuzz test of the mesh target a run stores for its report (``target_surface.json``: the
fitted spline's grid): seeded byte damage and JSON mutations. Reading the run must never
fail because of it: the report is written without the fit and says why (the file named), or
with a fit whose heights are finite; nothing raises, warns (warnings are errors in the test
suite) or writes outside the run's directory."""

from __future__ import annotations

import copy
import html
import json
import math
import random
import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import main_code
from fuzzing import byte_damage
from rigidfold.rundir import load_run
from test_fuzz_fold import JUNK, nodes, put

MESH = Path(__file__).parent / "data" / "dome_yup.obj"
TARGET = "target_surface.json"
MUTANTS = 60

GRID_JUNK = [
    [],
    [0.0],
    [0.0, 0.0, 0.0, 0.0],
    [3.0, 2.0, 1.0, 0.0],
    [0.0, 1.0, math.nan, 3.0],
    [0.0, 1.0, 2.0, math.inf],
    [[0.0, 1.0], [2.0, 3.0]],
    list(range(600)),
    "0,1,2,3",
    {"x": 1},
    "<script>alert(1)</script>",
    "\u202e\u0000\n",
]
"""Values that look almost like a grid's axis or heights, beside the generic JUNK."""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """A finished run on a mesh target (DOF 9 -> 8), without its report."""
    out = tmp_path_factory.mktemp("mesh") / "run"
    argv = ["generate", "--surface", f"mesh:{MESH}", "--up", "y", "--pattern", "grid:4x4"]
    assert main_code([*argv, "--target-dof", "8", "--no-deform", "--quiet", "--out", str(out)]) == 0
    assert json.loads((out / "summary.json").read_text())["target_surface"] == TARGET
    shutil.rmtree(out / "figures")
    (out / "report.html").unlink()
    return out


def mutant(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    """``data`` (the stored grid) damaged as bytes or as JSON, 1 to 3 times."""
    kinds = ("cut", "byte", "latin-1", "bom", "nul", "empty", "json", "json", "json")
    damaged, how = byte_damage(data, rng, kinds)
    if how != "json":
        return damaged, how
    doc = json.loads(data)
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        path, _ = rng.choice([(p, v) for p, v in nodes(doc) if p])
        if rng.random() < 0.2 and isinstance(path[-1], str):
            parent = doc
            for step in path[:-1]:
                parent = parent[step]
            del parent[path[-1]]
            done.append(f"del {list(path)}")
        else:
            value = copy.deepcopy(rng.choice(JUNK + GRID_JUNK))
            doc = put(doc, path, value)
            done.append(f"{list(path)} = {value!r:.40}")
    return json.dumps(doc, allow_nan=True).encode(), "; ".join(done)


def test_a_damaged_target_file_leaves_the_run_readable(run_dir, tmp_path):
    data = (run_dir / TARGET).read_bytes()
    rng = random.Random("fuzz-target-surface")
    plan = load_run(run_dir).final.coords[:, :2]
    built = lost = 0
    for k in range(MUTANTS):
        damaged, how = mutant(data, rng)
        case = shutil.copytree(run_dir, tmp_path / f"case{k}")
        (case / TARGET).write_bytes(damaged)
        label = f"mutant {k} ({how})"
        run = load_run(case)
        if run.surface is None:
            assert TARGET in run.surface_note and "could not be rebuilt" in run.surface_note, label
            lost += 1
        else:
            z = run.surface.height(plan[:, 0], plan[:, 1])
            assert np.isfinite(z).all(), label
            built += 1
        shutil.rmtree(case)
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    assert lost >= 20 and built >= 1, (lost, built)  # both kinds of case happen


@pytest.mark.parametrize(
    "change",
    [
        {"z": [[0.0, "a"]]},
        {"x": list(range(600))},
        {"source": "<script>alert(1)</script>\u0000"},
    ],
    ids=["heights", "too-many-nodes", "source-as-markup"],
)
def test_the_report_is_written_without_a_damaged_fit_or_with_its_name_as_text(
    run_dir, tmp_path, capsys, change
):
    case = shutil.copytree(run_dir, tmp_path / "run")
    doc = json.loads((case / TARGET).read_text())
    (case / TARGET).write_text(json.dumps({**doc, **change}))
    assert main_code(["report", str(case)]) == 0
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    text = (case / "report.html").read_text()
    if "source" in change:
        assert "<script>alert(1)" not in text  # the name is text, not markup
        assert "could not be rebuilt" not in html.unescape(text)
    else:
        assert f"the target surface could not be rebuilt from {TARGET}" in html.unescape(text)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]
