"""Pattern specs, typed: the paper's patterns by name (:class:`PaperPattern`), grids
(:class:`GridPattern`), footprint meshes (:class:`MeshPattern`) and FOLD or SVG files
(:class:`FilePattern`), and the plan each makes (:func:`make_plan`).

The command line's texts (``1``, ``grid:NXxNY``, ``mesh:POLYGON``, ``FILE.fold``) are read
into them by :mod:`rigidfold.generate.specs`; here the values are only checked for their
types, and each spec's ``text`` gives the option back. Every plan is placed with the
lower-left corner of its bounding box at (0, 0), the frame in which the target surfaces are
given (``rigidfold.surfaces``).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypedDict, Unpack

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.patterns.files import read_pattern_file
from rigidfold.patterns.footprint import (
    check_footprint,
    default_edge_length,
    footprint_mesh,
    read_footprint,
)
from rigidfold.patterns.grids import (
    DEFAULT_SIZE,
    DIAGONALS,
    check_extent,
    grid,
    grid11,
    pattern1,
    pattern1p,
    pattern2,
)

PATTERNS: dict[str, Callable[[], tuple[np.ndarray, np.ndarray]]] = {
    "1": pattern1,
    "1p": pattern1p,
    "2": pattern2,
    "11": grid11,
}
"""The paper's patterns: name -> function returning plan vertices (V, 2) and triangles (F, 3)."""

FORMS = f"{', '.join(PATTERNS)}, grid:NXxNY, mesh:POLYGON, FILE.fold or FILE.svg"
"""The forms of a pattern spec, for messages and help texts."""


def _text(spec: object, text: str) -> None:
    """Set a spec's ``text`` (the form the command line takes) where none was given."""
    if not isinstance(text, str):
        raise TypeError(f"a pattern spec's text is a str, got {type(text).__name__}")
    if not text:
        object.__setattr__(spec, "text", str(spec))


@dataclass(frozen=True)
class PaperPattern:
    """One of the paper's patterns, ``name`` a key of :data:`PATTERNS` (3 m x 3 m, fixed).

    text : the spec as given (default: ``name``); not compared.
    """

    name: str
    text: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or self.name not in PATTERNS:
            raise RigidfoldError(f"unknown pattern {self.name!r} (choose from {FORMS})")
        _text(self, self.text)

    def __str__(self) -> str:
        return self.text or self.name


@dataclass(frozen=True)
class GridPattern:
    """A grid of ``nx`` x ``ny`` vertices (:func:`grids.grid`; at least 2 x 2, checked when
    it is made).

    text : the spec as given (default: ``grid:NXxNY``); not compared.
    """

    nx: int
    ny: int
    text: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        for count in (self.nx, self.ny):
            if isinstance(count, bool) or not isinstance(count, int | np.integer):
                raise TypeError(f"a grid's vertex counts are ints, got {self.nx!r} x {self.ny!r}")
        object.__setattr__(self, "nx", int(self.nx))
        object.__setattr__(self, "ny", int(self.ny))
        _text(self, self.text)

    def __str__(self) -> str:
        return self.text or f"grid:{self.nx}x{self.ny}"


@dataclass(frozen=True, eq=False)
class MeshPattern:
    """A quality triangulation of a simple polygon (:func:`footprint.footprint_mesh`).

    outline : (N, 2) float64 polygon vertices in metres, checked when the plan is made
        (:func:`footprint.check_footprint`); or
    file : a file of ``x,y`` lines (:func:`footprint.read_footprint`), read when the plan is
        made; exactly one of the two.
    text : the spec as given (default: ``mesh:x1,y1;x2,y2;...`` or ``mesh:FILE``); not
        compared.
    """

    outline: np.ndarray | None = None
    file: Path | None = None
    text: str = ""

    def __post_init__(self) -> None:
        if (self.outline is None) == (self.file is None):
            raise TypeError("a mesh pattern takes an outline or a file, one of the two")
        if self.file is not None and not isinstance(self.file, Path):
            raise TypeError(f"a mesh pattern's file is a Path, got {type(self.file).__name__}")
        if self.outline is not None:
            if isinstance(self.outline, str):
                raise TypeError("a mesh pattern's outline is an (N, 2) array, got str")
            outline = np.array(self.outline, dtype=np.float64).reshape(-1, 2)
            outline.setflags(write=False)
            object.__setattr__(self, "outline", outline)
        _text(self, self.text)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MeshPattern):
            return NotImplemented
        if self.outline is None or other.outline is None:
            return self.outline is other.outline and self.file == other.file
        return np.array_equal(self.outline, other.outline)

    def __hash__(self) -> int:
        return hash(self.file if self.outline is None else self.outline.tobytes())

    def __str__(self) -> str:
        if self.text:
            return self.text
        if self.outline is None:
            return f"mesh:{os.fspath(self.file or '')}"
        return "mesh:" + ";".join(f"{_number(x)},{_number(y)}" for x, y in self.outline)


