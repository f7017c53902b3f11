"""The broad set's case list (benchmarks/broad_cases.py) and its harness's bookkeeping
(benchmarks/broad_set.py): no solves."""

from __future__ import annotations

import importlib.util
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from rigidfold.generate.specs import case_from_specs
from rigidfold.io.fold import read_fold

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _load(name: str):
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


bc = _load("broad_cases")
bs = _load("broad_set")


@pytest.fixture(scope="module")
def listed(tmp_path_factory):
    work = tmp_path_factory.mktemp("broad")
    every, left = bc.cases(work)
    return work, every, left


def test_at_least_60_cases_of_6_families_named_uniquely(listed):
    _, every, _ = listed
    families = Counter(c.family for c in every)
    assert len(every) >= 60
    assert len(families) >= 6 and set(families) <= set(bc.FAMILIES)
    names = [c.name for c in every]
    assert len(set(names)) == len(names)
    assert not any("," in n for n in names), "--only splits on commas"
    # every diagonal choice, three surfaces, every drawn file that reads
    grids = {c.diagonals for c in every if c.family == "grid"}
    assert grids == set(bc.GRID_DIAGONALS)
    assert {c.surface for c in every if c.family == "drawn"} == set(bc.SURFACES)


def test_the_list_is_fixed(listed, tmp_path):
    work, every, _ = listed
    again = bc.candidates()
    assert again == bc.candidates()  # seeds, polygons, everything drawn the same
    assert [c for c in every if c.family != "drawn"] == [c for c in again if c.family != "drawn"]
    assert {c.name for c in every} <= {c.name for c in again}
    # a perturbed FOLD file is the same drawn again elsewhere
    case = next(c for c in every if c.family == "perturbed")
    first = Path(case.pattern_spec(work)).read_bytes()
    assert Path(case.pattern_spec(tmp_path)).read_bytes() == first


def test_every_case_builds_as_the_command_line_would(listed):
    """make_case is what `rigidfold generate` does before its first solve: each case's
    pattern parses and its initial shape is accepted on its surface."""
    work, every, left = listed
    for case in every:
        built = case_from_specs(**case.make_case_kwargs(work))
        assert built.pattern.n_vertices >= 4, case.name
        assert case.cli_args(work)[:2] == ["--surface", case.surface]
    for name, reason in left:
        assert name.startswith("drawn/") and reason, name


def test_perturbed_tessellations_move_inner_vertices_only_and_keep_faces_valid(tmp_path):
    from rigidfold.generate.specs import parse_pattern

    base = bc.DRAWN_DIR / bc.PERTURBED_BASES[0]
    plan = parse_pattern(str(base))
    xy, faces = bc.perturbed_plan(base, bc.PERTURB_SEEDS[0])
    moved = np.linalg.norm(xy - plan.xy, axis=1)
    assert (moved > 0).sum() > len(xy) / 2  # most inner vertices moved
    assert (bc._signed_areas(xy, faces) > 0).all()
    low, high = bc._angle_room(bc._plan_angles(plan.xy, plan.faces))
    angles = bc._plan_angles(xy, faces)
    assert ((angles >= low) & (angles <= high)).all()
    read = read_fold(bc.write_perturbed(base, bc.PERTURB_SEEDS[0], tmp_path)).pattern
    assert read.n_vertices == len(xy) and len(read.faces) == len(faces)
    assert np.array_equal(read.coords[:, :2], xy)
    assert (moved <= bc.PERTURB_FRACTION * 3.0).all()  # far below the 3 m plan


def test_random_polygons_are_simple_with_no_sharp_corner():
    for seed in bc.MESH_SEEDS:
        xy = bc.random_polygon(seed)
        assert 4 <= len(xy) <= 8
        assert bc._corner_angles_ok(xy, np.radians(50.0))
        assert np.array_equal(xy, bc.random_polygon(seed))


