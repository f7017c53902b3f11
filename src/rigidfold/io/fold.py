"""Reading and writing crease patterns as FOLD 1.2 files.

FOLD (https://github.com/edemaine/fold, ``doc/spec.md``) is the JSON exchange format of
origami software (Origami Simulator, Rabbit Ear, ...). rigidfold writes one triangulated
model per file: ``vertices_coords`` (3D, metres), ``faces_vertices`` (counter-clockwise seen
from +z), ``edges_vertices`` in the order of :attr:`CreasePattern.edges`, ``edges_assignment``
and ``edges_foldAngle`` (degrees, valley positive). Fixed crease lines are joins, ``"J"``.
Custom data live under keys prefixed ``rigidfold:``.

The reader accepts FOLD files from other tools too: 2D coordinates (the flat state), polygon
faces (triangulated by :mod:`rigidfold.mesh.triangulate`, the added diagonals become ``"J"``
joins), missing edges (derived from the faces) and frames. Every length inside rigidfold is
metres: coordinates in another ``frame_unit`` (:data:`UNITS`) are converted on reading, and a
file drawn y-up (Blender, Origami Simulator) is turned z-up with ``up="y"``. Every problem
with the input is a one-line ``ValueError`` that names the file.

rigidfold writes its own models from scratch (:func:`fold_dict`, :func:`write_fold`); a shape
read from a file goes back as that file's document, kept whole, plus rigidfold's frames and
keys (:func:`round_trip_dict`, :func:`write_document`).
"""

from __future__ import annotations

import json
import math
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.files import atomic_write, check_json_depth, jsonable, parse_json
from rigidfold.mesh import CreasePattern, geometry, topology
from rigidfold.mesh.triangulate import orient_up, triangulate_polygons

FOLD_SPEC = 1.2
"""The FOLD version rigidfold writes."""

PREFIX = "rigidfold:"
"""Namespace of rigidfold's own keys in FOLD files."""

ASSIGNMENTS = frozenset("BMVFUCJ")
"""Edge assignments of FOLD 1.2: boundary, mountain, valley, flat, unassigned, cut, join."""

UNITS = {
    "unit": 1.0,
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "nm": 1e-9,
    "in": 0.0254,
    "pt": 0.0254 / 72,
}
"""Metres per unit of each ``frame_unit`` of FOLD 1.2. ``"unit"`` (no physical unit, the
default when a file gives none) is read as metres."""

UP_AXES = ("z", "y")
"""The up axes a FOLD file can be read with (``read_fold(up=...)``, ``--up``)."""


@dataclass(frozen=True, eq=False)
class FoldData:
    """A FOLD file read into a crease pattern.

    Attributes
    ----------
    pattern : CreasePattern
        The triangulated model. Its first ``n_file_edges`` edges are the file's
        ``edges_vertices`` in file order (so file edge indices are pattern edge indices);
        then come the diagonals added to triangulate polygon faces (``"J"``), then the edges
        derived from faces that the file does not list.
    n_file_edges : int
        Number of edges listed in the file's ``edges_vertices``.
    assignment : list of str, length E
        FOLD assignment of every pattern edge, as read or derived (``"B"`` for derived
        boundary edges, ``"U"`` for derived creases, ``"J"`` for added diagonals).
    metadata : dict
        The ``rigidfold:`` keys of the frame, prefix stripped.
    raw : dict
        The whole FOLD document as parsed from JSON.
    frame_classes : list of str
        The frame's ``frame_classes`` (e.g. ``["foldedForm"]``), empty when absent.
    unit : str
        The frame's ``frame_unit``, ``"unit"`` when the file gives none.
    scale : float
        Metres per file unit (:data:`UNITS`): the pattern's coordinates are the file's times
        this (then turned, for a y-up file).
    up : str
        The file's up axis: ``"z"``, or ``"y"`` for a file read y-up, whose (x, y, z) became
        (x, -z, y) so that its +y is rigidfold's +z (a rotation: right-handed still).
    """

    pattern: CreasePattern
    n_file_edges: int
    assignment: list[str]
    metadata: dict
    raw: dict = field(repr=False)
    frame_classes: list[str]
    unit: str
    scale: float
    up: str

    @property
    def unitless(self) -> bool:
        """True when the file gives no physical unit (its coordinates were read as metres)."""
        return self.unit == "unit"

    def shape_assignment(self) -> list[str]:
        """FOLD letter of every pattern edge for rigidfold's output frames (list of E str).

        The file's letter where it gives one (so a ``"M"`` or ``"V"`` crease of a flat
        crease pattern, folded 180 degrees in the file's intent, stays ``"M"`` or ``"V"``);
        an unassigned crease (``"U"``, in the file or derived from the faces) gets what the
        shape's fold angle says (:func:`edge_assignments`); added diagonals are ``"J"``.
        """
        measured = edge_assignments(self.pattern, self.pattern.settings.geometry.flat_angle)
        return [m if a == "U" else a for a, m in zip(self.assignment, measured, strict=True)]


