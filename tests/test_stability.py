"""Second order where first order is not enough (rigidfold.mechanism.second_order): a flat or
nearly flat vertex held around its boundary is prestress stable and accepted; a hinge with
one side held is a finite mechanism and refused with its crease named."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import folded_grid
from rigidfold.mesh import CreasePattern
from rigidfold.structure import (
    MATERIALS,
    Stability,
    StructureStatus,
    Supports,
    auto_supports,
    check_structure,
    check_supports,
)
from test_structure import independent_kernel


def centre_vertex(height: float) -> CreasePattern:
    """A 1 m square of four triangles around a centre vertex raised by ``height``."""
    xy = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, height]], float)
    return CreasePattern.from_faces(xy, np.array([(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]))


@pytest.mark.parametrize("height", [0.0, 1e-4])
def test_flat_vertex_held_at_its_corners_is_prestress_stable(height):
    """The centre may leave the plane at first order (an independent rank computation finds
    the motion), but the spokes in tension hold it: accepted as prestress stable."""
    p = centre_vertex(height)
    corners = np.array([0, 1, 2, 3])
    r = check_supports(p, Supports(corners))
    if height == 0.0:
        assert independent_kernel(p, corners) == 1
    assert not r.rigid and r.stable
    assert r.stability is Stability.PRESTRESS
    assert r.second_order.flexes == 1 and r.second_order.margin > 0
    assert r.detail.startswith("prestress stable: a first-order motion")
    assert r.to_dict()["stability"] == "prestress_stable"
    # the flex is the centre leaving the plane
    w = r.second_order.witness.reshape(-1, 3)
    assert np.allclose(w[:4], 0, atol=1e-3) and abs(w[4, 2]) == pytest.approx(1.0, abs=1e-3)


def test_raised_vertex_is_first_order_rigid():
    r = check_supports(centre_vertex(0.05), Supports(np.array([0, 1, 2, 3])))
    assert r.rigid and r.stability is Stability.FIRST_ORDER and r.second_order is None


@pytest.mark.parametrize("angle", [0.0, 0.4])
def test_hinge_with_one_side_held_is_a_mechanism(angle):
    """Two triangles on a free crease 0-2, the first held at its corners: the second turns
    about the crease, a finite motion (flat or folded), refused with the crease named."""
    xy = np.array(
        [
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [0.5 - 0.5 * np.cos(angle), 0.5 + 0.5 * np.cos(angle), 0.7 * np.sin(angle)],
        ],
        float,
    )
    p = CreasePattern.from_faces(xy, np.array([(0, 1, 2), (0, 2, 3)]))
    r = check_supports(p, Supports(np.array([0, 1, 2])))
    assert not r.rigid and not r.stable
    assert r.stability is Stability.MECHANISM
    crease = int(np.flatnonzero((p.edges == [0, 2]).all(axis=1))[0])
    assert r.mode == f"a mechanism that folds crease {crease} (0-2)"
    # the motion found keeps every edge length
    moved = p.coords + r.second_order.witness.reshape(-1, 3)
    assert np.abs(moved - p.coords)[3].max() > 0.01
    e = p.edges
    lengths = np.linalg.norm(moved[e[:, 1]] - moved[e[:, 0]], axis=1)
    assert np.allclose(lengths, p.edge_lengths, rtol=1e-8)
    check = check_structure(p, r, material=MATERIALS["plywood"], thickness=0.018, modes=0)
    assert check.status is StructureStatus.MECHANISM and check.response is None
    assert "mechanism that folds crease" in check.message


def test_flat_sheet_on_its_boundary():
    """A flat 4 x 4 grid: its boundary never makes it first-order rigid (every interior
    vertex may leave the plane), so auto returns the whole boundary, prestress stable. With
    free hinges its linear stiffness is singular and the check says the load was not carried;
    with hinge springs it carries the load and the reactions balance it."""
    p = folded_grid(4, 0.0)
    r = auto_supports(p, p.boundary_vertices)
    assert r.stability is Stability.PRESTRESS and r.second_order.flexes == 4
    assert set(r.supports.pinned) == set(p.boundary_vertices.tolist())
    common = dict(material=MATERIALS["plywood"], thickness=0.018, modes=0)
    free = check_structure(p, r, **common)
    assert free.status is StructureStatus.NOT_CONVERGED and "singular" in free.message
    sprung = check_structure(p, r, hinge_stiffness=100.0, **common)
    assert sprung.response.converged and sprung.balance_error < 1e-3
    assert sprung.status is not StructureStatus.MECHANISM
