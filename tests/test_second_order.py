"""The second-order test of shapes in generation (rigidfold.mechanism.second_order): known
self-stresses, forecasts that agree with the test of the child, the run's records."""

from __future__ import annotations

import time

import numpy as np
import pytest

import rigidfold.generate.deploy_check as deploy_check
from conftest import folded_grid
from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, Generation, Solution, Stop
from rigidfold.mechanism import analyze
from rigidfold.mechanism.margin import dof_margin
from rigidfold.mechanism.path import trace_path
from rigidfold.mechanism.second_order import ChildForecast, first_order, obstruction
from rigidfold.mesh import CreasePattern

# a generic flat degree-4 vertex: no two of its creases in line
GENERIC4 = np.array([[0.0, 0.0], [2.1, 0.2], [2.3, 1.9], [-0.2, 2.2], [1.05, 0.93]])
# the same with its creases in two straight lines (a square and its centre)
STRAIGHT4 = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0], [1.0, 1.0]])
FACES4 = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


def degree3() -> CreasePattern:
    """A triangle cut into three at a flat interior vertex (3): a degree-3 flat vertex."""
    coords = np.array([[0.0, 0.0], [2.0, 0.0], [0.8, 1.7], [0.9, 0.6]])
    return CreasePattern.from_faces(coords, np.array([[0, 1, 3], [1, 2, 3], [2, 0, 3]]))


def test_a_flat_degree_3_vertex_is_mobile_at_first_order_and_rigid_at_second():
    shape = degree3()
    assert analyze(shape, support_face=0).dof == 1
    ob = obstruction(shape, 0, 1)
    # an exact self-stress (singular value round-off) with a definite stress form
    assert ob.rigid and not ob.finite_motion
    assert ob.margin > DEFAULTS.structure.prestress_tol and ob.energy > 0
    assert ob.sigma < 1e-12 and ob.strain > DEFAULTS.path.tol
    d = ob.to_dict()
    assert d["rigid"] is True and d["flexes"] == 1


def test_the_stress_form_is_the_second_derivative_of_the_constraints():
    """z^T Hess(g_i) z against finite differences of g along the flex."""
    shape = degree3()
    fo = first_order(shape, 0, 1)
    z = fo.flexes[:, 0]
    x0 = fo.cons.x0
    h = 1e-4
    g = [fo.cons.values(x0 + t * z.reshape(-1, 3)) for t in (-h, 0.0, h)]
    second = (g[0] - 2 * g[1] + g[2]) / h**2
    np.testing.assert_allclose(fo.forms[:, 0, 0], second, atol=1e-5)


@pytest.mark.parametrize("fold", [0.3, 0.8])
def test_a_folded_degree_4_vertex_is_not_second_order_rigid_and_deploys(fold):
    shape = _folded_vertex(fold)
    dof = analyze(shape, support_face=0).dof
    assert dof == 1
    assert not obstruction(shape, 0, dof).rigid
    assert trace_path(shape, dof=dof, support_face=0).deploys


def test_forecast_of_a_child_is_the_test_of_the_child_at_the_same_geometry():
    """Fixing a crease that rotates adds no self-stress and keeps the flexes without its
    rate: the forecast at the parent is the child's own second-order test."""
    for coords, rigid in ((GENERIC4, True), (STRAIGHT4, False)):
        parent = CreasePattern.from_faces(coords, FACES4)
        dof = analyze(parent, support_face=0).dof
        assert dof == 2  # a flat degree-4 vertex: two flexes at first order
        forecast = ChildForecast.at(parent, 0, dof)
        assert not forecast.dead_end  # a degree-4 vertex folds
        for crease in parent.interior_edges:
            fixed = parent.fixed.copy()
            fixed[crease] = True
            child = parent.with_fixed(fixed)
            assert analyze(child, support_face=0).dof == 1
            said = forecast.rigid((int(crease),))
            found = obstruction(child, 0, 1)
            assert said == found.rigid == rigid