# ---------------------------------------------------------------------------------- writing
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
        data = _inherited(every, k)
        unit = data.get("frame_unit", "unit")
        if not isinstance(unit, str) or unit not in UNITS:
            raise RigidfoldError(f"{at}: frame_unit {_short(unit)} is not a unit rigidfold knows")
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


def edge_assignments(
    pattern: CreasePattern, flat_angle: float = DEFAULTS.geometry.flat_angle
) -> list[str]:
    """FOLD assignment letter of each edge.  -> list of E str"""
    rho = pattern.fold_angles
    letters = np.where(rho > flat_angle, "V", np.where(rho < -flat_angle, "M", "F"))
    letters[pattern.fixed] = "J"
    letters[pattern.is_boundary_edge] = "B"
    return letters.tolist()


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


# ---------------------------------------------------------------------------------- reading
def read_fold(
    source: str | os.PathLike | dict,
    frame: int = 0,
    *,
    up: str = "z",
    rigid_panels: bool = True,
    settings: Settings = DEFAULTS,
) -> FoldData:
    """Read a FOLD file (or an already parsed FOLD dict) into a crease pattern, in metres.

    Parameters
    ----------
    source : str, path-like or dict
        FOLD file, or its parsed JSON.
    frame : int
        Frame to read: 0 is the top level, ``k >= 1`` is ``file_frames[k - 1]``, which
        inherits the keys it lacks from its ``frame_parent`` (default 0) when
        ``frame_inherit`` is true.
    up : str
        The file's up axis (:data:`UP_AXES`): ``"z"``, or ``"y"`` for a file drawn y-up
        (Blender, Origami Simulator), whose (x, y, z) becomes (x, -z, y).
    rigid_panels : bool
        True (a shape): every polygon face is a rigid planar panel, the diagonals added to
        triangulate it are fixed creases (``"J"``). False (a crease pattern to be lifted onto
        a surface): they are free creases (``"U"``).
    settings : Settings
        Tolerances: ``triangulation_area_tol`` for polygon faces, ``plan_area_tol`` for the
        plan, and those of the pattern (:attr:`CreasePattern.settings`: ``degenerate_area``,
        ``corner_angle``).

    Returns
    -------
    FoldData
        The triangulated pattern and what the file says about it. Coordinates are converted
        from the frame's ``frame_unit`` (:data:`UNITS`; none or ``"unit"``: read as metres,
        :attr:`FoldData.unitless`) to metres; 2D coordinates get z = 0; polygon faces are
        triangulated in their best-fit plane (:mod:`rigidfold.mesh.triangulate`: earcut,
        then constrained Delaunay), each diagonal an added edge (see
        ``rigid_panels``); edges that the file omits are derived from the faces. If the faces
        are consistently oriented but clockwise seen from +z in total, all are reversed. Edges
        assigned ``"J"`` or marked true in ``edges_rigidfold:fixed`` (a list of booleans, one
        per file edge) are fixed creases, all other interior edges free creases.

    Raises
    ------
    ValueError
        One line naming the file and the problem: unreadable file, invalid JSON, JSON nested
        deeper than ``settings.limits.max_json_depth`` (checked at its default), missing or
        malformed keys, an unknown ``frame_unit``, non-finite coordinates, 2D and 3D vertices
        mixed, a coordinate beyond ``settings.limits.max_coordinate`` metres, indices out of
        range, cut edges (``"C"``), a boundary edge assigned ``"J"`` or marked fixed, faces
        whose projection onto the xy plane has zero area (a y-up file, a closed or
        flat-folded sheet), a surface that is not an oriented disc.
    """
    if up not in UP_AXES:
        raise RigidfoldError(f"up must be one of {', '.join(UP_AXES)}, got {up!r}")
    label, raw = _load(source)
    try:
        return _parse(raw, frame, up, rigid_panels, settings)
    except ValueError as exc:
        raise RigidfoldError(f"{label}: {' '.join(str(exc).split())}") from None


