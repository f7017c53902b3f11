"""The run artifact (issue 28): one schema for summary.json, log.jsonl and the solution files,
one set of generate options and the FOLD frame contract."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidfold.errors import RigidfoldError
from rigidfold.generate import GenerateOptions, Generation
from rigidfold.io import FRACTION_KEY, motion_frames, read_frames
from rigidfold.mesh import CreasePattern
from rigidfold.patterns import pattern1
from rigidfold.rundir import RunSummary, SolutionRecord, Stage, aggregate


def _record(development="converged", motion=None, deformation=None) -> SolutionRecord:
    return SolutionRecord.from_dict(
        {
            "step": 3,
            "dof": 2,
            "development": {"status": development, "D": 1e-9, "flipped": 0, "overlaps": 0},
            "motion": None if motion is None else {"status": motion, "max_length_error": 0.0},
            "deformation": None
            if deformation is None
            else {
                "status": deformation,
                "reached_plane": deformation == "reached_plane",
                "mean_dl_mm": 0.1,
                "max_dl_mm": 0.2,
                "mean_drho_fix_deg": 0.0,
                "max_drho_fix_deg": 0.0,
            },
        }
    )


@pytest.mark.parametrize(
    ("record", "failed"),
    [
        (_record(), []),
        (_record("failed"), [Stage.DEVELOPMENT]),
        (_record(motion="ok", deformation="reached_plane"), []),
        (_record(motion="failed"), [Stage.MOTION]),
        (_record(deformation="failed"), [Stage.DEFORMATION]),
        (
            _record("failed", "failed", "failed"),
            [Stage.DEVELOPMENT, Stage.MOTION, Stage.DEFORMATION],
        ),
    ],
)
def test_failed_stages_are_decided_once(record, failed):
    """A stage that did not run neither passes nor fails; the others by their status."""
    assert record.failed_stages() == failed
    for stage in Stage:
        ran = stage is Stage.DEVELOPMENT or getattr(record, stage.value) is not None
        assert record.ran(stage) is ran
        assert record.passed(stage) is (None if not ran else stage not in failed)


def test_record_round_trip_and_aggregate():
    record = _record(motion="ok", deformation="reached_plane")
    assert SolutionRecord.from_dict(json.loads(json.dumps(record.to_dict()))) == record
    figures = aggregate([record, _record(deformation="failed")])
    assert figures["deformation"]["checked"] == 2
    assert figures["deformation"]["reached_plane"] == 1
    assert figures["motion"]["traced"] == 1
    assert figures["development"]["max_D"] == pytest.approx(1e-9)


def test_summary_is_written_and_read_through_one_record():
    """summary.json is RunSummary.to_dict (every key of the run's own to_dict kept, the
    run-wide figures before per_solution) and reads back to the same content."""
    records = [_record(motion="ok", deformation="reached_plane"), _record()]
    summary = RunSummary.from_run(
        Generation(),
        records,
        stage_times={"develop": 1.5},
        options={"target_dof": 1},
        case={"F_tol": 1e-7},
        solutions=("solutions/a.fold", "solutions/b.fold"),
        exports=("final/b.obj",),
    )
    data = summary.to_dict()
    assert set(Generation().to_dict()) <= set(data)
    assert data["time_s"]["develop"] == 1.5 and data["n_lock"] == 0
    keys = list(data)
    assert keys[0] == "schema_version"
    assert keys.index("structure") + 1 == keys.index("per_solution")
    assert {k: data[k] for k in aggregate(records)} == aggregate(records)
    text = json.loads(json.dumps(data))
    again = RunSummary.from_dict(text, "summary.json")
    assert again.to_dict() == text
    assert again.per_solution == tuple(records) and again.solutions == summary.solutions


@pytest.mark.parametrize("value", [float("inf"), 3.0, [1.0], "fast"])
def test_a_damaged_stage_time_is_bad_input(value):
    """A solution's ``time_s`` that is no object (a fuzzed summary.json once had Infinity
    there) is refused in one line naming it, not read into a crash."""
    summary = RunSummary.from_run(
        Generation(), [_record()], stage_times={}, options={}, case={}, solutions=("a",)
    )
    data = json.loads(json.dumps(summary.to_dict()))
    data["per_solution"][0]["time_s"] = value
    with pytest.raises(RigidfoldError, match=r"per_solution\[0\]\.time_s"):
        RunSummary.from_dict(data, "summary.json")


def test_generate_options_validate_and_round_trip():
    options = GenerateOptions(criterion="s", target_dof=3, lookahead=True)
    assert GenerateOptions.from_dict(options.to_dict() | {"symmetric": True}) == options
    assert options.replace(seed=5).seed == 5
    with pytest.raises(ValueError, match="unknown generate option 'target'"):
        options.replace(target=2)
    with pytest.raises(ValueError, match="unknown criterion 'x'"):
        GenerateOptions(criterion="x")
    with pytest.raises(ValueError, match="target DOF must be an integer >= 0, got -1"):
        GenerateOptions(target_dof=-1)
    with pytest.raises(ValueError, match="check must be a Check \\(final, all\\), got 'all'"):
        GenerateOptions(check="all")  # the command line's text is read by rigidfold.cli


def test_settings_hold_no_run_options():
    """The target DOF and the deployability check are options of a run, not tolerances."""
    from rigidfold.config import Settings

    names = set(Settings().flat())
    assert not names & {"target_dof", "deploy_check"}


def test_motion_frames_carry_their_fraction():
    """The fraction folded of each motion frame is a key of the frame, read back as written
    (not recovered from the title); frames of another writer are spaced evenly."""
    xy, faces = pattern1()
    pattern = CreasePattern.from_faces(np.column_stack([xy, np.zeros(len(xy))]), faces)
    coords = np.repeat(pattern.coords[None], 3, axis=0)
    fractions = np.array([0.0, 0.37, 1.0])
    frames = motion_frames(pattern, coords, fractions)
    assert [f[FRACTION_KEY] for f in frames] == fractions.tolist()
    read = read_frames({"file_frames": frames}, pattern.n_vertices, "test")
    np.testing.assert_array_equal(read.fraction, fractions)
    assert read.diagram is None and read.motion.shape == (3, pattern.n_vertices, 3)
    for f in frames:
        del f[FRACTION_KEY]
        f["frame_title"] = "a motion frame"
    other = read_frames({"file_frames": frames}, pattern.n_vertices, "test")
    np.testing.assert_array_equal(other.fraction, [0.0, 0.5, 1.0])


def test_every_stage_has_its_rule():
    """One table says when each check of a solution passes, and its enum reads its status."""
    from rigidfold.rundir.schema import STAGES

    assert set(STAGES) == set(Stage)
    record = _record(motion="ok")
    assert record.status(Stage.MOTION) is STAGES[Stage.MOTION].passing
    assert record.status(Stage.DEFORMATION) is None
    assert _record("error").status(Stage.DEVELOPMENT) == "error"


def test_a_design_beyond_dz_fails_the_fit_check(tmp_path):
    """issue 38 demo: the fit check runs through the one pipeline on every solution; a design
    farther from the target than dz fails it (Stage.FIT), with its words, in the verdict."""
    from rigidfold.config import DEFAULTS
    from rigidfold.generate import generate
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.pipeline import run_verdict
    from rigidfold.pipeline.checks import check_solution

    options = GenerateOptions(target_dof=18, deform=False)
    case = case_from_specs("bezier", "1", seed=1)
    run = generate(case, options)
    final = run.final
    assert final is not None
    kept = check_solution(final, case, options, motion=False, deform=False).record
    assert kept.fit is not None and kept.fit["status"] == "within"
    assert kept.failed_stages() == []
    tight = case_from_specs(
        "bezier", "1", seed=1, settings=DEFAULTS.with_(dz=kept.fit["max_abs_dz_m"] / 2)
    )
    record = check_solution(final, tight, options, motion=False, deform=False).record
    assert record.failed_stages() == [Stage.FIT]
    assert record.detail(Stage.FIT).startswith("max |z - target| ")
    records = [record] * len(run.solutions)
    files = [tmp_path / f"step_{k}.fold" for k in range(len(records))]
    verdict = run_verdict(run, records, files, options.target_dof)
    assert f"{Stage.FIT.message} for the final design (max |z - target|" in verdict.shortfalls[0]


# ------------------------------------------------- the records once (issue 46, item 3)


def test_summary_shape_follows_run_summary_fields():
    """SUMMARY_SHAPE is made from RunSummary: every field is a key of it (the fields without
    a default required), and a field added to RunSummary is a key of the shape so made."""
    from dataclasses import MISSING, fields, make_dataclass

    from rigidfold.rundir.json_shapes import Nullable, record_shape
    from rigidfold.rundir.schema import SOLUTION_SHAPE, SUMMARY_SHAPE

    assert list(SUMMARY_SHAPE.keys) == [f.name for f in fields(RunSummary)]
    required = {
        f.name for f in fields(RunSummary) if f.default is MISSING and f.default_factory is MISSING
    }
    assert set(SUMMARY_SHAPE.required) == required
    assert required == {
        "stop", "stop_reason", "final_dof", "n_lock", "per_solution", "case", "solutions",
    }  # fmt: skip
    assert SUMMARY_SHAPE.keys["per_solution"] == [SOLUTION_SHAPE]
    assert list(SOLUTION_SHAPE.keys) == [f.name for f in fields(SolutionRecord)]
    assert SUMMARY_SHAPE.keys["n_lock"] == Nullable(int)
    added = make_dataclass(
        "Later", [("n_flips", int | None, None)], bases=(RunSummary,), frozen=True, kw_only=True
    )
    assert record_shape(added, null_is_default=True).keys["n_flips"] == Nullable(int)


def test_stage_figures_are_declared_once():
    """A key read of a stage's figures is declared in its TypedDict, which makes its shape;
    one added there is checked in summary.json."""
    from typing import Annotated, get_type_hints

    from rigidfold.rundir.json_shapes import Nullable, record_shape, shape_of
    from rigidfold.rundir.schema import SOLUTION_SHAPE, DevelopmentFigures

    development = SOLUTION_SHAPE.keys["development"]
    assert development == Nullable(record_shape(DevelopmentFigures))
    assert set(development.shape.keys) == set(get_type_hints(DevelopmentFigures))

    class Later(DevelopmentFigures, total=False):
        wrinkles: int | None

    later = shape_of(Annotated[dict | None, Later])
    assert later.shape.keys["wrinkles"] == Nullable(int)
    summary = RunSummary.from_run(
        Generation(), [_record()], stage_times={}, options={}, case={}, solutions=("a",)
    )
    data = json.loads(json.dumps(summary.to_dict()))
    data["per_solution"][0]["development"]["D"] = "small"
    with pytest.raises(RigidfoldError, match=r"'per_solution\[0\]\.development\.D' is \"small\""):
        RunSummary.from_dict(data, "summary.json")


def test_each_counter_has_one_name_from_the_run_to_the_summary():
    """Generation.to_dict's keys are RunSummary's fields and summary.json's keys under the
    same names (no renaming: ``n_lock`` everywhere, never ``N_lock``)."""
    from dataclasses import fields

    run = Generation(n_lock=2, n_exceed=1, n_path=3, n_backtrack=4, n_rigid=5)
    produced = run.to_dict()
    names = {f.name for f in fields(RunSummary)}
    assert set(produced) <= names
    summary = RunSummary.from_run(run, [], stage_times={}, case={}, solutions=())
    data = summary.to_dict()
    for key, value in produced.items():
        assert data[key] == value and getattr(summary, key) == value
    assert not [k for k in data if k.startswith("N_") or "_F_" in k]
    assert (summary.n_lock, summary.n_exceed, summary.n_rigid) == (2, 1, 5)