def test_harness_flags_an_overrun_and_summarizes_per_variant_and_family():
    assert bs.grace(180.0) == 10.0 and bs.grace(600.0) == 30.0
    assert bs.VARIANTS["today"] == ()
    assert bs._percentile([1.0, 2.0, 3.0, 4.0, 5.0], 0.9) == pytest.approx(4.6)

    def row(case, family, variant, passed, wall, develop=1.0, overrun=False):
        return {
            "case": case,
            "family": family,
            "variant": variant,
            "passed": passed,
            "final_dof": 1 if passed else 3,
            "clear": passed,
            "deploys": passed,
            "overrun": overrun,
            "killed": False,
            "limit_s": 180.0,
            "exit": 0,
            "summary": True,
            "wall_s": wall,
            "cpu_s": wall,
            "solves_per_dof": 1.0,
            "time_s": {"solve": wall / 2, "develop": develop},
        }

    rows = [
        row("grid/a", "grid", "today", True, 10.0),
        row("grid/a", "grid", "other", True, 5.0),
        row("mesh/b", "mesh", "today", False, 200.0, overrun=True),
        row("mesh/b", "mesh", "other", True, 20.0),
    ]
    s = bs.stats([r for r in rows if r["variant"] == "today"])
    assert (s["runs"], s["passed"], s["overrun"]) == (2, 1, 1)
    assert s["median_s"] == 105.0
    assert s["develop_share"] == pytest.approx(2.0 / 210.0)
    text = bs.summarize(rows)
    assert "OVERRUN mesh/b" in text
    assert "other vs today on 2 cases: passes 1 more, 0 fewer" in text
    assert text.count("  grid ") == 2 and text.count("  mesh ") == 2


def test_the_run_environment_is_pinned():
    from rigidfold.runtime.numerics import RESTARTED_ENV, pinned_environ

    env = bs.run_environment()
    assert env[RESTARTED_ENV] == "1"
    for key, value in pinned_environ({}).items():
        if key != "GLIBC_TUNABLES":
            assert env[key] == value


def test_the_reference_variant_runs_another_checkouts_search(tmp_path):
    """``--variants reference,today --reference DIR``: the same command, with DIR's src
    first on PYTHONPATH (a change of the search against the one before it, in one run)."""
    import os

    here = str(BENCH.parent / "src")
    assert bs.run_environment()["PYTHONPATH"].split(os.pathsep)[0] == here
    other = bs.run_environment(tmp_path)["PYTHONPATH"].split(os.pathsep)
    assert other[0] == str(tmp_path / "src") and here not in other[:1]
    assert bs.VARIANTS["reference"] == bs.VARIANTS["today"]
    with pytest.raises(SystemExit):  # a variant and its checkout go together
        bs.main(["--variants", "reference", "--list"])
    with pytest.raises(SystemExit):  # not a checkout of rigidfold
        bs.main(["--variants", "reference,today", "--reference", str(tmp_path), "--list"])


def test_the_solves_above_dof_10_are_read_from_the_runs_log(tmp_path):
    """Issue 49's target figure: the attempts after the first solve up to the first accepted
    solution at DOF <= 10 (a failed one included), per DOF removed above 10; none where the
    run never got there or started at or below it."""
    import json

    def log(dofs_outcomes, name):
        path = tmp_path / name
        lines = [json.dumps({"schema_version": 1})]
        lines += [json.dumps({"dof": d, "outcome": o}) for d, o in dofs_outcomes]
        path.write_text("\n".join(lines) + "\n{torn", encoding="utf-8")
        return path

    run = [(50, "accepted"), (34, "accepted"), (None, "exceed"), (18, "accepted"), (9, "accepted")]
    got = bs._read_descent(log(run, "a.jsonl"))
    assert got == {"solves_above": 4, "solves_above_per_dof": 4 / 40}
    assert bs._read_descent(log(run[:3], "b.jsonl")) == {}
    assert bs._read_descent(log([(8, "accepted"), (7, "accepted")], "c.jsonl")) == {}
    assert bs._read_descent(tmp_path / "missing.jsonl") == {}
    rows = [
        {"initial_dof": 50, "solves_above_per_dof": 0.1, "wall_s": 1.0, "cpu_s": 1.0},
        {"initial_dof": 30, "solves_above_per_dof": 0.9, "wall_s": 1.0, "cpu_s": 1.0},
    ]
    for r in rows:
        r.update(passed=True, overrun=False, summary=True)
    s = bs.stats(rows)
    assert (s["large"], s["max_solves_above"]) == (1, 0.1)