def pattern_from_fold(
    source: str | os.PathLike | dict,
    frame: int = 0,
    *,
    up: str = "z",
    settings: Settings = DEFAULTS,
) -> CreasePattern:
    """The crease pattern of a FOLD file; see :func:`read_fold`."""
    return read_fold(source, frame, up=up, settings=settings).pattern


def _load(source) -> tuple[str, dict]:
    """(label for messages, parsed FOLD document) of a path or dict."""
    if isinstance(source, dict):
        try:
            check_json_depth(source)
        except ValueError as exc:
            raise RigidfoldError(f"FOLD data: {exc}") from None
        return "FOLD data", source
    if not isinstance(source, str | os.PathLike):
        raise RigidfoldError(f"read_fold needs a file path or a dict, got {type(source).__name__}")
    path = Path(source)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise RigidfoldError(f"cannot read {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise RigidfoldError(f"not a FOLD file: {path}: not UTF-8 text") from None
    try:
        raw = parse_json(text)
    except json.JSONDecodeError as exc:
        raise RigidfoldError(
            f"not a FOLD file: {path}: invalid JSON at line {exc.lineno} column {exc.colno}"
        ) from None
    except ValueError as exc:
        raise RigidfoldError(f"not a FOLD file: {path}: {exc}") from None
    if not isinstance(raw, dict):
        raise RigidfoldError(
            f"not a FOLD file: {path}: the top level is {_kind(raw)}, not a JSON object"
        )
    return str(path), raw


def _parse(raw: dict, frame: int, up: str, rigid_panels: bool, settings: Settings) -> FoldData:
    data = _frame(raw, frame)
    unit = data.get("frame_unit", "unit")
    if not isinstance(unit, str) or unit not in UNITS:
        raise RigidfoldError(
            f"frame_unit {_short(unit)} is not a unit rigidfold knows; use one of "
            f"{', '.join(UNITS)}"
        )
    coords = _coords(data) * UNITS[unit]
    far = np.abs(coords).max(axis=1, initial=0.0) > settings.limits.max_coordinate
    if far.any():
        i = int(np.argmax(far))
        raise RigidfoldError(
            f"vertices_coords[{i}] = {_short(data['vertices_coords'][i])} lies farther than "
            f"{settings.limits.max_coordinate:g} m from the origin (Settings.limits.max_coordinate)"
        )
    if up == "y":
        coords = geometry.from_y_up(coords)
    polygons = _polygons(data, len(coords))
    file_edges, file_assignment = _file_edges(data, len(coords))
    file_assignment = _mark_fixed(data, file_edges, file_assignment)
    triangles, diagonals = triangulate_polygons(
        coords, polygons, area_tol=settings.geometry.triangulation_area_tol, name="faces_vertices"
    )
    triangles = orient_up(coords, triangles)
    _check_plan(coords, triangles, up, settings.geometry.plan_area_tol)
    edges, assignment = _complete_edges(
        file_edges, file_assignment, diagonals, "J" if rigid_panels else "U", triangles, len(coords)
    )
    fixed = np.array([a == "J" for a in assignment], dtype=bool)
    pattern = CreasePattern(
        coords=coords, faces=triangles, edges=edges, fixed=fixed, settings=settings
    )
    classes = data.get("frame_classes", [])
    if not isinstance(classes, list) or not all(isinstance(c, str) for c in classes):
        raise RigidfoldError(f"frame_classes must be a list of strings, got {_short(classes)}")
    return FoldData(
        pattern=pattern,
        n_file_edges=len(file_edges),
        assignment=assignment,
        metadata={
            k[len(PREFIX) :]: v
            for k, v in data.items()
            if isinstance(k, str) and k.startswith(PREFIX)
        },
        raw=raw,
        frame_classes=list(classes),
        unit=unit,
        scale=UNITS[unit],
        up=up,
    )


def _check_plan(coords: np.ndarray, triangles: np.ndarray, up: str, tol: float) -> None:
    """ValueError when the triangles' projection onto the xy plane has (near) zero area:
    a y-up file, a vertical sheet, a closed box or a flat-folded state, which reversing the
    faces would not mend (:class:`CreasePattern` checks the sign)."""
    if not geometry.plan_area(coords, triangles, tol)[2]:
        return
    if up == "z":
        raise RigidfoldError(
            "the faces' projection onto the xy plane has zero area: rigidfold needs z up and "
            "a sheet that covers an area in plan (not closed, not folded flat); is the file "
            "y-up? (--up y)"
        )
    raise RigidfoldError(
        "read y-up, the faces' projection onto the file's xz plane has zero area: rigidfold "
        "needs the file's y axis up and a sheet that covers an area in plan (not closed, not "
        "folded flat); is the file z-up? (--up z)"
    )


def _frame(raw: dict, index: int) -> dict:
    """The keys of frame ``index`` (0 = top level), inherited keys included."""
    if not (_is_integer(index) and index >= 0):
        raise RigidfoldError(f"frame must be a non-negative integer, got {index!r}")
    frames = raw.get("file_frames", [])
    if not isinstance(frames, list) or not all(isinstance(f, dict) for f in frames):
        raise RigidfoldError("file_frames must be a list of objects")
    frames = [raw, *frames]
    if index >= len(frames):
        raise RigidfoldError(f"frame {index} does not exist (frames 0..{len(frames) - 1})")
    return _inherited(frames, index)


def _inherited(frames: list[dict], index: int) -> dict:
    """The keys of ``frames[index]`` (``frames[0]``: the top level) with those it inherits."""
    chain = [index]
    data = dict(frames[index])
    while chain[-1] != 0 and frames[chain[-1]].get("frame_inherit") is True:
        parent = frames[chain[-1]].get("frame_parent", 0)
        if not (_is_integer(parent) and 0 <= parent < len(frames)):
            raise RigidfoldError(f"frame {chain[-1]} has an invalid frame_parent {_short(parent)}")
        if parent in chain:
            raise RigidfoldError(f"frames {chain} inherit from each other in a cycle")
        chain.append(parent)
        data = {**frames[parent], **data}
    return data


def _coords(data: dict) -> np.ndarray:
    """``vertices_coords`` as a (V, 3) float array, z = 0 for 2D points (all 2D or all 3D)."""
    rows = _required_list(data, "vertices_coords")
    coords = np.zeros((len(rows), 3))
    for i, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) in (2, 3) and all(map(_is_number, row))):
            raise RigidfoldError(f"vertices_coords[{i}] must be 2 or 3 numbers, got {_short(row)}")
        try:
            coords[i, : len(row)] = row
        except OverflowError:  # an integer too large for a float
            coords[i] = math.inf
        if not np.isfinite(coords[i]).all():
            raise RigidfoldError(f"vertices_coords[{i}] is not finite: {_short(row)}")
        if len(row) != len(rows[0]):
            raise RigidfoldError(
                f"vertices_coords[{i}] has {len(row)} coordinates, vertices_coords[0] has "
                f"{len(rows[0])}: a file's vertices are all 2D or all 3D, got {_short(row)}"
            )
    return coords