def test_a_shape_whose_stress_form_is_definite_is_a_dead_end():
    """The flat degree-3 vertex: its one flex is held at second order, so no fix of a crease
    leaves anything that folds; a flat degree-4 vertex (two flexes, a finite motion) is not."""
    assert ChildForecast.at(degree3(), 0, 1).dead_end
    generic = CreasePattern.from_faces(GENERIC4, FACES4)
    assert not ChildForecast.at(generic, 0, 2).dead_end


def test_the_dof_margin_names_a_clear_count_and_a_near_mechanism():
    shape = degree3()
    clear = dof_margin(shape, 0)
    assert clear.dof == 1 and clear.clear and "clear" in clear.message
    # a vertex lifted by 1e-7 of the span: DOF 0 by the count, a near-mechanism by the margin
    lifted = shape.with_coords(shape.coords + np.array([[0, 0, 0]] * 3 + [[0, 0, 2e-9]]))
    near = dof_margin(lifted, 0)
    assert not near.clear and near.near >= 1
    assert "no clear margin" in near.message or "without a clear gap" in near.message


class _Mech:
    def __init__(self, dof: int) -> None:
        self.dof = dof


class _Result:
    F = 1e-20


def test_final_dof_is_the_final_designs_and_the_lowest_is_its_own_field():
    sols = [Solution(k, _Result(), _Mech(d)) for k, d in enumerate((5, 2))]  # type: ignore[arg-type]
    run = Generation(initial_dof=7, solutions=sols, final_step=0, stop=Stop.NO_DEPLOYABLE)
    assert (run.final_dof, run.lowest_dof, run.n_reduce) == (5, 2, 5)
    d = run.to_dict()
    assert (d["final_dof"], d["lowest_dof"], d["final_step"]) == (5, 2, 0)
    assert AttemptOutcome.RIGID.value == "second_order_rigid"


def _folded_vertex(fold: float) -> CreasePattern:
    """The straight degree-4 vertex folded by ``fold`` about its diagonal 0-2."""
    c = np.column_stack([STRAIGHT4, np.zeros(5)])
    axis = (c[2] - c[0]) / np.linalg.norm(c[2] - c[0])
    p = c[3] - c[0]
    c[3] = c[0] + (
        p * np.cos(fold) + np.cross(axis, p) * np.sin(fold) + axis * (axis @ p) * (1 - np.cos(fold))
    )
    return CreasePattern.from_faces(c, FACES4)


def test_a_dense_step_passes_the_bifurcation_point_of_a_flat_vertex_on_its_branch():
    """The flat state of a degree-4 vertex is a bifurcation point (two flexes: a fold about
    either diagonal). Arriving along the fold about 0-2, the dense step continues on that
    branch, onto the constraints to the tracer's tolerance."""
    from rigidfold.mechanism.recovery import escape
    from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints

    flat = CreasePattern.from_faces(STRAIGHT4, FACES4)
    cons = RigidFoldingConstraints(flat, 0)
    t = np.zeros(cons.n)
    t[3 * 3 + 2] = 1.0  # vertex 3 leaves the plane: the fold about 0-2
    x0 = cons.x0
    out = escape(cons, x0, t, cons.free_angles(x0), 0.05, "projection", DEFAULTS)
    assert out is not None
    y, _, _, _ = out
    assert np.abs(cons.residual(y)).max() <= DEFAULTS.path.tol
    moved = (y - x0).reshape(-1, 3) * cons.scale
    assert abs(moved[3, 2]) > 1e-3  # along the branch it came on
    assert np.abs(moved[[0, 1, 2, 4]]).max() < 1e-9  # the other branch is not taken


def test_a_dense_step_is_not_tried_past_its_deadline():
    """The dense step of the flat vertex above, its deadline passed: none is tried (each
    corrector iteration is a dense least-squares solve; on a 463-vertex pattern they ran a
    trace 15 s past a run's time limit, docs/broad_set.md, session 29)."""
    from rigidfold.mechanism.recovery import escape
    from rigidfold.mechanism.rigid_folding import RigidFoldingConstraints

    cons = RigidFoldingConstraints(CreasePattern.from_faces(STRAIGHT4, FACES4), 0)
    t = np.zeros(cons.n)
    t[3 * 3 + 2] = 1.0
    x0, rho = cons.x0, cons.free_angles(cons.x0)
    for mode in ("projection", "descent"):
        assert escape(cons, x0, t, rho, 0.05, mode, DEFAULTS) is not None
        gone = time.monotonic() - 1.0
        assert escape(cons, x0, t, rho, 0.05, mode, DEFAULTS, deadline=gone) is None


