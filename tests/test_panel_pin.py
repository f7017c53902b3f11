"""Panel-Pin against the frame model: over the folding motion of a DOF-1 design, the
smallest stiffness eigenvalue of Panel-Pin's formulation (tests/panel_pin.py: rigid panels,
pins at the vertices, hinge springs) and that of the frame model (the pseudo stiffness of
the selection criteria, rigidfold.mechanism) follow the same trend. The values differ (the
two models measure a mode's size in different displacements); their order must not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.stats import spearmanr

from panel_pin import PanelPin
from rigidfold.frame.model import default_support_face
from rigidfold.io import read_fold
from rigidfold.mechanism import analyze
from rigidfold.mechanism.path import trace_path
from rigidfold.mechanism.stiffness import PseudoStiffness
from rigidfold.mesh import CreasePattern

DATA = Path(__file__).parent / "data"


def trends(pattern: CreasePattern, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(fraction folded, frame model's, Panel-Pin's smallest eigenvalue) at n - 1 shapes of
    the folding motion (the flat end left out: there first order overstates the DOF), unit
    hinge stiffnesses."""
    frames, fraction = trace_path(pattern, dof=1).frames(pattern, n)
    frame, panel = [], []
    for coords in frames[1:]:
        shape = pattern.with_coords(coords)
        mech = analyze(shape)
        assert mech.dof == 1
        frame.append(PseudoStiffness(mech.H_phi, np.ones(len(mech.hinges))).eigenvalues[0])
        held = int(shape.facets[default_support_face(shape)])
        panel.append(PanelPin(shape).mechanism_eigenvalues(held)[0])
    return fraction[1:], np.array(frame), np.array(panel)


@pytest.mark.parametrize("design", ["dome_sym_dof1.fold", "roof_12x8_dof1.fold"])
def test_panel_pin_trend_agrees_with_the_frame_model(design):
    """Ten shapes of the motion (10 % to 100 % folded): the dome's eigenvalue rises and
    falls, the roof's falls. The rank correlation is at least 0.95, both peak and bottom at
    the same shape, and every step that changes either model's value by more than 5 % goes
    the same way in both (near the dome's peak, values within a few per cent of each other
    may swap: docs/structure.md)."""
    pattern = read_fold(DATA / design).pattern
    _, frame, panel = trends(pattern, 11)
    assert np.all(frame > 0) and np.all(panel > 0)
    assert spearmanr(frame, panel).statistic >= 0.95
    assert np.argmax(frame) == np.argmax(panel) and np.argmin(frame) == np.argmin(panel)
    rel_f, rel_p = np.diff(frame) / frame[:-1], np.diff(panel) / panel[:-1]
    large = (np.abs(rel_f) > 0.05) | (np.abs(rel_p) > 0.05)
    assert np.array_equal(np.sign(rel_f[large]), np.sign(rel_p[large]))