def _polygons(data: dict, n_vertices: int) -> list[list[int]]:
    """``faces_vertices``, checked: each face >= 3 distinct vertex indices in range."""
    rows = _required_list(data, "faces_vertices")
    for k, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) >= 3 and all(map(_is_integer, row))):
            raise RigidfoldError(
                f"faces_vertices[{k}] must be a list of at least 3 vertex indices, "
                f"got {_short(row)}"
            )
        _check_range(row, n_vertices, f"faces_vertices[{k}]")
        if len(set(row)) != len(row):
            raise RigidfoldError(f"faces_vertices[{k}] repeats a vertex: {_short(row)}")
    return [[int(v) for v in row] for row in rows]


def _file_edges(data: dict, n_vertices: int) -> tuple[list[tuple[int, int]], list[str] | None]:
    """``edges_vertices`` (checked) and ``edges_assignment`` (None when absent)."""
    rows = data.get("edges_vertices", [])
    if not isinstance(rows, list):
        raise RigidfoldError(f"edges_vertices must be a list, got {_kind(rows)}")
    for k, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) == 2 and all(map(_is_integer, row))):
            raise RigidfoldError(f"edges_vertices[{k}] must be 2 vertex indices, got {_short(row)}")
        _check_range(row, n_vertices, f"edges_vertices[{k}]")
    edges = [(int(u), int(v)) for u, v in rows]
    if "edges_assignment" not in data:
        return edges, None
    assignment = data["edges_assignment"]
    if not isinstance(assignment, list) or len(assignment) != len(edges):
        raise RigidfoldError(
            f"edges_assignment must be a list of {len(edges)} letters (one per edge in "
            f"edges_vertices), got {_kind(assignment)}"
        )
    for k, letter in enumerate(assignment):
        if not isinstance(letter, str) or letter not in ASSIGNMENTS:
            raise RigidfoldError(
                f"edges_assignment[{k}] is {_short(letter)}, not one of B M V F U C J"
            )
        if letter == "C":
            raise RigidfoldError(
                f'edge {k} is a cut ("C"): rigidfold handles crease patterns without cuts only'
            )
    return edges, list(assignment)


