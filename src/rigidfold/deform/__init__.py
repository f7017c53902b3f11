"""Step 9: large-deformation check (OpenSees), the folding motion, and both with Step 8."""

from rigidfold.deform.analysis import (
    DeformResult,
    DeformStatus,
    PanelSection,
    TubeSection,
    deform,
    panel_section,
)
from rigidfold.deform.check import Agreement, Verdicts, Verification, compare, verify
from rigidfold.deform.motion import Motion, MotionStatus, folding_motion

__all__ = [
    "Agreement",
    "DeformResult",
    "DeformStatus",
    "Motion",
    "MotionStatus",
    "PanelSection",
    "TubeSection",
    "Verdicts",
    "Verification",
    "compare",
    "deform",
    "folding_motion",
    "panel_section",
    "verify",
]
