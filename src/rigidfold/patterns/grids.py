"""The crease patterns of the paper (Sections 6.3-6.6, Table 4), in plan.

The paper's patterns cover the 3 m x 3 m square [0, 3]^2; :func:`grid` makes grids of any
vertex counts, size and diagonals. Each function returns the plan vertices
``(V, 2)`` and counter-clockwise triangles ``(F, 3)``; :func:`rigidfold.patterns.build` lifts
them onto a target surface.

The paper's figures 5, 6, 13 and 16 are missing from the text; the layouts are therefore
chosen here and documented in each function.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError

DIAGONALS = ("centre", "parallel", "alternate")
"""How :func:`grid` splits each rectangle: see its docstring."""

DEFAULT_SIZE = (3.0, 3.0)
"""Width and height (metres) of a ``grid:`` pattern without a size, and the box a drawing
without units is fitted into: the paper's square."""


def check_extent(width: float, height: float, what: str, settings: Settings = DEFAULTS) -> None:
    """A one-line ValueError naming ``what`` unless a plan of ``width`` x ``height`` metres
    (its bounding box) is from ``settings.limits.min_pattern_size`` to
    ``settings.limits.max_coordinate`` across (its larger side)."""
    across = max(width, height)
    if not settings.limits.min_pattern_size <= across <= settings.limits.max_coordinate:
        raise RigidfoldError(
            f"{what} is {width:.3g} m x {height:.3g} m: a crease pattern is "
            f"{settings.limits.min_pattern_size:g} m to "
            f"{settings.limits.max_coordinate:g} m across "
            "(Settings.limits.min_pattern_size, Settings.limits.max_coordinate)"
        )


def grid(
    nx: int, ny: int, width: float = 3.0, height: float = 3.0, diagonals: str = "centre"
) -> tuple[np.ndarray, np.ndarray]:
    """An nx x ny vertex grid over [0, width] x [0, height], each rectangle cut by a diagonal.

    Vertex ``j * nx + i`` lies at ``(i * width / (nx - 1), j * height / (ny - 1))`` (the
    last column at x = width and the last row at y = height exactly); the
    triangles come cell by cell, row by row from y = 0, two per cell. ``diagonals``:

    * ``"centre"``: every diagonal points at the grid's centre, which makes the layout
      mirror-symmetric about both mid-lines (and, on a square grid, both diagonals) and gives
      every corner degree 3. With an even vertex count along x, the middle column of cells
      straddles the mid-line x = width / 2 and no diagonal there can point at the centre:
      they rise (lower-left to upper-right) above the centre and fall below it, which keeps
      the mirror symmetry about y = height / 2 (and likewise for an even count along y; the
      one centre cell of two even counts rises). Two even counts leave no mirror symmetry;
    * ``"parallel"``: every diagonal runs from the cell's lower-left to its upper-right
      corner (pattern 1p): the corners (0, height) and (width, 0) have degree 2;
    * ``"alternate"``: the diagonals alternate cell by cell like a checkerboard, lower-left to
      upper-right in the cell at the origin; with odd vertex counts every corner has degree
      3, with an even count two corners have degree 2.

    ``grid(7, 7)`` is pattern 1 and ``grid(11, 11)`` the 11 x 11 grid, coordinate for
    coordinate and triangle for triangle.
    """
    for n in (nx, ny):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
            raise RigidfoldError(f"a grid needs at least 2 x 2 vertices, got {nx!r} x {ny!r}")
    for name, size in (("width", width), ("height", height)):
        if not (np.isfinite(size) and size > 0):
            raise RigidfoldError(
                f"a grid's {name} must be a positive number of metres, got {size!r}"
            )
    if diagonals not in DIAGONALS:
        raise RigidfoldError(
            f"unknown diagonals {diagonals!r} (choose from {', '.join(DIAGONALS)})"
        )
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    x = np.where(i == nx - 1, width, i * (width / (nx - 1)))  # the far sides exactly
    y = np.where(j == ny - 1, height, j * (height / (ny - 1)))
    return np.column_stack([x.ravel(), y.ravel()]), _split_cells(nx, ny, diagonals)