def test_a_trace_whose_dense_step_outlasts_its_deadline_is_cut(monkeypatch):
    """A stall reached before the deadline whose dense step ends after it: the trace is cut
    (no verdict on the shape), not stalled."""
    from rigidfold.mechanism import path as path_module

    real, deadline = path_module.correct, time.monotonic() + 1.0

    def failing(*args, **kwargs):
        y, _, nf, system = real(*args, **kwargs)
        return y, False, nf, system

    def slow_escape(*args, **kwargs):
        while time.monotonic() <= deadline:
            time.sleep(0.01)
        return None

    monkeypatch.setattr(path_module, "correct", failing)
    monkeypatch.setattr(path_module, "escape", slow_escape)
    path = trace_path(_folded_vertex(0.8), dof=1, support_face=0, deadline=deadline)
    assert path.cut and path.status.name == "MAX_STEPS"


def test_a_trace_whose_sparse_corrector_fails_goes_on_by_dense_steps(monkeypatch):
    """A stall of the sparse continuation (forced here: its corrector fails on the first
    30 calls) is passed by a dense step, and the path still reaches the flat state."""
    from rigidfold.mechanism import path as path_module

    real, calls = path_module.correct, [0]

    def failing(*args, **kwargs):
        calls[0] += 1
        y, ok, nf, system = real(*args, **kwargs)
        return (y, False, nf, system) if calls[0] <= 30 else (y, ok, nf, system)

    monkeypatch.setattr(path_module, "correct", failing)
    shape = _folded_vertex(0.8)
    path = trace_path(shape, dof=1, support_face=0)
    assert path.deploys and path.escapes >= 1
    assert path.max_length_error < 1e-8


def test_a_rigid_candidate_is_rejected_before_its_trace_with_the_same_verdict(monkeypatch):
    """With ``second_order_first`` a candidate's solution found second-order rigid is
    rejected (RIGID) without tracing its path; the search is the same attempt for attempt as
    when the test follows a trace that does not reach the flat state (none of those
    rigid solutions' traces reached it)."""
    import dataclasses

    from rigidfold.generate import generate
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.mechanism.path import PathStatus

    real = deploy_check.trace_path
    doomed: set[bytes] = set()
    traced: list[tuple[bytes, str]] = []

    def first_two_never_deploy(pattern, **kwargs):
        path = real(pattern, **kwargs)
        key = pattern.fixed.tobytes()
        if kwargs.get("dof") == 1 and (len(doomed) < 2 or key in doomed):
            doomed.add(key)
            path = dataclasses.replace(path, status=PathStatus.TURNED_BACK)
        traced.append((key, path.status.value))
        return path

    monkeypatch.setattr(deploy_check, "trace_path", first_two_never_deploy)
    runs, traces = [], []
    for first in (True, False):
        doomed.clear()
        traced.clear()
        settings = DEFAULTS.with_(second_order_first=first, restart_after=2, fold_limits=())
        case = case_from_specs("bezier", "1", seed=1, settings=settings)
        runs.append(  # the paper's solver, IPOPT alone, with which this case meets rigid ones
            generate(case, criterion="s", seed=1, lookahead=True, deform=False, projection="large")
        )
        traces.append(list(traced))
    before, after = runs
    rigid = [a for a in before.attempts if a.outcome is AttemptOutcome.RIGID]
    assert rigid, "the run met second-order rigid candidates"
    assert all(a.path is None and a.second_order["rigid"] for a in rigid)
    assert [(a.fixed_added, a.outcome, a.dof) for a in before.attempts] == [
        (a.fixed_added, a.outcome, a.dof) for a in after.attempts
    ]
    assert len(traces[0]) == len(traces[1]) - len(rigid)
    traced_after = [a for a in after.attempts if a.outcome is AttemptOutcome.RIGID]
    assert all(a.path is not None and not a.path["deploys"] for a in traced_after)


