"""FOLD 1.2 crease patterns: the format's constants and the reader.

FOLD (https://github.com/edemaine/fold, ``doc/spec.md``) is the JSON exchange format of
origami software (Origami Simulator, Rabbit Ear, ...). rigidfold writes one triangulated
model per file (:mod:`rigidfold.io.fold_write`): ``vertices_coords`` (3D, metres),
``faces_vertices`` (counter-clockwise seen from +z), ``edges_vertices`` in the order of
:attr:`CreasePattern.edges`, ``edges_assignment`` and ``edges_foldAngle`` (degrees, valley
positive). Fixed crease lines are joins, ``"J"``. Custom data live under keys prefixed
``rigidfold:``; a design's development diagram and folding motion are frames
(:mod:`rigidfold.io.fold_frames`).

The reader (:func:`read_fold`) accepts FOLD files from other tools too: 2D coordinates (the
flat state), polygon faces (triangulated by :mod:`rigidfold.mesh.triangulate`, the added
diagonals become ``"J"`` joins), missing edges (derived from the faces) and frames. Every
length inside rigidfold is metres: coordinates in another ``frame_unit`` (:data:`UNITS`) are
converted on reading, and a file drawn y-up (Blender, Origami Simulator) is turned z-up with
``up="y"``. Every problem with the input is a one-line ``ValueError`` that names the file.
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
from rigidfold.io.files import check_json_depth, parse_json
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


def edge_assignments(
    pattern: CreasePattern, flat_angle: float = DEFAULTS.geometry.flat_angle
) -> list[str]:
    """FOLD assignment letter of each edge.  -> list of E str"""
    rho = pattern.fold_angles
    letters = np.where(rho > flat_angle, "V", np.where(rho < -flat_angle, "M", "F"))
    letters[pattern.fixed] = "J"
    letters[pattern.is_boundary_edge] = "B"
    return letters.tolist()


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
            f"frame_unit {short_text(unit)} is not a unit rigidfold knows; use one of "
            f"{', '.join(UNITS)}"
        )
    coords = _coords(data) * UNITS[unit]
    far = np.abs(coords).max(axis=1, initial=0.0) > settings.limits.max_coordinate
    if far.any():
        i = int(np.argmax(far))
        raise RigidfoldError(
            f"vertices_coords[{i}] = {short_text(data['vertices_coords'][i])} lies farther than "
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
        raise RigidfoldError(f"frame_classes must be a list of strings, got {short_text(classes)}")
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
    return inherited_frame(frames, index)


def inherited_frame(frames: list[dict], index: int) -> dict:
    """The keys of ``frames[index]`` (``frames[0]``: the top level) with those it inherits."""
    chain = [index]
    data = dict(frames[index])
    while chain[-1] != 0 and frames[chain[-1]].get("frame_inherit") is True:
        parent = frames[chain[-1]].get("frame_parent", 0)
        if not (_is_integer(parent) and 0 <= parent < len(frames)):
            raise RigidfoldError(
                f"frame {chain[-1]} has an invalid frame_parent {short_text(parent)}"
            )
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
            raise RigidfoldError(
                f"vertices_coords[{i}] must be 2 or 3 numbers, got {short_text(row)}"
            )
        try:
            coords[i, : len(row)] = row
        except OverflowError:  # an integer too large for a float
            coords[i] = math.inf
        if not np.isfinite(coords[i]).all():
            raise RigidfoldError(f"vertices_coords[{i}] is not finite: {short_text(row)}")
        if len(row) != len(rows[0]):
            raise RigidfoldError(
                f"vertices_coords[{i}] has {len(row)} coordinates, vertices_coords[0] has "
                f"{len(rows[0])}: a file's vertices are all 2D or all 3D, got {short_text(row)}"
            )
    return coords


def _polygons(data: dict, n_vertices: int) -> list[list[int]]:
    """``faces_vertices``, checked: each face >= 3 distinct vertex indices in range."""
    rows = _required_list(data, "faces_vertices")
    for k, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) >= 3 and all(map(_is_integer, row))):
            raise RigidfoldError(
                f"faces_vertices[{k}] must be a list of at least 3 vertex indices, "
                f"got {short_text(row)}"
            )
        _check_range(row, n_vertices, f"faces_vertices[{k}]")
        if len(set(row)) != len(row):
            raise RigidfoldError(f"faces_vertices[{k}] repeats a vertex: {short_text(row)}")
    return [[int(v) for v in row] for row in rows]


def _file_edges(data: dict, n_vertices: int) -> tuple[list[tuple[int, int]], list[str] | None]:
    """``edges_vertices`` (checked) and ``edges_assignment`` (None when absent)."""
    rows = data.get("edges_vertices", [])
    if not isinstance(rows, list):
        raise RigidfoldError(f"edges_vertices must be a list, got {_kind(rows)}")
    for k, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) == 2 and all(map(_is_integer, row))):
            raise RigidfoldError(
                f"edges_vertices[{k}] must be 2 vertex indices, got {short_text(row)}"
            )
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
                f"edges_assignment[{k}] is {short_text(letter)}, not one of B M V F U C J"
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
    return short_text(value)


def short_text(value, limit: int = 60) -> str:
    """repr of a value for messages, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
