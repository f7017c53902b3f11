"""A new user's stumbles (issue 30, items 23 and 24): what the command line says when a
plan cannot meet the sector-angle bounds, when a solve from the target fails, when an option
is misspelt and when a size looks like millimetres."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.generate.specs import case_from_specs

HYPAR = Path(__file__).parent / "data" / "origami_simulator" / "hypar.svg"


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``rigidfold ARGV``, argparse's own exits included."""
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------ item 23: sector angles of the plan
def test_a_plan_far_outside_the_angle_bounds_is_refused_before_solving():
    """Origami Simulator's hypar.svg lifted onto the hp surface: about a third of its sector
    angles are slivers far below theta_min. It failed after the solve with "face 0 ... is
    degenerate"; it is refused when the case is made, saying what is out of range and which
    options change the bounds. (By default a drawn plan's own angles widen the bounds, and
    hypar.svg loads: the refusal is that of bounds kept as given, ``--theta-widen none``.)"""
    given = DEFAULTS.with_(theta_widen="none")
    angles = np.degrees(
        case_from_specs(
            "hp", str(HYPAR), settings=given.with_(theta_far_share=1.0)
        ).pattern.corner_angles
    )
    below, above = int((angles < 30).sum()), int((angles > 120).sum())
    with pytest.raises(ValueError) as info:
        case_from_specs("hp", str(HYPAR), settings=given)
    message = str(info.value)
    assert "\n" not in message
    assert f"{below + above} of {angles.size} sector angles outside" in message
    assert f"{below} below 30 degrees (the smallest {angles.min():.2g})" in message
    assert f"{above} above 120 degrees (the largest {angles.max():.4g})" in message
    assert "[30, 120] degrees" in message
    assert "--theta-min" in message and "--theta-max" in message
    # the bounds that the options set decide: wide ones let the same plan through
    wide = given.with_(theta_min=math.radians(0.1), theta_max=math.radians(179))
    assert case_from_specs("hp", str(HYPAR), settings=wide).pattern.n_faces == angles.size // 3
    # and so does its own plan, by default
    case = case_from_specs("hp", str(HYPAR))
    assert case.settings.design.theta_min < math.radians(angles.min()) and case.notes


@pytest.mark.parametrize("spec", ["1", "2", "11", "grid:9x6"])
def test_the_paper_patterns_and_grids_pass_the_angle_check(spec):
    """Plans with a few angles somewhat outside the bounds, which the solver brings inside,
    are not refused (pattern 2's smallest is 17 degrees)."""
    assert case_from_specs("dome", spec).pattern.n_faces > 0


def test_the_cli_refuses_the_plan_in_one_line(tmp_path, capsys):
    code, _, err = run(
        [
            "generate",
            "--surface",
            "hp",
            "--pattern",
            str(HYPAR),
            "--theta-widen",
            "none",
            "--out",
            str(tmp_path / "o"),
        ],
        capsys,
    )
    assert code == 2 and err.count("\n") == 1, err
    assert "sector angles" in err and "--theta-min" in err
    assert not (tmp_path / "o").exists()


def test_a_failed_initial_solve_says_what_to_try(tmp_path, capsys):
    """The hp surface on a 3 x 3 grid with centre diagonals: the solve from the target is
    not accepted by IPOPT alone (the paper's solver; the projection after IPOPT's early stop
    finds one, GenerateOptions.projection). The last line says what to try."""
    argv = ["generate", "--surface", "hp", "--pattern", "grid:3x3", "--quiet", "--no-report"]
    alone = ["--projection", "large"]
    code, out, _ = run([*argv, *alone, "--out", str(tmp_path / "o")], capsys)
    last = out.strip().splitlines()[-1]
    assert code == 1
    assert "no developable polyhedron from the initial shape" in last
    for option in ("--dz", "--theta-min", "--theta-max", "--diagonals"):
        assert option in last
    code, out, _ = run(["optimize", *argv[1:5], "--out", str(tmp_path / "p")], capsys)
    assert code == 1 and out.strip().splitlines()[-1].startswith("not accepted: to try: ")
    # one of the suggestions: another triangulation of the grid converges
    code, out, _ = run([*argv, "--diagonals", "parallel", "--out", str(tmp_path / "q")], capsys)
    assert "no developable polyhedron" not in out


def test_a_solver_point_with_a_collapsed_face_is_a_failed_solve(monkeypatch):
    """A solver that ends where a triangle has collapsed gave a ValueError ("face 0 ... is
    degenerate") from inside ``solve``; it is a failed solve, at the start point."""
    from rigidfold.optimize import Status
    from rigidfold.optimize.ipopt import IpoptSolver
    from rigidfold.optimize.solver import SolverOutcome, SolverRun

    case = case_from_specs("dome", "grid:3x3")
    problem = case.problem()
    coords = case.pattern.coords.copy()
    face = case.pattern.faces[0]
    coords[face[2]] = coords[face[0]]  # face 0 collapses onto an edge

    def collapsed(self, xi0, w, deadline=None, max_iter=None, stall=None):
        return SolverRun(problem.start_point(coords), 7, SolverOutcome.SOLVED, "IPOPT: x")

    monkeypatch.setattr(IpoptSolver, "solve", collapsed)
    result = problem.solve()
    assert result.status is Status.FAILED
    assert "degenerate" in result.message
    np.testing.assert_array_equal(result.coords, case.pattern.coords)


# ---------------------------------------------------- item 24: misspelt options, millimetres
@pytest.mark.parametrize(
    ("argv", "suggestion"),
    [
        (["generate", "--surface", "dome", "--targetdof", "0"], "did you mean --target-dof?"),
        (["optimize", "--surface", "dome", "--overwite"], "did you mean --overwrite?"),
        (["genrate", "--surface", "dome"], "did you mean 'generate'?"),
        (["generate", "--criterion", "shta"], "did you mean 'shat'?"),
        (["export", "x.fold", "--convention", "origami-simulater"], "'origami-simulator'?"),
    ],
)
def test_a_misspelt_option_or_choice_gets_did_you_mean(argv, suggestion, tmp_path, capsys):
    code, _, err = run([*argv, "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and err.count("\n") == 1, err
    assert suggestion in err
    assert not (tmp_path / "o").exists()


def test_an_unknown_option_without_a_near_name_gets_no_guess(tmp_path, capsys):
    code, _, err = run(["optimize", "--zzzzzz", "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "unrecognized arguments: --zzzzzz" in err and "did you mean" not in err


@pytest.mark.parametrize(
    ("options", "warning"),
    [
        (["--size", "3000x3000"], "the plan is 3000 m x 3000 m"),
        (["--dz", "300"], "--dz 300 m is larger than the plan (3 m x 3 m)"),
    ],
)
def test_sizes_that_look_like_millimetres_get_a_warning(options, warning, tmp_path, capsys):
    """``--size 3000x3000`` (millimetres meant) designs a 3 km shelter: a warning on
    stderr says the sizes are metres; the run goes on."""
    argv = ["optimize", "--surface", "dome", "--pattern", "grid:3x3", *options]
    code, _, err = run([*argv, "--out", str(tmp_path / "o")], capsys)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rigidfold: warning: "), err
    assert warning in lines[0] and "metres" in lines[0]
    assert code in (0, 1) and (tmp_path / "o" / "summary.json").is_file()


def test_sizes_in_metres_get_no_warning(tmp_path, capsys):
    argv = ["optimize", "--surface", "dome", "--pattern", "grid:3x3", "--size", "12x8"]
    code, _, err = run([*argv, "--dz", "0.5", "--out", str(tmp_path / "o")], capsys)
    assert code in (0, 1) and err == ""
