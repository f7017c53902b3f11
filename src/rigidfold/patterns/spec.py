"""Pattern specs: the paper's names, ``grid:NXxNY``, ``mesh:POLYGON`` and FOLD or SVG files,
parsed into a plan.

Every plan is placed with the lower-left corner of its bounding box at (0, 0), the frame in
which the target surfaces are given (``rigidfold.surfaces``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypedDict

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.patterns.files import is_pattern_file, read_pattern_file
from rigidfold.patterns.footprint import default_edge_length, footprint_mesh, read_footprint
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

_COUNTS = re.compile(r"\s*(\d+)\s*[xX]\s*(\d+)\s*")


@dataclass(frozen=True, eq=False)
class Plan:
    """A crease pattern in plan, and how it was made.

    spec : str, the pattern as given ("1", "grid:15x9", "mesh:0,0;12,0;12,8;0,8", "cp.fold");
    xy : (V, 2) float64 plan vertices, the lower-left corner of their bounding box at (0, 0);
    faces : (F, 3) int64 triangles, counter-clockwise seen from +z;
    fixed : (k, 2) int64 vertex pairs of the crease lines that start fixed (a file's);
    diagonals : str of a ``grid:`` pattern, else None;
    edge_length : float, the target edge length (metres) of a ``mesh:`` pattern, else None;
    footprint : (N, 2) float64 counter-clockwise polygon of a ``mesh:`` pattern, placed as
        ``xy``, else None;
    source : dict of a pattern read from a file (:attr:`files.PatternFile.source`), else None.
    """

    spec: str
    xy: np.ndarray
    faces: np.ndarray
    fixed: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    diagonals: str | None = None
    edge_length: float | None = None
    footprint: np.ndarray | None = None
    source: dict | None = None

    @property
    def box(self) -> tuple[float, float]:
        """Width and height (metres) of the plan's bounding box."""
        width, height = np.ptp(self.xy, axis=0)
        return float(width), float(height)

    def metadata(self) -> dict:
        """JSON-serialisable description: the spec and everything needed to make it again."""
        return {
            "pattern": self.spec,
            "plan_size_m": list(self.box),
            "diagonals": self.diagonals,
            "edge_length_m": self.edge_length,
            "footprint_m": None if self.footprint is None else self.footprint.tolist(),
            "pattern_file": self.source,
        }


class PatternKeywords(TypedDict, total=False):
    """The keywords of :func:`parse_pattern` besides the spec and the settings, as
    :func:`rigidfold.generate.case.make_case` passes them on (one list, not two)."""

    size: str | tuple[float, float] | None
    diagonals: str | None
    edge_length: float | None
    scale: float | None
    up: str
    rigid_panels: bool


def parse_pattern(
    spec: str,
    *,
    size: str | tuple[float, float] | None = None,
    diagonals: str | None = None,
    edge_length: float | None = None,
    scale: float | None = None,
    up: str = "z",
    rigid_panels: bool = False,
    settings: Settings = DEFAULTS,
) -> Plan:
    """The plan of a pattern spec; a one-line ValueError naming what was received if bad.

    spec : one of the paper's names (``1``, ``1p``, ``2``, ``11``: 3 m x 3 m, fixed);
        ``grid:NXxNY``, a grid of NX x NY vertices over ``size`` (:func:`grids.grid`);
        ``mesh:POLYGON``, a quality triangulation of a simple polygon given as
        ``x1,y1;x2,y2;...`` in metres or as a file of ``x,y`` lines
        (:func:`footprint.footprint_mesh`), translated so that its bounding box starts at
        (0, 0); ``FILE.fold`` or ``FILE.svg``, a crease pattern drawn in another tool
        (:func:`files.read_pattern_file`), scaled and translated likewise.
    size : "WxH" or (W, H) in metres, of a ``grid:`` pattern (default 3 x 3), or the box a
        file drawn without units is fitted into (default 3 x 3);
    scale : metres per unit of a file drawn without units (instead of fitting it into size);
    up : the up axis of a FOLD file, ``"z"`` or ``"y"`` (ignored by the other forms);
    rigid_panels : a file's polygon faces are rigid panels (their added diagonals fixed);
    diagonals : "centre" (default), "parallel" or "alternate", of a ``grid:`` pattern only;
    edge_length : target edge length in metres of a ``mesh:`` pattern only (default
        :func:`footprint.default_edge_length`);
    settings : theta_min and the pattern limits (``mesh_*``, ``max_pattern_faces``).
    """
    text = str(spec).strip()
    given = {
        "size": size,
        "diagonals": diagonals,
        "edge length": edge_length,
        "scale": scale,
        "rigid panels": rigid_panels or None,
    }
    kind, colon, rest = text.partition(":")
    kind = kind.strip().lower()
    if not colon and text in PATTERNS:
        _refuse_options(text, given, keep=())
        xy, faces = PATTERNS[text]()
        return Plan(text, xy, faces)
    if colon and kind == "grid":
        _refuse_options(text, given, keep=("size", "diagonals"))
        counts = _COUNTS.fullmatch(rest)
        if counts is None:
            raise RigidfoldError(
                f"a grid pattern is grid:NXxNY (vertex counts, e.g. grid:15x9), got {text!r}"
            )
        nx, ny = int(counts[1]), int(counts[2])
        check_faces(2 * (nx - 1) * (ny - 1), f"pattern {text!r}", settings)
        width, height = parse_size(size)
        check_extent(width, height, f"pattern {text!r}", settings)
        diagonals = DIAGONALS[0] if diagonals is None else diagonals
        return Plan(text, *grid(nx, ny, width, height, diagonals), diagonals=diagonals)
    if colon and kind == "mesh":
        _refuse_options(text, given, keep=("edge length",))
        outline = read_footprint(rest.strip(), settings)
        outline = outline - outline.min(axis=0)
        length = default_edge_length(outline, settings) if edge_length is None else edge_length
        xy, faces = footprint_mesh(outline, length, settings)
        check_faces(len(faces), f"pattern {text!r}", settings)
        return Plan(text, xy, faces, edge_length=float(length), footprint=outline)
    if is_pattern_file(text):
        _refuse_options(text, given, keep=("size", "scale", "rigid panels"))
        read = read_pattern_file(
            text,
            size=None if size is None else parse_size(size),
            scale=scale,
            up=up,
            rigid_panels=rigid_panels,
            settings=settings,
        )
        check_faces(len(read.faces), f"pattern {text!r}", settings)
        return Plan(text, read.xy, read.faces, fixed=read.fixed, source=read.source)
    raise RigidfoldError(f"unknown pattern {spec!r} (choose from {FORMS})")


def check_faces(count: int, what: str, settings: Settings = DEFAULTS) -> None:
    """ValueError ``"<what> has <count> triangles, more than <limit>
    (Settings.limits.max_pattern_faces)"`` when a pattern's real triangle count passes the limit:
    checked after triangulation, before any problem is built on it."""
    if count > settings.limits.max_pattern_faces:
        raise RigidfoldError(
            f"{what} has {count} triangles, more than {settings.limits.max_pattern_faces} "
            "(Settings.limits.max_pattern_faces)"
        )


def parse_size(size: str | tuple[float, float] | None) -> tuple[float, float]:
    """(W, H) in metres from "WxH" (e.g. "12x8") or a pair; None gives :data:`DEFAULT_SIZE`."""
    if size is None:
        return DEFAULT_SIZE
    try:
        if isinstance(size, str):
            width, height = (float(t) for t in re.split(r"[xX]", size.strip()))
        else:
            width, height = (float(t) for t in size)
    except (TypeError, ValueError):
        width = height = float("nan")
    if not (np.isfinite([width, height]).all() and width > 0 and height > 0):
        raise RigidfoldError(
            f"a pattern size is WxH in metres with W, H > 0 (e.g. 12x8), got {size!r}"
        )
    return width, height


def _refuse_options(text: str, given: dict, keep: tuple[str, ...]) -> None:
    """A one-line ValueError for the options given that pattern ``text`` does not take."""
    extra = [name for name, value in given.items() if value is not None and name not in keep]
    if extra:
        raise RigidfoldError(
            f"pattern {text!r} takes no {' or '.join(extra)} (a size and diagonals are for "
            "grid:NXxNY patterns, an edge length for mesh:POLYGON, a size, scale and rigid "
            "panels for FOLD and SVG files)"
        )
