"""The folding motion as rigid motions of the panels, from flat to the design.

The motion is a sequence of frames, vertex positions (K, V, 3) from the flat sheet
(fraction 0) to the design (fraction 1): the design file's own motion frames
(``foldedForm`` frames, as ``rigidfold generate`` writes them for a checked design, read
by :func:`rigidfold.io.read_frames`) when they are a rigid motion of the design from flat
(:func:`motion_evidence`: motion frames are evidence, checked, never trusted) and fine
enough, else the design's rigid-folding path
(:func:`rigidfold.mechanism.path.trace_path`) sampled at equal arclength
(:meth:`rigidfold.mechanism.path.FoldingPath.frames`) so finely that no hinge turns more
than ``settings.fabricate.frame_step`` between two frames. Each panel moves rigidly: at
frame i its points are ``R[i, k] @ x + t[i, k]`` for ``x`` in the design, ``R, t`` the
least-squares fit (Kabsch) of the panel's vertices in the design onto theirs in the frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.exports import Design
from rigidfold.fabricate import progress
from rigidfold.fabricate.panels import Panels
from rigidfold.io import read_frames
from rigidfold.mesh.geometry import rigid_motions

if TYPE_CHECKING:
    from rigidfold.mechanism.path import FoldingPath

MAX_FRAMES = 4000
"""Most frames a traced motion is sampled at (a motion that needs more is checked at these)."""


@dataclass(frozen=True, eq=False)
class PanelMotion:
    """Rigid motions of the panels along the folding motion, flat first.

    rotations : (K, P, 3, 3) float64 and translations : (K, P, 3) float64: panel k at frame
        i holds ``rotations[i, k] @ x + translations[i, k]`` for a point x of it in the design.
    fraction : (K,) float64, fraction folded of each frame: 0 flat .. 1 the design.
    closing : (K, H) float64, how far each hinge has folded towards the solids' side at each
        frame, radians (:meth:`rigidfold.fabricate.panels.Panels.closing`).
    source : where the frames come from, in words.
    """

    rotations: np.ndarray
    translations: np.ndarray
    fraction: np.ndarray
    closing: np.ndarray
    source: str

    @property
    def n_frames(self) -> int:
        return len(self.fraction)

    @property
    def largest_step(self) -> float:
        """Largest change of one hinge's fold angle between two frames, radians."""
        if self.n_frames < 2 or self.closing.shape[1] == 0:
            return 0.0
        return float(np.abs(np.diff(self.closing, axis=0)).max())

    @property
    def range(self) -> tuple[np.ndarray, np.ndarray]:
        """((H,), (H,)): the least and the largest closing fold angle of each hinge over the
        motion, the flat state (0) included, radians."""
        low = np.minimum(self.closing.min(axis=0, initial=0.0), 0.0)
        high = np.maximum(self.closing.max(axis=0, initial=0.0), 0.0)
        return low, high

    def to_dict(self) -> dict:
        return {
            "frames": self.n_frames,
            "source": self.source,
            "largest_step_deg": math.degrees(self.largest_step),
        }


