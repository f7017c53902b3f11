"""The rigid-folding path (``rigidfold.mechanism.path``) and the deployability check of
generation (Step 5 beyond the paper: N_path)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from conftest import paper_generate
from rigidfold.cli.commands import main
from rigidfold.config import DEFAULTS
from rigidfold.frame.model import default_support_face
from rigidfold.generate import AttemptOutcome, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.io.fold import pattern_from_fold
from rigidfold.mechanism.path import PathStatus, trace_path
from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints, System, correct
from rigidfold.mesh.geometry import edge_lengths
from rigidfold.patterns import miura
from rigidfold.rundir import read_log

DATA = Path(__file__).parent / "data"


def locked(shape):
    """The shape with one more free crease fixed: a Miura-ori so made has no mechanism."""
    fixed = shape.fixed.copy()
    fixed[shape.free_creases[len(shape.free_creases) // 2]] = True
    return shape.with_fixed(fixed)


def free(shape):
    """The shape with every crease free (a Miura-ori's quads cut into free triangles)."""
    return shape.with_fixed(np.zeros(shape.n_edges, dtype=bool))


def assert_rigid(path, shape, tol=1e-8):
    """Every traced point keeps every edge length and fixed-crease fold angle."""
    from rigidfold.mesh import CreasePattern

    assert path.max_length_error < tol
    for point in path.points:
        assert np.allclose(edge_lengths(point, shape.edges), shape.edge_lengths, rtol=tol)
        moved = CreasePattern(point, shape.faces, shape.edges, shape.fixed, shape.settings)
        fixed = shape.fixed_creases
        assert np.allclose(moved.fold_angles[fixed], shape.fold_angles[fixed], atol=1e-7)


@pytest.mark.parametrize("height", [0.3, 0.5, 0.8])
def test_a_miura_ori_unfolds_to_flat_along_its_one_path(height):
    shape = miura(3, 3, height=height)
    path = trace_path(shape)
    assert path.status is PathStatus.FLAT and path.deploys and path.dof == 1
    assert path.max_fold[-1] <= DEFAULTS.path.flat_tol
    assert np.all(np.diff(path.measure) < 0)  # a Miura-ori unfolds monotonically
    assert path.limit_points == () and path.bifurcations == ()
    assert np.allclose(path.points[0], shape.coords, rtol=0, atol=1e-12)
    assert_rigid(path, shape)


def test_the_tangent_and_the_descent_direction_lie_in_the_null_space():
    """Invariants of the linear algebra: J t = 0 for the tangent of a 1-DOF shape and for the
    Gauss-Newton direction of a many-DOF one; the direction lowers the fold angles."""
    for shape, mode in ((miura(3, 3), "projection"), (free(miura(3, 3)), "descent")):
        cons = RigidFoldingConstraints(shape, default_support_face(shape))
        J, J_rho = cons.jacobian(cons.x0)
        rho = cons.free_angles(cons.x0)
        t0 = np.random.default_rng(1).standard_normal(cons.n)
        system = System(J, J_rho, mode, t0, DEFAULTS)
        d = system.direction(t0, rho)
        assert np.abs(J @ d).max() < 1e-9 * max(np.abs(d).max(), 1e-300)
        if mode == "descent":
            assert float(rho @ (J_rho @ d)) < 0


def test_the_jacobian_is_the_derivative_of_the_constraints():
    shape = miura(3, 3, height=0.6)
    cons = RigidFoldingConstraints(shape, default_support_face(shape))
    rng = np.random.default_rng(0)
    x = cons.x0 + 1e-3 * rng.standard_normal(cons.n)
    J, J_rho = cons.jacobian(x)
    v = rng.standard_normal(cons.n)
    h = 1e-6
    fd = (cons.residual(x + h * v) - cons.residual(x - h * v)) / (2 * h)
    assert np.allclose(J @ v, fd, atol=1e-7)
    fd_rho = (cons.free_angles(x + h * v) - cons.free_angles(x - h * v)) / (2 * h)
    assert np.allclose(J_rho @ v, fd_rho, atol=1e-7)
    assert sp.issparse(J) and J.shape == (cons.n_rows, cons.n)


def test_a_shape_without_mechanism_has_no_path():
    path = trace_path(locked(miura(3, 3)))
    assert path.status is PathStatus.RIGID and not path.deploys and len(path.points) == 1


def test_a_shape_of_many_dof_goes_to_flat_closest_to_the_straight_line():
    shape = free(miura(3, 3))
    path = trace_path(shape)
    assert path.dof == 9 and path.deploys
    assert np.all(np.diff(path.measure) < 0)
    assert_rigid(path, shape)


def test_a_path_that_turns_back_is_found_and_explained():
    """The DOF-1 shape of the symmetric dome (criterion S, Section 6.5): its one path comes
    down to 0.288 of the design's folding measure and folds up again."""
    shape = pattern_from_fold(DATA / "dome_sym_dof1.fold")
    path = trace_path(shape)
    assert path.status is PathStatus.TURNED_BACK and not path.deploys
    assert "turns back at m = 0.288" in path.message
    assert path.measure[path.closest] == pytest.approx(0.288, abs=5e-4)
    assert len(path.limit_points) >= 1
    record = path.to_dict()
    assert record["closest_measure"] == pytest.approx(0.288, abs=5e-4)
    assert len(record["fold_at_closest_deg"]) == len(shape.free_creases)
    json.dumps(record)
    assert_rigid(path, shape)


def test_path_settings_take_effect():
    shape = miura(3, 3, height=0.5)
    budget = trace_path(shape, settings=DEFAULTS.with_(path_max_steps=1))
    assert budget.status is PathStatus.MAX_STEPS and budget.steps <= 2 * 1
    collide = trace_path(shape, settings=DEFAULTS.with_(path_collision_angle=math.radians(1.0)))
    assert collide.status in (PathStatus.COLLISION, PathStatus.TURNED_BACK)
    loose = trace_path(shape, settings=DEFAULTS.with_(path_flat_tol=math.radians(170.0)))
    assert loose.deploys and loose.steps == 0 and "flat already" in loose.message
    fine = trace_path(shape, settings=DEFAULTS.with_(path_max_fold_step=math.radians(1.0)))
    coarse = trace_path(shape)
    assert fine.deploys and fine.steps > coarse.steps


def test_a_creeping_descent_ends_where_its_pace_puts_the_flat_state_beyond_its_budget():
    """A descent (DOF 9) held to small steps falls by about 1/177 of the design's measure a
    step: with a budget of 150 steps, the flat state is beyond it at that pace and the trace
    ends after its first window of steps; with 220 it reaches the flat state, as it does
    with the default pace settings."""
    shape = free(miura(3, 3))
    small = DEFAULTS.with_(path_max_fold_step=math.radians(0.2))
    whole = trace_path(shape, settings=small)
    assert whole.deploys and 150 < whole.steps < 220
    pace = {"path_pace_steps": 10, "path_pace_margin": 1.0}
    short = trace_path(shape, settings=small.with_(path_max_steps=150, **pace))
    assert short.status is PathStatus.MAX_STEPS and short.steps == 10 and not short.cut
    assert "at its pace" in short.message and "140 steps left" in short.message
    room = trace_path(shape, settings=small.with_(path_max_steps=220, **pace))
    assert room.deploys and room.steps == whole.steps


def test_motion_frames_are_equal_steps_of_the_path_and_keep_lengths():
    from rigidfold.deform import folding_motion
    from rigidfold.develop import develop

    shape = miura(4, 3)
    motion = folding_motion(shape, develop(shape).coords2d)
    assert motion.status == "ok" and len(motion.frames) == DEFAULTS.deformation.motion_frames
    assert np.allclose(motion.parameter, np.linspace(0, 1, DEFAULTS.deformation.motion_frames))
    assert motion.max_length_error < 1e-8
    assert motion.path["deploys"] is True


# --------------------------------------------------------------- generation (N_path)
@pytest.fixture(scope="module")
def seed_103():
    """Pattern 1 on Bezier seed 103 (S-hat, look-ahead): the paper's Step 5 ends on a DOF-1
    shape whose path does not reach the flat state; the deployability check replaces it (on
    the paper's chain, one crease per solve)."""
    case = case_from_specs("bezier", "1", seed=103)
    paper = paper_generate(case, criterion="shat", seed=103, lookahead=True)
    checked = generate(case, criterion="shat", seed=103, lookahead=True, batch="off")
    return case, paper, checked


def test_a_design_whose_path_turns_back_is_rejected(seed_103):
    _, paper, checked = seed_103
    final = paper.solutions[-1]
    assert paper.final_dof == 1 and paper.n_path == 0 and not paper.deploy_check
    assert not trace_path(final.result.pattern, dof=1).deploys  # as the paper delivers it
    assert checked.deploy_check and checked.n_path >= 1
    rejected = [a for a in checked.attempts if a.outcome is AttemptOutcome.PATH]
    assert len(rejected) == checked.n_path
    for attempt in rejected:
        assert attempt.path is not None and attempt.path["deploys"] is False
        assert attempt.path["status"] != "flat" and attempt.dof is not None
        assert len(attempt.path["fold_at_closest_deg"]) > 0


def test_a_deployable_design_is_accepted_and_delivered(seed_103):
    _, _, checked = seed_103
    final = checked.final
    assert checked.final_dof == 1 and final is not None and final.path is not None
    assert final.path.deploys and final.path.max_fold[-1] <= DEFAULTS.path.flat_tol
    assert_rigid(final.path, final.result.pattern)
    assert final.result.F <= DEFAULTS.solver.polish_tol * 10  # polished to F = 0
    record = checked.to_dict()
    assert record["n_path"] == checked.n_path and record["final_deploys"] is True
    assert record["time_s"]["path"] > 0


def test_polish_keeps_the_constraints_and_moves_the_shape_little():
    case = case_from_specs("bezier", "1", seed=1)
    problem = case.problem()
    result = problem.solve()
    polished = problem.polish(result)
    assert polished.F <= DEFAULTS.solver.polish_tol < result.F
    assert polished.max_violation <= DEFAULTS.solver.constraint_tol
    assert np.abs(polished.coords - result.coords).max() < 1e-3
    assert np.abs(polished.pattern.angle_defects).max() < 1e-12


def test_the_counters_are_stored_and_reported(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["generate", "--surface", "bezier", "--seed", "103", "--pattern", "1"]
    flags = ["--lookahead", "--no-deform", "--quiet", "--batch", "off"]  # the paper's chain
    assert main([*args, *flags, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert f"N_path={summary['n_path']}" in printed and summary["n_path"] >= 1
    assert summary["final_deploys"] is True and summary["options"]["deploy_check"] is True
    log = read_log(out / "log.jsonl")
    assert sum(a.outcome == "path" for a in log) == summary["n_path"]
    # the report's slider shows the traced path of the final design, flat to folded
    final = json.loads((out / summary["verdict"]["final_design"]).read_text())
    motion = [f for f in final["file_frames"] if "folding motion" in f.get("frame_title", "")]
    assert len(motion) == DEFAULTS.deformation.motion_frames
    assert final["rigidfold:motion"]["path"]["deploys"] is True
    html = (out / "report.html").read_text()
    assert "N_path" in html


# DOF-1 shapes of Origami Simulator's waterbomb (195 vertices) whose paths stalled before:
# six on the dome (a run of commit 48ded5e) and three on Bezier seed 7 (benchmarks/
# deploy_anywhere.py, bezier:waterbomb); the test runs the six and the second of the three
# (the others take some 8 s each). Two more, of constraints without redundant rows (n - 1 of
# them) that stalled at near singular points after the dense steps (commit 0110e3a, issue 40):
# waterbomb_bezier_3 (bezier:waterbomb; kept in the data, out of the tests: it takes 7-15 s)
# and huffman_waterbomb_bezier_0 (440 vertices, bezier:huffmanWaterbomb; the test after next)
STALLED = [
    *sorted((DATA / "stalled").glob("waterbomb_dome_*.npz")),
    DATA / "stalled" / "waterbomb_bezier_1.npz",
]


def stalled_shape(file):
    """A DOF-1 shape saved in tests/data (its coordinates, faces, edges, fixed creases and
    DOF): one whose sparse continuation stalled (``stalled/``), or another path's case."""
    from rigidfold.mesh import CreasePattern

    data = np.load(file)
    shape = CreasePattern(
        coords=data["coords"],
        faces=data["faces"].astype(np.int64),
        edges=data["edges"].astype(np.int64),
        fixed=data["fixed"],
    )
    return shape, int(data["dof"])


@pytest.mark.parametrize("file", STALLED, ids=[f.stem for f in STALLED])
def test_a_path_whose_projection_continuation_stalled_ends_classified(file):
    """Self-stressed constraints with near-singular values at the regularisation: once the
    projection continuation stalls, the redundant rows are dropped and the square system of
    the independent rows goes on (where it stalls too, with the near flexes held), to one
    of the classified ends (not ``stalled``), every traced point on the constraints to
    path_tol; a path that stops where least squares leaves a residual above path_tol says
    so, with the near self-stress's singular value."""
    shape, dof = stalled_shape(file)
    path = trace_path(shape, dof=dof, support_face=default_support_face(shape))
    assert path.status is not PathStatus.STALLED, path.message
    assert path.dropped_rows > 0
    assert path.max_length_error < 1e-8
    if path.status is PathStatus.STOPS_SHORT and "least-squares residual" in path.message:
        assert "near self-stress" in path.message  # it says why no step goes on


def test_a_stall_without_redundant_rows_goes_on_by_the_branches_of_a_near_bifurcation():
    """Constraints of n - 1 independent rows (nothing to drop) with a second near flex
    (singular value about 1e-10 of the largest): the dense step past the stall tries the
    branches in the plane of J's two smallest singular vectors, and the path ends
    classified, every point on the constraints to path_tol."""
    shape, dof = stalled_shape(DATA / "stalled" / "huffman_waterbomb_bezier_0.npz")
    path = trace_path(shape, dof=dof, support_face=default_support_face(shape))
    assert path.status is not PathStatus.STALLED, path.message
    assert path.dropped_rows == 0 and path.escapes >= 1
    assert path.max_length_error < 1e-8


# DOF-1 shapes of the paper's pattern 2 (52 vertices) whose paths stalled: Bezier seed 24,
# criterion S, with the look-ahead and the deployability check (the study of Tables 5-6,
# issue 40, session 19). Each holds a fixed crease at 180 degrees (its facets folded onto
# each other); the fixed-angle residual jumped by 2 pi where atan2 flipped to -180, and the
# corrector diverged from it (residuals of 1e3 to 1e11). Taken modulo 2 pi, they trace.
FOLDED_FIXED = [DATA / "stalled" / f"paper2_s_24_{k}.npz" for k in range(4)]


@pytest.mark.parametrize("file", FOLDED_FIXED, ids=[f.stem for f in FOLDED_FIXED])
def test_a_shape_with_a_fixed_crease_at_180_degrees_traces_to_a_classified_end(file):
    shape, dof = stalled_shape(file)
    fixed = shape.fixed_creases
    assert np.abs(shape.fold_angles[fixed]).max() > np.radians(179.9)
    support = default_support_face(shape)
    path = trace_path(shape, dof=dof, support_face=support)
    assert path.status is not PathStatus.STALLED, path.message
    assert path.max_length_error < 1e-8
    cons = RigidFoldingConstraints(shape, support)
    for point in path.points:  # every fixed crease held, through the flip of atan2 too
        assert np.abs(cons.residual(point.ravel() / cons.scale)).max() < 1e-8


def test_a_fixed_angle_residual_is_continuous_through_180_degrees():
    """The change of a fold angle is taken modulo 2 pi: +179.9 to -179.9 degrees is a turn of
    0.2 degrees, not of 359.8."""
    from rigidfold.mesh.geometry import angle_change

    a, b = np.radians([179.9, -179.9, 10.0]), np.radians([-179.9, 179.9, -20.0])
    assert np.allclose(np.degrees(angle_change(a, b)), [-0.2, 0.2, 30.0])


def test_the_square_system_of_the_independent_rows_corrects_by_least_squares():
    """On self-stressed constraints (a Miura-ori's rigid quads), the rows kept are
    independent and n - 1 of them; the tangent of [J_rows; t^T] is in the null space of the
    whole J; a correction leaves exactly the least-squares residual of the linearised
    constraints (the part of c in the self-stresses), as dense least squares does."""
    from rigidfold.mechanism.rigid_folding import independent_rows

    shape = miura(3, 3, height=0.6)
    cons = RigidFoldingConstraints(shape, default_support_face(shape))
    J, J_rho = cons.jacobian(cons.x0)
    rows, sigma = independent_rows(J, 1)
    assert len(rows) == cons.n - 1 < cons.n_rows and sigma < DEFAULTS.mechanism.rank_tol
    assert np.linalg.matrix_rank(J[rows].toarray()) == cons.n - 1
    rho = cons.free_angles(cons.x0)
    t0 = System(J, J_rho, "projection", None, DEFAULTS).direction(-(J_rho.T @ rho), rho)
    system = System(J, J_rho, "augmented", t0, DEFAULTS, rows)
    t = system.direction(t0, rho)
    assert np.abs(J @ t).max() < 1e-9 and t @ t0 > 0
    c = np.random.default_rng(2).standard_normal(cons.n_rows) * 1e-6
    dy = system.correction(c)
    assert abs(t0 @ dy) < 1e-12
    A = np.vstack([J.toarray(), 1e6 * t0])  # the tangent row held (weighted)
    best = np.linalg.lstsq(A, -np.r_[c, 0.0], rcond=None)[0]
    left = c + J @ dy
    assert np.allclose(left, c + J @ best, atol=1e-12)
    assert np.allclose(left, system.irreducible(c), atol=1e-12)


@pytest.mark.parametrize("n", [3, 8])
def test_the_sparse_independent_rows_span_the_row_space_as_the_dense_ones(n):
    """From ``mechanism_sparse_analysis_vertices`` on the self-stresses whose rows are
    dropped come from the smallest singular values of J^T (no dense SVD): n - 1 rows kept,
    of full rank, the same smallest singular value."""
    from rigidfold.mechanism.rigid_folding import independent_rows

    shape = miura(n, n, height=0.6)
    cons = RigidFoldingConstraints(shape, default_support_face(shape))
    J = cons.jacobian(cons.x0)[0]
    dense, sigma = independent_rows(J, 1)
    sparse, sigma_sparse = independent_rows(J, 1, DEFAULTS)
    assert len(sparse) == len(dense) == cons.n - 1 < cons.n_rows
    assert np.linalg.matrix_rank(J[sparse].toarray()) == cons.n - 1
    assert sigma < DEFAULTS.mechanism.rank_tol and sigma_sparse < DEFAULTS.mechanism.rank_tol


# DOF-1 shapes of the paper's patterns whose constraints keep a second near flex along the
# whole path (J's second smallest singular value about 1e-9 of the largest, at the rank
# threshold): Newton's corrector converges there at its linear rate, the steps stay small,
# and the trace needs 200 to 800 of them (the study of Tables 5-6, issue 40, session 20:
# pattern 1, S-hat, Bezier seed 20; pattern 2, S-hat, seed 32). With a budget of 200 steps
# they ended `max_steps` and were rejected; they deploy.
NEAR_FLEX = sorted((DATA / "near_flex").glob("*.npz"))


@pytest.mark.parametrize("file", NEAR_FLEX, ids=[f.stem for f in NEAR_FLEX])
def test_a_path_along_a_second_near_flex_reaches_the_flat_state(file):
    shape, dof = stalled_shape(file)
    support = default_support_face(shape)
    cons = RigidFoldingConstraints(shape, support)
    s = np.linalg.svd(cons.jacobian(cons.x0)[0].toarray(), compute_uv=False)
    assert s[-1] / s[0] < 1e-8  # J (n - 1, n): the path's flex, and a second near one
    path = trace_path(shape, dof=dof, support_face=support)
    assert path.status is PathStatus.FLAT, path.message
    assert path.max_length_error < 1e-8


def test_a_path_that_folds_further_on_its_way_to_the_flat_state_deploys():
    """A DOF-1 child of Origami Simulator's sharp-angled Miura-ori on the dome (761 free
    creases; the clear DOF-2 shape of a run, crease 5 fixed and solved from it, session 37):
    its folding measure falls to 0.93 of the design's, rises some 0.13 above that as creases
    fold further, then falls to the flat state. With a turn back at a rise of 0.05 (the
    setting before session 37) the trace called it "turns back" and the search rejected a
    design that deploys; with ``path_turn_back`` 1 (a rise by the design's own measure) it
    reaches the flat state, every point on the constraints to path_tol."""
    shape, dof = stalled_shape(DATA / "turn_back" / "miura_sharpangle_dome_0.npz")
    path = trace_path(shape, dof=dof)
    assert path.status is PathStatus.FLAT, path.message
    assert path.max_length_error < 1e-8
    rise = path.measure - np.minimum.accumulate(path.measure)
    assert 0.05 < rise.max() < DEFAULTS.path.turn_back  # it folds further on the way
    early = trace_path(shape, dof=dof, settings=DEFAULTS.with_(path_turn_back=0.05))
    assert early.status is PathStatus.TURNED_BACK


def test_the_corrector_gives_a_prediction_beyond_newtons_reach_up_at_its_bound():
    """``Settings.path.corrector_factorizations``: a trace's corrector that would factorise
    its system more often than that for one step fails there (the step is halved), where it
    went on before, 5 to 9 factorisations for a step it failed anyway; a step within
    Newton's reach converges to the same point either way."""
    shape, _ = stalled_shape(DATA / "turn_back" / "miura_sharpangle_dome_0.npz")
    cons = RigidFoldingConstraints(shape, default_support_face(shape))
    mode = "augmented" if cons.n_rows == cons.n - 1 else "projection"
    J, J_rho = cons.jacobian(cons.x0)
    rho = cons.free_angles(cons.x0)
    t = System(J, J_rho, "projection", None, DEFAULTS).direction(-(J_rho.T @ rho), rho)
    t /= np.linalg.norm(t)
    rms = math.sqrt(shape.n_vertices)  # one mean edge length of root-mean-square steps
    most = DEFAULTS.path.corrector_factorizations
    assert most > 0

    def corrected(length, bound):
        return correct(cons, cons.x0 + length * rms * t, mode, t, DEFAULTS, most=bound)

    near, near_bounded = corrected(1e-3, 0), corrected(1e-3, most)
    assert near[1] and near_bounded[1] and near[2] <= most
    assert np.array_equal(near[0], near_bounded[0])
    far, far_bounded = corrected(2.0, 0), corrected(2.0, most)
    assert not far[1] and not far_bounded[1]  # beyond reach: both fail
    # the same iterations up to the bound, where the bounded one stops
    assert far_bounded[2] == min(most, far[2])
