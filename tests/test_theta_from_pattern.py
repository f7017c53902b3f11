"""``Settings.design.theta_from_pattern`` (``--theta-from-pattern``): the sector-angle
bounds widened to a drawn pattern's own angles, the side it breaks only, so that problem (6)
starts inside them (issue 49: the first solve of drawn patterns)."""

from __future__ import annotations

import math
from pathlib import Path

from rigidfold.config import DEFAULTS, Settings
from rigidfold.generate.case_options import SettingsOptions
from rigidfold.generate.specs import case_from_specs

DATA = Path(__file__).parent / "data" / "origami_simulator"
ON = Settings().with_(theta_from_pattern=True)


def test_off_by_default_the_paper_bounds():
    assert DEFAULTS.design.theta_from_pattern is False
    case = case_from_specs("hp", str(DATA / "cross.svg"), seed=1)
    assert case.settings.design.theta_min == DEFAULTS.design.theta_min
    assert case.settings.design.theta_max == DEFAULTS.design.theta_max


def test_a_drawn_patterns_slivers_are_kept_inside_the_bounds():
    for name, surface in [("cross", "hp"), ("MoosersTrainRigid-Gardner", "hp")]:
        case = case_from_specs(surface, str(DATA / f"{name}.svg"), seed=1, settings=ON)
        angles = case.pattern.corner_angles
        d = case.settings.design
        assert d.theta_min < angles.min() and angles.max() < d.theta_max  # strictly inside
        assert d.theta_min == 0.9 * angles.min()  # the side broken only, with its margin
        if angles.max() <= DEFAULTS.design.theta_max:
            assert d.theta_max == DEFAULTS.design.theta_max
        else:
            assert math.isclose(d.theta_max, angles.max() + 0.1 * (math.pi - angles.max()))
        # the other settings are the given ones
        assert case.settings.design.dz == ON.design.dz and case.settings.mechanism == ON.mechanism


def test_a_pattern_inside_the_bounds_keeps_them():
    case = case_from_specs("dome", "grid:5x5", settings=ON)
    assert case.settings is ON


def test_the_command_lines_flag_sets_it():
    assert SettingsOptions(theta_from_pattern=True).settings().design.theta_from_pattern
    assert not SettingsOptions().settings().design.theta_from_pattern
