"""Steps 8 and 9 of one shape: development diagram, large-deformation check, folding motion.

:func:`verify` is what ``rigidfold generate`` runs for every accepted solution and what
``rigidfold deform`` runs on a FOLD file. The development (Step 8) always runs; the
OpenSees analysis only when asked; the motion is traced from the development when the
development converged. Every stage's failure is a status in the result, never an exception.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from rigidfold.config import DEFAULTS, Settings
from rigidfold.deform.analysis import DeformResult, deform
from rigidfold.deform.motion import Motion, folding_motion
from rigidfold.develop import Development, DevelopStatus, develop
from rigidfold.mesh import CreasePattern


@dataclass
class Verification:
    """Results of Steps 8-9 for one shape; ``deformation`` / ``motion`` None when not run."""

    development: Development
    deformation: DeformResult | None
    motion: Motion | None
    times: dict

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures of every stage (for log.json, summary.json and the CLI)."""
        out: dict[str, Any] = {
            "development": self.development.to_dict(),
            "deformation": None if self.deformation is None else self.deformation.to_dict(),
            "motion": None if self.motion is None else self.motion.to_dict(),
            "time_s": dict(self.times),
        }
        if self.deformation is not None:
            out["deformation"]["history"] = self.deformation.history
        return out


def verify(
    pattern: CreasePattern,
    *,
    run_deform: bool = True,
    run_motion: bool = True,
    support_face: int | None = None,
    settings: Settings = DEFAULTS,
) -> Verification:
    """Development (Step 8), large-deformation check (Step 9) and motion of one shape."""
    times = {}
    t0 = time.perf_counter()
    development = develop(pattern, settings=settings)
    times["develop"] = time.perf_counter() - t0
    deformation = None
    if run_deform:
        t0 = time.perf_counter()
        deformation = deform(pattern, support_face=support_face, settings=settings)
        times["deform"] = time.perf_counter() - t0
    motion = None
    if run_motion and development.status is DevelopStatus.CONVERGED:
        t0 = time.perf_counter()
        motion = folding_motion(
            pattern, development.coords2d, support_face=support_face, settings=settings
        )
        times["motion"] = time.perf_counter() - t0
    return Verification(development, deformation, motion, times)