def _spanned(P: np.ndarray, Q: np.ndarray) -> float:
    """The sine of the largest principal angle between the spans of P and Q (same width)."""
    assert P.shape == Q.shape
    if P.shape[1] == 0:
        return 0.0
    cosines = np.linalg.svd(np.linalg.qr(P)[0].T @ np.linalg.qr(Q)[0], compute_uv=False)
    return float(np.sqrt(max(0.0, 1.0 - cosines.min() ** 2)))


def _sparse_cases() -> dict[str, CreasePattern]:
    """Shapes with self-stresses and second-order rigid children: a generic folded grid
    with creases fixed, a flat grid (its flexes leave the plane; every fixed crease adds a
    self-stress of its flat vertices), the flat degree-3 vertex (second-order rigid) and
    the generic flat degree-4 vertex (every child second-order rigid)."""
    rng = np.random.default_rng(3)
    folded = folded_grid(8, amplitude=0.15, seed=2)
    fixed = folded.fixed.copy()
    fixed[rng.choice(folded.interior_edges, 40, replace=False)] = True
    flat = folded_grid(5, amplitude=0.0)
    flat_fixed = flat.fixed.copy()
    flat_fixed[rng.choice(flat.interior_edges, 14, replace=False)] = True
    return {
        "folded-8x8": folded.with_fixed(fixed),
        "flat-5x5": flat.with_fixed(flat_fixed),
        "degree-3": degree3(),
        "generic-4": CreasePattern.from_faces(GENERIC4, FACES4),
    }


@pytest.mark.parametrize("name", ["folded-8x8", "flat-5x5", "degree-3", "generic-4"])
def test_the_sparse_first_order_spans_the_dense_one_and_forecasts_the_same(name):
    """From ``mechanism_sparse_analysis_vertices`` on, the flexes and self-stresses come from
    the smallest singular values of A and A^T without a dense SVD: the same spans, the same
    stress singular values, the same second-order verdicts on the shape and on every child."""
    shape = _sparse_cases()[name]
    dof = analyze(shape, support_face=0).dof
    dense_settings = DEFAULTS.with_(sparse_analysis_vertices=10**6)
    sparse_settings = DEFAULTS.with_(sparse_analysis_vertices=3)
    dense = first_order(shape, 0, dof, dense_settings)
    sparse = first_order(shape, 0, dof, sparse_settings)
    assert (dense.method, sparse.method) == ("dense", "sparse")
    assert sparse.flexes.shape == dense.flexes.shape
    assert sparse.stresses.shape == dense.stresses.shape and dense.stresses.shape[1] > 0
    assert _spanned(dense.flexes, sparse.flexes) < 1e-6
    assert _spanned(dense.stresses, sparse.stresses) < 1e-6
    np.testing.assert_allclose(sparse.flexes.T @ sparse.flexes, np.eye(dof), atol=1e-12)
    np.testing.assert_allclose(
        np.sort(sparse.stress_values), np.sort(dense.stress_values), rtol=1e-6, atol=1e-12
    )
    a = obstruction(shape, 0, dof, dense_settings)
    b = obstruction(shape, 0, dof, sparse_settings)
    assert (a.rigid, a.finite_motion, a.stresses) == (b.rigid, b.finite_motion, b.stresses)
    # margins near zero are round-off of either basis: they agree to the test's tolerance
    assert b.margin == pytest.approx(a.margin, rel=1e-4, abs=DEFAULTS.structure.prestress_tol)
    if dof >= 2:
        fa = ChildForecast.at(shape, 0, dof, dense_settings)
        fb = ChildForecast.at(shape, 0, dof, sparse_settings)
        assert fa.dead_end == fb.dead_end
        free = [int(c) for c in shape.interior_edges if not shape.fixed[c]]
        said = [fa.rigid((c,)) for c in free]
        assert said == [fb.rigid((c,)) for c in free]
        assert name != "generic-4" or all(said)