@dataclass(frozen=True)
class FilePattern:
    """A crease pattern drawn in another tool, a ``.fold`` or ``.svg`` file
    (:func:`files.read_pattern_file`), read when the plan is made.

    text : the spec as given (default: the path); not compared.
    """

    path: Path
    text: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.path, Path):
            raise TypeError(f"a pattern file is a Path, got {type(self.path).__name__}")
        _text(self, self.text)

    def __str__(self) -> str:
        return self.text or os.fspath(self.path)


PatternSpec = PaperPattern | GridPattern | MeshPattern | FilePattern
"""A crease pattern as the user chose it."""

PATTERN_TYPES = (PaperPattern, GridPattern, MeshPattern, FilePattern)

_TAKES: dict[type, tuple[str, ...]] = {
    PaperPattern: (),
    GridPattern: ("size", "diagonals"),
    MeshPattern: ("edge length",),
    FilePattern: ("size", "scale", "rigid panels"),
}
"""The options each kind of spec takes (:func:`refuse_options`)."""


def _number(value: float) -> str:
    """The shortest text that reads back as ``value`` (``12`` for 12.0)."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


@dataclass(frozen=True, eq=False)
class Plan:
    """A crease pattern in plan, and how it was made.

    spec : :data:`PatternSpec`, the pattern as chosen; its ``text`` is recorded ("1",
        "grid:15x9", "mesh:0,0;12,0;12,8;0,8", "cp.fold");
    xy : (V, 2) float64 plan vertices, the lower-left corner of their bounding box at (0, 0);
    faces : (F, 3) int64 triangles, counter-clockwise seen from +z;
    fixed : (k, 2) int64 vertex pairs of the crease lines that start fixed (a file's);
    diagonals : str of a ``grid:`` pattern, else None;
    edge_length : float, the target edge length (metres) of a ``mesh:`` pattern, else None;
    footprint : (N, 2) float64 counter-clockwise polygon of a ``mesh:`` pattern, placed as
        ``xy``, else None;
    source : dict of a pattern read from a file (:attr:`files.PatternFile.source`), else None;
    drawn_angles : (F, 3) float64 radians of a pattern read from a file, the corner angles of
        ``faces`` as the file draws them (:attr:`files.PatternFile.sector_angles`: a folded
        FOLD file's in 3D), else None.
    """

    spec: PatternSpec
    xy: np.ndarray
    faces: np.ndarray
    fixed: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    diagonals: str | None = None
    edge_length: float | None = None
    footprint: np.ndarray | None = None
    source: dict | None = None
    drawn_angles: np.ndarray | None = None

    @property
    def box(self) -> tuple[float, float]:
        """Width and height (metres) of the plan's bounding box."""
        width, height = np.ptp(self.xy, axis=0)
        return float(width), float(height)

    def metadata(self) -> dict:
        """JSON-serialisable description: the spec and everything needed to make it again."""
        return {
            "pattern": self.spec.text,
            "plan_size_m": list(self.box),
            "diagonals": self.diagonals,
            "edge_length_m": self.edge_length,
            "footprint_m": None if self.footprint is None else self.footprint.tolist(),
            "pattern_file": self.source,
        }


class PlanKeywords(TypedDict, total=False):
    """The keywords of :func:`make_plan` besides the spec, its size and the settings (the
    readers of texts take the size as text too)."""

    diagonals: str | None
    edge_length: float | None
    scale: float | None
    up: str
    rigid_panels: bool


class PatternKeywords(PlanKeywords, total=False):
    """The keywords of :func:`make_plan` besides the spec and the settings, as
    :func:`rigidfold.generate.case.make_case` passes them on (one list, not two)."""

    size: tuple[float, float] | None


def given_options(size: object, options: PlanKeywords) -> dict[str, object]:
    """The options a pattern was given, by the names its messages use (None: not given),
    for :func:`refuse_options`."""
    return {
        "size": size,
        "diagonals": options.get("diagonals"),
        "edge length": options.get("edge_length"),
        "scale": options.get("scale"),
        "rigid panels": options.get("rigid_panels") or None,
    }


def make_plan(
    spec: PatternSpec,
    *,
    settings: Settings = DEFAULTS,
    **options: Unpack[PatternKeywords],
) -> Plan:
    """The plan of a pattern spec; a one-line RigidfoldError naming what was received if bad.

    spec : a :class:`PaperPattern` (3 m x 3 m, fixed); a :class:`GridPattern`, a grid over
        ``size`` (:func:`grids.grid`); a :class:`MeshPattern`, a quality triangulation of a
        simple polygon (:func:`footprint.footprint_mesh`) translated so that its bounding box
        starts at (0, 0); a :class:`FilePattern`, a crease pattern drawn in another tool
        (:func:`files.read_pattern_file`), scaled and translated likewise.
    size : (W, H) in metres, of a grid (default 3 x 3), or the box a file drawn without units
        is fitted into (default 3 x 3);
    scale : metres per unit of a file drawn without units (instead of fitting it into size);
    up : the up axis of a FOLD file, ``"z"`` or ``"y"`` (ignored by the other forms);
    rigid_panels : a file's polygon faces are rigid panels (their added diagonals fixed);
    diagonals : "centre" (default), "parallel" or "alternate", of a grid only;
    edge_length : target edge length in metres of a mesh only (default
        :func:`footprint.default_edge_length`);
    settings : theta_min and the pattern limits (``mesh_*``, ``max_pattern_faces``).
    """
    if not isinstance(spec, PATTERN_TYPES):
        raise TypeError(
            f"a plan is made from a pattern spec ({', '.join(t.__name__ for t in PATTERN_TYPES)})"
            f", got {type(spec).__name__} (rigidfold.generate.specs.parse_pattern_spec reads "
            "text)"
        )
    text = spec.text
    size, diagonals = options.get("size"), options.get("diagonals")
    refuse_options(text, type(spec), given_options(size, options))
    if isinstance(spec, PaperPattern):
        xy, faces = PATTERNS[spec.name]()
        return Plan(spec, xy, faces)
    if isinstance(spec, GridPattern):
        nx, ny = spec.nx, spec.ny
        check_faces(2 * (nx - 1) * (ny - 1), f"pattern {text!r}", settings)
        width, height = DEFAULT_SIZE if size is None else check_size(size)
        check_extent(width, height, f"pattern {text!r}", settings)
        diagonals = DIAGONALS[0] if diagonals is None else diagonals
        return Plan(spec, *grid(nx, ny, width, height, diagonals), diagonals=diagonals)
    if isinstance(spec, MeshPattern):
        if spec.outline is None:
            assert spec.file is not None  # MeshPattern checks it
            outline = read_footprint(spec.file, settings)
        else:
            outline = check_footprint(spec.outline, settings)
        outline = outline - outline.min(axis=0)
        length = options.get("edge_length")
        length = default_edge_length(outline, settings) if length is None else length
        xy, faces = footprint_mesh(outline, length, settings)
        check_faces(len(faces), f"pattern {text!r}", settings)
        return Plan(spec, xy, faces, edge_length=float(length), footprint=outline)
    read = read_pattern_file(
        spec.path,
        size=None if size is None else check_size(size),
        scale=options.get("scale"),
        up=options.get("up", "z"),
        rigid_panels=options.get("rigid_panels", False),
        settings=settings,
    )
    check_faces(len(read.faces), f"pattern {text!r}", settings)
    return Plan(
        spec,
        read.xy,
        read.faces,
        fixed=read.fixed,
        source=read.source,
        drawn_angles=read.sector_angles,
    )


def check_faces(count: int, what: str, settings: Settings = DEFAULTS) -> None:
    """ValueError ``"<what> has <count> triangles, more than <limit>
    (Settings.limits.max_pattern_faces)"`` when a pattern's real triangle count passes the limit:
    checked after triangulation, before any problem is built on it."""
    if count > settings.limits.max_pattern_faces:
        raise RigidfoldError(
            f"{what} has {count} triangles, more than {settings.limits.max_pattern_faces} "
            "(Settings.limits.max_pattern_faces)"
        )


def check_size(size: object, shown: object = None) -> tuple[float, float]:
    """(W, H) in metres from a pair of numbers, both finite and > 0; else a one-line
    RigidfoldError naming ``shown`` (default: ``size``), as the user gave it."""
    try:
        width, height = (float(t) for t in size)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        width = height = float("nan")
    if not (np.isfinite([width, height]).all() and width > 0 and height > 0):
        shown = size if shown is None else shown
        raise RigidfoldError(
            f"a pattern size is WxH in metres with W, H > 0 (e.g. 12x8), got {shown!r}"
        )
    return width, height


def refuse_options(text: str, kind: type, given: Mapping[str, object]) -> None:
    """A one-line RigidfoldError for the options ``given`` (name -> value, None: not given)
    that pattern ``text``, of spec type ``kind``, does not take."""
    extra = [
        name for name, value in given.items() if value is not None and name not in _TAKES[kind]
    ]
    if extra:
        raise RigidfoldError(
            f"pattern {text!r} takes no {' or '.join(extra)} (a size and diagonals are for "
            "grid:NXxNY patterns, an edge length for mesh:POLYGON, a size, scale and rigid "
            "panels for FOLD and SVG files)"
        )