def fit_panels(panels: Panels, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rotations (K, P, 3, 3), translations (K, P, 3)): each panel's rigid motion from the
    design onto each of ``frames`` (K, V, 3), by least squares over its vertices (Kabsch:
    :func:`rigidfold.mesh.geometry.rigid_motions`)."""
    return rigid_motions(panels.pattern.coords, frames, panels.vertices)


def closing_angles(panels: Panels, rotations: np.ndarray) -> np.ndarray:
    """(..., H) float64: the closing fold angle of each hinge for panel rotations
    (..., P, 3, 3), from the two panels' turned normals and the turned hinge direction
    (the fold angle of :func:`rigidfold.mesh.geometry.fold_angles`)."""
    p = panels.pattern
    left, right = panels.hinge_panels.T
    u, v = panels.hinge_vertices.T
    t0 = p.coords[v] - p.coords[u]
    t0 /= np.linalg.norm(t0, axis=1, keepdims=True)
    ra = rotations[..., left, :, :]
    rb = rotations[..., right, :, :]
    na = np.einsum("...hij,hj->...hi", ra, panels.normals[left])
    nb = np.einsum("...hij,hj->...hi", rb, panels.normals[right])
    t = np.einsum("...hij,hj->...hi", ra, t0)
    sin = -np.einsum("...i,...i->...", np.cross(na, nb), t)
    cos = np.einsum("...i,...i->...", na, nb)
    return panels.sign * np.arctan2(sin, cos)


def panel_motion(
    panels: Panels, frames: np.ndarray, fraction: np.ndarray, source: str
) -> PanelMotion:
    """The :class:`PanelMotion` of ``frames`` (K, V, 3), flat first, at ``fraction`` (K,)."""
    rotations, translations = fit_panels(panels, frames)
    closing = closing_angles(panels, rotations)
    return PanelMotion(
        rotations, translations, np.asarray(fraction, dtype=np.float64), closing, source
    )


def file_frames(design: Design) -> tuple[np.ndarray, np.ndarray] | None:
    """(frames (K, V, 3), fraction (K,)) of the folding motion the design file carries (its
    motion frames, :func:`rigidfold.io.read_frames`, read once with the file), or None when
    it has fewer than two. Not yet checked: :func:`motion_evidence` says whether they are
    a rigid motion of the design from flat."""
    frames = design.frames
    if frames is None:
        frames = read_frames(design.data.raw, design.pattern.n_vertices, "the design file")
    if len(frames.motion) < 2:
        return None
    return frames.motion, frames.fraction


def motion_evidence(
    panels: Panels, frames: np.ndarray, fraction: np.ndarray, *, settings: Settings = DEFAULTS
) -> str:
    """Why ``frames`` (K, V, 3), at ``fraction`` (K,), are not a rigid motion of ``panels``'
    design from flat, in words; ``""`` when they are: each panel moves rigidly (its
    vertices within ``settings.fabricate.frame_tol`` times the design's size of its
    least-squares rigid motion, so lengths are kept and panels stay flat), the first frame
    is flat (every hinge within ``settings.path.flat_tol`` of flat, as the traced path's
    flat end), the last one is the design (so moved rigidly onto it), and the fraction rises
    from 0 to 1."""
    pattern = panels.pattern
    size = float(np.linalg.norm(np.ptp(pattern.coords, axis=0))) or 1.0
    tol = settings.fabricate.frame_tol * size
    s = np.asarray(fraction, dtype=np.float64)
    if not (np.isclose(s[0], 0.0) and np.isclose(s[-1], 1.0) and np.all(np.diff(s) >= 0)):
        return "their fraction folded does not rise from 0 to 1"
    rotations, translations = fit_panels(panels, frames)
    worst, at = 0.0, 0
    for k, verts in enumerate(panels.vertices):
        moved = np.einsum("kij,vj->kvi", rotations[:, k], pattern.coords[verts])
        off = np.linalg.norm(moved + translations[:, k, None] - frames[:, verts], axis=2)
        if off.max() > worst:
            worst, at = float(off.max()), k
    if worst > tol:
        return f"panel {at} does not move rigidly (off by {worst * 1e3:.3g} mm)"
    first = np.abs(closing_angles(panels, rotations[0])).max(initial=0.0)
    if first > settings.path.flat_tol:
        return f"the first frame is not flat (a hinge folded {math.degrees(first):.3g} degrees)"
    whole = [np.arange(pattern.n_vertices)]
    r, t = rigid_motions(frames[-1], pattern.coords[None], whole)
    off = np.linalg.norm(frames[-1] @ r[0, 0].T + t[0, 0] - pattern.coords, axis=1).max()
    if off > tol:
        return f"the last frame is not the design (a vertex {off * 1e3:.3g} mm off)"
    return ""


def design_motion(
    panels: Panels,
    design: Design | None = None,
    *,
    frames: tuple[np.ndarray, np.ndarray] | None = None,
    path: FoldingPath | None = None,
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> tuple[PanelMotion | None, str]:
    """(motion, message): the folding motion of ``panels``' design (see the module's text),
    or (None, why) when it has no motion from flat: its file carries none fine enough and
    its folding path does not reach the flat state.

    frames : (frames (K, V, 3), fraction (K,)) of a motion already at hand (a run's traced
    motion), used instead of the design file's; path : the design's folding path already
    traced (:func:`rigidfold.mechanism.path.trace_path`), sampled instead of tracing it
    again when the frames are too coarse; up : how the design was read (its frames are read
    z up, as rigidfold writes them: frames of another up axis are not the design's motion,
    and the path is traced). Raises ValueError for a design of more than
    ``settings.limits.max_fabricate_panels`` panels."""
    del up  # the frames are evidence, checked against the design as read
    from rigidfold.mechanism.path import trace_path

    progress.check_size(panels.n, settings=settings)
    step = settings.fabricate.frame_step
    carried = frames
    where = "the traced motion's"
    rejected = ""
    if carried is None and design is not None:
        carried, where = file_frames(design), "the design file's"
        if carried is not None:
            why = motion_evidence(panels, *carried, settings=settings)
            if why:
                n = len(carried[0])
                rejected = f" (the design file's {n} frames are not its motion: {why})"
                carried = None
    if carried is not None:
        shapes, fraction = carried
        motion = panel_motion(panels, shapes, fraction, f"{where} {len(shapes)} frames")
        if motion.largest_step <= step:
            return motion, motion.source
    pattern = panels.pattern
    if path is None:
        text = f"tracing the folding path of {panels.n} panels{rejected}"
        progress.step(text, panels.n, settings=settings)
        path = trace_path(pattern, settings=settings)
    if not path.deploys:
        if carried is not None:
            return motion, f"{motion.source} (the path could not be traced finer: {path.message})"
        return None, f"{path.status.message}: {path.message}{rejected}"
    largest = float(np.abs(panels.closing(pattern.fold_angles)).max(initial=0.0))
    n = min(max(math.ceil(largest / step) + 1, 3), MAX_FRAMES)
    for _ in range(3):
        sampled, fraction = path.frames(pattern, n, settings=settings)
        motion = panel_motion(
            panels, sampled, fraction, f"the traced folding path at {n} frames{rejected}"
        )
        if motion.largest_step <= step or n >= MAX_FRAMES:
            break
        n = min(math.ceil((n - 1) * motion.largest_step / step) + 1, MAX_FRAMES)
    return motion, motion.source
