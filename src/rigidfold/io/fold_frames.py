"""rigidfold's frames of a design's FOLD file: the development diagram and the folding motion.

A design's file (:mod:`rigidfold.io.fold_write`) carries, after its folded form, a
``creasePattern`` frame with the development diagram (Step 8) and ``foldedForm`` frames of
its folding motion from flat to folded, each with its fraction folded
(:data:`FRACTION_KEY`); :func:`read_frames` is the one reader of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.io.fold import UNITS, edge_assignments, inherited_frame, short_text
from rigidfold.mesh import CreasePattern


def crease_pattern_frame(coords2d: np.ndarray, *, title: str = "development diagram") -> dict:
    """A FOLD frame with the 2D development diagram, inheriting topology from frame 0.

    coords2d : (V, 2) float, vertex positions of the flattened sheet (metres).
    """
    return {
        "frame_title": title,
        "frame_classes": ["creasePattern"],
        "frame_parent": 0,
        "frame_inherit": True,
        "vertices_coords": np.asarray(coords2d, dtype=float).tolist(),
    }


def motion_frames(
    pattern: CreasePattern,
    frames: np.ndarray,
    parameter: np.ndarray,
    *,
    parent: int = 0,
    assignment: list[str] | None = None,
) -> list[dict]:
    """FOLD frames of a folding motion, inheriting topology from frame ``parent``.

    pattern : the folded design (its faces, edges and the crease letters of the motion);
    frames : (K, V, 3) float, vertex positions from flat to folded, written as given
    (:func:`rigidfold.deform.folding_motion` holds the support panel still and the figures
    of the motion, ``rigidfold:motion``, name its triangles); parameter : (K,) fraction
    folded; assignment : E letters every frame carries (default :func:`edge_assignments` of
    the design, so that a crease still flat in a frame keeps its mountain or valley letter).
    Each frame is a "foldedForm" titled with its fraction, with its own ``edges_foldAngle``
    (E,) in degrees, measured on that frame, and ``edges_assignment``: a viewer that follows
    ``frame_inherit`` does not take the folded design's angles for the flat frame's.
    """
    letters = edge_assignments(pattern) if assignment is None else list(assignment)
    return [
        {
            "frame_title": f"folding motion: {100 * float(s):.0f}% folded",
            "frame_classes": ["foldedForm"],
            "frame_parent": parent,
            "frame_inherit": True,
            "vertices_coords": np.asarray(x, dtype=float).tolist(),
            "edges_assignment": letters,
            "edges_foldAngle": np.degrees(pattern.with_coords(x).fold_angles).tolist(),
            FRACTION_KEY: float(s),
        }
        for x, s in zip(frames, parameter, strict=True)
    ]


FRACTION_KEY = "rigidfold:fraction"
"""The key of a motion frame (:func:`motion_frames`) that holds its fraction folded, 0 (flat)
to 1 (the design)."""


@dataclass(frozen=True, eq=False)
class DesignFrames:
    """rigidfold's frames of a design's FOLD file, read back (the contract of
    :func:`crease_pattern_frame` and :func:`motion_frames`).

    diagram : (V, 2) float64 development diagram of the last ``creasePattern`` frame, or
    None; diagram_frame : its frame number (``k >= 1`` is ``file_frames[k - 1]``), or None;
    motion : (K, V, 3) float64 ``foldedForm`` frames from flat to the design (those that
    carry :data:`FRACTION_KEY`, after the last ``creasePattern`` frame; frames of another
    writer, without it: every ``foldedForm`` frame), metres; fraction : (K,) float64
    fraction folded of each (:data:`FRACTION_KEY`; frames of another writer: evenly spaced).
    """

    diagram: np.ndarray | None
    motion: np.ndarray
    fraction: np.ndarray
    diagram_frame: int | None = None


def crease_pattern_frames(raw: dict) -> list[int]:
    """The frame numbers (``k >= 1`` is ``file_frames[k - 1]``, as :func:`read_fold` counts)
    of the ``creasePattern`` frames of a FOLD document, last first."""
    frames = raw.get("file_frames") or []
    return [
        k
        for k in range(len(frames), 0, -1)
        if isinstance(frames[k - 1], dict)
        and isinstance(frames[k - 1].get("frame_classes"), list)
        and "creasePattern" in frames[k - 1]["frame_classes"]
    ]


def read_frames(raw: dict, n_vertices: int, where: str) -> DesignFrames:
    """The :class:`DesignFrames` of a FOLD document ``raw`` (parsed once: every frame is
    read from it, none re-parsed) whose model has ``n_vertices``: the one reader of a
    design's frames. Each frame's coordinates are converted from its ``frame_unit`` (its
    own or inherited, :data:`UNITS`) to metres and read z up, as rigidfold writes them.
    ValueError naming ``where`` and the frame for a frame of another vertex count, a unit
    rigidfold does not know, coordinates that are not finite numbers, or a
    ``creasePattern`` frame that is not flat."""
    frames = raw.get("file_frames") or []
    if not isinstance(frames, list) or not all(isinstance(f, dict) for f in frames):
        raise RigidfoldError(f"{where}: file_frames must be a list of objects")
    every = [raw, *frames]
    diagram, diagram_frame = None, None
    motion: list[tuple[int, np.ndarray, float]] = []
    for k, frame in enumerate(frames, start=1):
        classes = frame.get("frame_classes") or []
        if not isinstance(classes, list):
            continue
        kind = "creasePattern" if "creasePattern" in classes else None
        kind = kind or ("foldedForm" if "foldedForm" in classes else None)
        if kind is None:
            continue
        at = f"{where}: file_frames[{k - 1}]"
        data = inherited_frame(every, k)
        unit = data.get("frame_unit", "unit")
        if not isinstance(unit, str) or unit not in UNITS:
            raise RigidfoldError(
                f"{at}: frame_unit {short_text(unit)} is not a unit rigidfold knows"
            )
        coords = _frame_coords(data, n_vertices, 3, at) * UNITS[unit]
        if kind == "creasePattern":
            if np.abs(coords[:, 2]).max(initial=0.0) > 0:
                raise RigidfoldError(f"{at}: a creasePattern frame that is not flat (z != 0)")
            diagram, diagram_frame = coords[:, :2], k
            motion = []  # the motion follows the last diagram
        else:
            motion.append((k, coords, motion_fraction(frame)))
    keyed = [m for m in motion if not math.isnan(m[2])]
    if keyed:
        motion = keyed
    fraction = [m[2] for m in motion]
    if not keyed:  # frames of another writer: evenly spaced
        fraction = np.linspace(0.0, 1.0, len(motion)).tolist()
    return DesignFrames(
        diagram,
        np.asarray([m[1] for m in motion], dtype=float).reshape(-1, n_vertices, 3),
        np.asarray(fraction, dtype=float),
        diagram_frame,
    )


def motion_fraction(frame: dict) -> float:
    """A motion frame's fraction folded (:data:`FRACTION_KEY`); NaN when it has none."""
    value = frame.get(FRACTION_KEY)
    if isinstance(value, int | float) and not isinstance(value, bool) and 0 <= value <= 1:
        return float(value)
    return math.nan


def _frame_coords(frame: dict, n_vertices: int, dim: int, where: str) -> np.ndarray:
    """(V, dim) float64 ``vertices_coords`` of a frame (2D frames padded with z = 0 to 3D
    when ``dim`` is 3)."""
    try:
        xy = np.asarray(frame["vertices_coords"], dtype=float)
    except (KeyError, TypeError, ValueError, OverflowError):
        raise RigidfoldError(f"{where} has no numeric vertices_coords") from None
    if xy.ndim != 2 or xy.shape[0] != n_vertices or xy.shape[1] not in (2, 3):
        raise RigidfoldError(
            f"{where}: vertices_coords of shape {xy.shape}, expected ({n_vertices}, 2|3)"
        )
    if not np.isfinite(xy).all():
        raise RigidfoldError(f"{where}: non-finite vertices_coords")
    if dim == 3 and xy.shape[1] == 2:
        xy = np.column_stack([xy, np.zeros(n_vertices)])
    return xy[:, :dim]