def _mark_fixed(
    data: dict, file_edges: list[tuple[int, int]], assignment: list[str] | None
) -> list[str] | None:
    """The file's assignment with the edges marked in ``edges_rigidfold:fixed`` made ``"J"``
    (the others of a file without assignments are ``""``, derived by :func:`_complete_edges`)."""
    key = f"edges_{PREFIX}fixed"
    if key not in data:
        return assignment
    marks = data[key]
    if not (
        isinstance(marks, list)
        and len(marks) == len(file_edges)
        and all(isinstance(m, bool) for m in marks)
    ):
        raise RigidfoldError(
            f"{key} must be a list of {len(file_edges)} booleans (one per edge in "
            f"edges_vertices), got {_kind(marks)}"
        )
    letters = list(assignment) if assignment is not None else [""] * len(file_edges)
    return ["J" if m else a for m, a in zip(marks, letters, strict=True)]


def _complete_edges(
    file_edges: list[tuple[int, int]],
    file_assignment: list[str] | None,
    diagonals: list[tuple[int, int]],
    diagonal_letter: str,
    triangles: np.ndarray,
    n_vertices: int,
) -> tuple[np.ndarray, list[str]]:
    """Edges (E, 2) and their assignments: file edges, then diagonals, then derived edges.

    Edges derived from the triangles, and file edges without an assignment, are ``"B"`` when
    one triangle uses them and ``"U"`` otherwise; diagonals are ``diagonal_letter``. Raises
    ValueError for a boundary edge assigned ``"J"``.
    """

    def key(u: int, v: int) -> int:
        return min(u, v) * n_vertices + max(u, v)

    side_keys, uses = np.unique(
        topology.edge_keys(topology.half_edges(triangles), n_vertices), return_counts=True
    )
    boundary = set(side_keys[uses == 1].tolist())

    def derived(u: int, v: int) -> str:
        return "B" if key(u, v) in boundary else "U"

    letters = file_assignment or [""] * len(file_edges)
    assignment = [a or derived(u, v) for a, (u, v) in zip(letters, file_edges, strict=True)]
    for e, (u, v) in enumerate(file_edges):
        if assignment[e] == "J" and key(u, v) in boundary:
            raise RigidfoldError(
                f'edge {e} is a fixed crease ("J" or {PREFIX}fixed) but lies on the boundary'
            )
    edges = list(file_edges)
    known = {key(u, v) for u, v in edges}
    candidates = [(u, v, diagonal_letter) for u, v in diagonals]
    candidates += [(u, v, derived(u, v)) for u, v in topology.edges_from_faces(triangles).tolist()]
    for u, v, letter in candidates:
        if key(u, v) not in known:
            known.add(key(u, v))
            edges.append((u, v))
            assignment.append(letter)
    return np.asarray(edges, dtype=np.int64).reshape(-1, 2), assignment


# ---------------------------------------------------------------------------------- helpers
def _required_list(data: dict, key: str) -> list:
    if key not in data:
        raise RigidfoldError(f"missing {key}")
    value = data[key]
    if not isinstance(value, list) or not value:
        raise RigidfoldError(f"{key} must be a non-empty list, got {_kind(value)}")
    return value


def _check_range(indices: list, n_vertices: int, where: str) -> None:
    for v in indices:
        if not 0 <= v < n_vertices:
            raise RigidfoldError(
                f"{where} refers to vertex {v}, but there are {n_vertices} vertices"
            )


def _is_number(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def _is_integer(x) -> bool:
    return isinstance(x, numbers.Integral) and not isinstance(x, bool)


def _kind(value) -> str:
    """Short description of a JSON value for messages, e.g. 'an array of 3 items'."""
    if isinstance(value, list):
        return f"an array of {len(value)} items"
    if isinstance(value, dict):
        return "an object"
    return _short(value)


def _short(value, limit: int = 60) -> str:
    """repr of a value for messages, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