def _split_cells(nx: int, ny: int, diagonals: str) -> np.ndarray:
    """Triangles (F, 3) of an nx x ny vertex grid, each cell cut by one diagonal."""
    tris = []
    cx, cy = (nx - 1) / 2, (ny - 1) / 2
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b = j * nx + i, j * nx + i + 1  # lower-left, lower-right
            d, e = a + nx, b + nx  # upper-left, upper-right
            if diagonals == "centre":
                # the cell's centre lies in the quadrant given by the signs below; the
                # diagonal through it that points at the grid centre rises when both signs
                # agree; a cell on a mid-line (a zero sign) rises on the upper or right half
                sx, sy = np.sign(i + 0.5 - cx), np.sign(j + 0.5 - cy)
                rising = sx == sy if sx and sy else sx + sy >= 0
            else:
                rising = diagonals == "parallel" or (i + j) % 2 == 0
            if rising:  # diagonal a-e
                tris += [(a, b, e), (a, e, d)]
            else:  # diagonal b-d
                tris += [(a, b, d), (b, e, d)]
    return np.asarray(tris, dtype=np.int64)


def pattern1() -> tuple[np.ndarray, np.ndarray]:
    """Crease pattern 1: 7 x 7 vertex grid, spacing 0.5 m, V = 49, E = 120, F = 72.

    Every 0.5 m square is split by the diagonal that points at the centre (1.5, 1.5), so the
    layout is mirror-symmetric about both mid-lines and both diagonals and every corner
    vertex has degree 3. The paper's Figure 5 is missing; this layout is chosen over
    :func:`pattern1p` (all diagonals parallel) because 1p's corners (0, 3) and (3, 0) are
    triangles hinged on a single crease, independent one-DOF flaps in every shape, and
    because with this layout the random criterion locks as often as in Table 5 (mean N_lock
    7.59 over 100 surfaces against the paper's 7.32, ``docs/results.md``; 99.5 with 1p,
    ``docs/earlier_results.md``).
    """
    return grid(7, 7)


def pattern1p() -> tuple[np.ndarray, np.ndarray]:
    """Pattern 1 with parallel diagonals: V, E, F as :func:`pattern1`.

    Each 0.5 m square is split by its diagonal from lower-left to upper-right, so every
    interior vertex has degree 6 but the corners (0, 3) and (3, 0) have degree 2: the
    triangle there is hinged on one crease, a one-DOF flap independent of the rest of the
    mechanism. Kept as the other reading of the paper's Figure 5.
    """
    return grid(7, 7, diagonals="parallel")


def pattern2() -> tuple[np.ndarray, np.ndarray]:
    """Crease pattern 2: staggered rows, Delaunay triangulation, V = 52, E = 129, F = 78.

    Rows at y = 0, 0.5, ..., 3. The first and last rows have 7 vertices at x = 0, 0.5, ..., 3;
    the five inner rows have a vertex on each side (x = 0 and x = 3) and inner vertices that
    alternate row by row: 6 at x = 0.25, 0.75, ..., 2.75, then 5 at x = 0.5, ..., 2.5, then
    6, 5, 6. (Table 4 prints E = 117, which contradicts Euler's formula V - E + F = 1.)
    The plan triangles beside the sides have 26.6-degree angles, below theta_min = 30 degrees.
    """
    rows = []
    for k, y in enumerate(np.arange(7) * 0.5):
        if k % 2 == 0:  # rows 0, 2, 4, 6: x = 0, 0.5, ..., 3
            xs = np.arange(7) * 0.5
        else:
            xs = np.concatenate([[0.0], 0.25 + 0.5 * np.arange(6), [3.0]])
        rows.append(np.column_stack([xs, np.full(len(xs), y)]))
    pts = np.concatenate(rows)
    tri = Delaunay(pts).simplices.astype(np.int64)
    return pts, counter_clockwise(pts, tri)


def grid11() -> tuple[np.ndarray, np.ndarray]:
    """11 x 11 grid, spacing 0.3 m, V = 121, E = 320, F = 200 (Sections 6.5-6.6).

    Every square's diagonal points towards the centre (1.5, 1.5): the triangulation is
    mirror-symmetric about x = 1.5, y = 1.5 and both diagonals of the square.
    """
    return grid(11, 11)


def counter_clockwise(pts: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Triangles (F, 3) of plan points (V, 2), each reordered counter-clockwise seen from +z."""
    p = pts[tri]
    cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (
        p[:, 2, 0] - p[:, 0, 0]
    )
    out = tri.copy()
    out[cross < 0] = out[cross < 0][:, [0, 2, 1]]
    return out
