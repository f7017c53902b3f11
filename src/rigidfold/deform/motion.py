"""The folding motion: a path of rigidly folded shapes from the plane to the designed shape.

The path is the shape's rigid-folding path (:func:`rigidfold.mechanism.path.trace_path`):
numerical continuation of the rigid-folding constraints (every edge length, every fixed
crease's fold angle, a support triangle held still) from the design until every fold angle
is within ``path_flat_tol`` of 0. For a 1-DOF mechanism it is the mechanism's own path, for
more DOF the one closest to the straight line in fold angles. No single crease has to fold
monotonically. The motion keeps ``settings.deformation.motion_frames`` shapes of the traced path at
equal steps of arclength (:meth:`rigidfold.mechanism.path.FoldingPath.frames`), the
development diagram (Step 8) at z = 0 as its flat end. The *support panel* (the panel,
triangles joined by fixed creases, of the support triangle) holds still: every folded frame
is turned and moved as a rigid body so that the panel's vertices lie where they lie in the
development, and the rest of the sheet folds up around it. ``max_length_error`` is the
largest relative edge-length error over all frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.frame.model import default_support_face
from rigidfold.mechanism.path import FoldingPath, PathStatus, trace_path
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import best_fit, edge_lengths
from rigidfold.outcomes import Outcome


class MotionStatus(Outcome):
    """How the folding motion was traced."""

    OK = "ok", "the motion is traced from the plane to the designed shape"
    FAILED = "failed", "no rigid-folding path to the plane was found"
    CUT = "cut", "the run's time limit ended the trace before the plane"


@dataclass
class Motion:
    """Frames of the folding motion, flat first.

    frames : (K, V, 3) float64; traced (status OK): frames[0] is the development diagram at
        z = 0, frames[-1] the designed shape turned and moved as a rigid body, and the
        support panel's vertices keep their place in every frame. Not traced: the part that
        was traced, the designed shape last, in its own place.
    parameter : (K,) fraction of the traced path's arclength, 0 (flat) .. 1 (designed); NaN
        where the motion was not traced
    max_length_error : largest |l - l0| / l0 over all edges and frames
    status : MotionStatus; message (the detail) says how it was traced or why it failed
    support_faces : (k,) int, the triangles of the support panel (the panel, joined by fixed
        creases, of the support triangle), which holds still
    dof : int or None, the DOF the path tracer worked with
    turned_back : the shape's folding path returns to the design without reaching the plane
        (:attr:`rigidfold.mechanism.path.PathStatus.TURNED_BACK`)
    path : the traced path's figures (:meth:`rigidfold.mechanism.path.FoldingPath.to_dict`)
    """

    frames: np.ndarray
    parameter: np.ndarray
    max_length_error: float
    status: MotionStatus
    support_faces: np.ndarray
    message: str = ""
    dof: int | None = None
    turned_back: bool = False
    path: dict | None = None

    def support_vertices(self, pattern: CreasePattern) -> np.ndarray:
        """(n,) int, sorted: the vertices of the support panel of ``pattern`` (the shape the
        motion folds)."""
        return np.unique(pattern.faces[self.support_faces])

    def to_dict(self) -> dict:
        """JSON-serialisable figures of the motion (not its frames)."""
        return {
            "status": self.status.value,
            "message": self.message,
            "frames": len(self.frames),
            "max_length_error": self.max_length_error,
            "support_faces": self.support_faces.tolist(),
            "dof": self.dof,
            "turned_back": self.turned_back,
            "path": self.path,
        }


def folding_motion(
    pattern: CreasePattern,
    flat: np.ndarray,
    *,
    support_face: int | None = None,
    dof: int | None = None,
    path: FoldingPath | None = None,
    deadline: float | None = None,
    settings: Settings = DEFAULTS,
) -> Motion:
    """The folding motion of ``pattern`` down to its development ``flat`` (V, 2).

    ``path``: the shape's traced folding path where it is known (generation traces it for
    the deployability check), else it is traced here, with ``dof`` (the mechanism's, default
    the generic count) and ``support_face`` (default
    :func:`rigidfold.frame.model.default_support_face`). Returns up to
    ``settings.deformation.motion_frames`` frames from the plane to the designed shape, the
    support panel held still, when the path reaches the flat state; otherwise the part that was
    traced. ``deadline`` (a time of ``time.monotonic()``, a run's time limit): the trace here
    ends there; a motion it cuts says so (:attr:`MotionStatus.CUT`), not that the shape does
    not deploy.
    """
    if support_face is None:
        support_face = default_support_face(pattern)
    panel = np.flatnonzero(pattern.facets == pattern.facets[support_face])
    if path is None:
        path = trace_path(
            pattern, dof=dof, support_face=support_face, settings=settings, deadline=deadline
        )
    n = max(int(settings.deformation.motion_frames), 2)
    if path.deploys:
        folded, fraction = path.frames(pattern, n, support_face=support_face, settings=settings)
        folded, fraction = folded[1:], fraction[1:]  # the flat end: the development itself
        frames = _hold_support(folded, flat, np.unique(pattern.faces[panel]))
        parameter = np.concatenate([[0.0], fraction])
        status, message = MotionStatus.OK, path.message
    else:
        frames = path.frames(pattern, n, support_face=support_face, settings=settings)[0]
        parameter = np.full(len(frames), np.nan)
        status = MotionStatus.CUT if path.cut else MotionStatus.FAILED
        message = f"{path.status.message}: {path.message}"
    L0 = pattern.edge_lengths
    err = max(float(np.max(np.abs(edge_lengths(f, pattern.edges) - L0) / L0)) for f in frames)
    return Motion(
        frames,
        parameter,
        err,
        status,
        panel,
        message,
        dof=path.dof,
        turned_back=path.status is PathStatus.TURNED_BACK,
        path=path.to_dict(),
    )


def _hold_support(folded: np.ndarray, flat: np.ndarray, panel: np.ndarray) -> np.ndarray:
    """The development at z = 0, then ``folded`` (k, V, 3) (the flattest first, the design
    last), each turned and moved (a proper rotation and a translation) so that the support
    panel's vertices ``panel`` best fit theirs in the development ``flat`` (V, 2)."""
    target = np.column_stack([flat, np.zeros(len(flat))])
    return np.concatenate([target[None], best_fit(folded, target, panel)])
