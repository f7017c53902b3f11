"""Writing crease patterns as FOLD 1.2 files.

rigidfold writes its own models from scratch (:func:`fold_dict`, :func:`write_fold`): one
triangulated model per file, in metres, with the format's keys of
:mod:`rigidfold.io.fold` and rigidfold's own under ``rigidfold:``; a shape read from a file
goes back as that file's document, kept whole, plus rigidfold's frames and keys
(:func:`round_trip_dict`, :func:`write_document`).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.files import atomic_write, jsonable
from rigidfold.io.fold import FOLD_SPEC, PREFIX, FoldData, edge_assignments
from rigidfold.io.fold_frames import motion_frames
from rigidfold.mesh import CreasePattern


def fold_dict(
    pattern: CreasePattern,
    *,
    title: str = "",
    frame_class: str = "foldedForm",
    metadata: dict | None = None,
    creator: str = "rigidfold",
    settings: Settings = DEFAULTS,
    frames: list[dict] | None = None,
) -> dict:
    """The FOLD 1.2 document of a crease pattern.

    Parameters
    ----------
    pattern : CreasePattern
        The model; coordinates (V, 3), faces (F, 3), edges (E, 2) are written as they are.
    title : str
        ``frame_title``.
    frame_class : str
        The single entry of ``frame_classes``, e.g. ``"foldedForm"`` or ``"creasePattern"``.
    metadata : dict, optional
        Extra data with string keys; each item is stored as ``"rigidfold:<key>"``, cleaned by
        :func:`rigidfold.io.jsonable` (NumPy values become JSON numbers and lists, non-finite
        floats ``null``; anything that is not JSON data is a ValueError naming the key).
    creator : str
        ``file_creator``.
    settings : Settings
        ``settings.geometry.flat_angle`` decides which free creases are flat (``"F"``).
    frames : list of dict, optional
        Further frames (``file_frames``), e.g. from :func:`crease_pattern_frame`.

    Returns
    -------
    dict
        JSON-serialisable FOLD document. Edge assignments: ``"B"`` boundary, ``"J"`` fixed
        crease, and free creases ``"V"`` (fold angle > flat_angle), ``"M"`` (< -flat_angle)
        or ``"F"``. ``edges_foldAngle`` (E,) is the signed fold angle in degrees for every
        edge, fixed creases included, 0 on the boundary.
    """
    data = {
        "file_spec": FOLD_SPEC,
        "file_creator": creator,
        "file_classes": ["singleModel"],
        "frame_classes": [frame_class],
        "frame_title": title,
        **_model_keys(pattern, edge_assignments(pattern, settings.geometry.flat_angle)),
        **_prefixed(metadata),
    }
    if frames:
        data["file_frames"] = frames
    return data


def round_trip_dict(
    source: FoldData,
    coords2d: np.ndarray,
    *,
    motion: tuple[np.ndarray, np.ndarray] | None = None,
    title: str = "folded form",
    metadata: dict | None = None,
) -> dict:
    """The FOLD document a shape was read from, kept whole, plus rigidfold's frames and keys.

    Every key and frame of the input stays as it is: its ``file_*`` keys, ``file_frames``,
    polygons, ``edges_assignment``, ``edges_foldAngle``, ``faceOrders``, custom namespaces, all
    in the input's own unit and orientation (only a non-finite number, which JSON cannot hold,
    becomes ``null``). rigidfold adds:

    * ``"rigidfold:<key>"`` at the top level for each ``metadata`` item (as in
      :func:`fold_dict`), replacing any of an earlier run, and ``"rigidfold:input"``: the
      file's unit, metres per unit and up axis as read;
    * after the input's frames, its own, each with ``frame_unit: "m"`` (given or inherited,
      so that a reader that follows ``frame_inherit`` gets metres), z up, titled
      ``"rigidfold: ..."``:

      1. the development diagram (``creasePattern``, ``frame_parent`` 0, not inheriting):
         rigidfold's triangulated model, self-contained. ``vertices_coords`` (V, 2) the
         development, ``faces_vertices`` (F, 3) counter-clockwise, ``edges_vertices``
         (E, 2) (the file's edges first, in file order, then added diagonals and derived
         edges: the pattern's edge indices), ``edges_assignment``
         (:meth:`FoldData.shape_assignment`: the file's letters kept, never a folded
         ``"M"``/``"V"`` turned ``"F"``) and ``edges_foldAngle`` (the shape's fold angles,
         degrees);
      2. the folding motion, ``motion = (frames (K, V, 3), parameter (K,))`` when given, as
         :func:`motion_frames` inheriting from 1;
      3. the folded form (``foldedForm``, inheriting from 1): ``vertices_coords`` (V, 3) of
         the shape checked, in metres, z up.

    Parameters
    ----------
    source : FoldData
        The file read (:func:`read_fold`, frame 0); its pattern is the shape.
    coords2d : (V, 2) float
        The development diagram (metres).
    motion : ((K, V, 3) float, (K,) float), optional
        The folding motion's vertex positions and fraction folded.
    title : str
        What the folded-form frame is, after ``"rigidfold: "``.
    metadata : dict, optional
        rigidfold's figures; see :func:`fold_dict`.
    """
    pattern = source.pattern
    first = 1 + len(source.raw.get("file_frames", []))
    diagram = {
        "frame_title": "rigidfold: development diagram",
        "frame_classes": ["creasePattern"],
        "frame_parent": 0,
        "frame_inherit": False,
        **_model_keys(pattern, source.shape_assignment()),
        "vertices_coords": np.asarray(coords2d, dtype=float).tolist(),
    }
    moving = (
        []
        if motion is None
        else motion_frames(pattern, *motion, parent=first, assignment=source.shape_assignment())
    )
    folded = {
        "frame_title": f"rigidfold: {title}",
        "frame_classes": ["foldedForm"],
        "frame_parent": first,
        "frame_inherit": True,
        "vertices_coords": pattern.coords.tolist(),
    }
    for frame in moving:
        frame["frame_title"] = f"rigidfold: {frame['frame_title']}"
    read = {"unit": source.unit, "metres_per_unit": source.scale, "up": source.up}
    kept = jsonable(source.raw, where="the FOLD document read")
    return {
        **kept,
        **_prefixed({**(metadata or {}), "input": read}),
        "file_frames": [*kept.get("file_frames", []), diagram, *moving, folded],
    }


def write_fold(path: str | os.PathLike, pattern: CreasePattern, **kwargs) -> Path:
    """Write a crease pattern as a FOLD file, atomically (:func:`rigidfold.io.atomic_write`).

    Tables are written one row per line.

    Parameters
    ----------
    path : str or path-like
        Destination file.
    pattern : CreasePattern
        The model.
    **kwargs
        Keyword arguments of :func:`fold_dict` (title, frame_class, metadata, creator,
        settings).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        ``"cannot write '<path>': <reason>"`` when the file cannot be written.
    """
    return write_document(path, fold_dict(pattern, **kwargs))


def write_document(path: str | os.PathLike, document: dict) -> Path:
    """Write a FOLD document (JSON data, e.g. from :func:`round_trip_dict`) atomically, one
    top-level key per line and tables one row per line. Returns ``path``; ValueError
    ``"cannot write '<path>': <reason>"`` when the file cannot be written."""
    return atomic_write(path, _dumps(document))


def _model_keys(pattern: CreasePattern, assignment: list[str]) -> dict:
    """The FOLD keys of a pattern's geometry and topology, in metres (``frame_unit: "m"``):
    coordinates (V, 3), faces (F, 3), edges (E, 2), ``assignment`` (E letters) and the fold
    angles in degrees (E,)."""
    return {
        "frame_unit": "m",
        "vertices_coords": pattern.coords.tolist(),
        "faces_vertices": pattern.faces.tolist(),
        "edges_vertices": pattern.edges.tolist(),
        "edges_assignment": assignment,
        "edges_foldAngle": np.degrees(pattern.fold_angles).tolist(),
    }


def _prefixed(metadata: dict | None) -> dict:
    """``{"rigidfold:<key>": jsonable(value)}`` of string-keyed metadata."""
    keys = {}
    for key, value in (metadata or {}).items():
        if not isinstance(key, str):
            raise RigidfoldError(f"metadata keys must be strings, got {key!r}")
        keys[PREFIX + key] = jsonable(value, where=f"metadata {key!r}")
    return keys


def _dumps(data: dict) -> str:
    """JSON text: one top-level key per line, tables (lists of lists) one row per line."""
    items = []
    for key, value in data.items():
        if isinstance(value, list) and value and all(isinstance(row, list) for row in value):
            rows = ",\n  ".join(json.dumps(row, allow_nan=False) for row in value)
            text = f"[\n  {rows}\n ]"
        else:
            text = json.dumps(value, allow_nan=False)
        items.append(f" {json.dumps(key)}: {text}")
    return "{\n" + ",\n".join(items) + "\n}\n"
