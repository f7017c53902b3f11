"""The crease patterns of the paper (Sections 6.3-6.6, Table 4), in plan.

All patterns cover the 3 m x 3 m square [0, 3]^2. Each function returns the plan vertices
``(V, 2)`` and counter-clockwise triangles ``(F, 3)``; :func:`rigidfold.patterns.build` lifts
them onto a target surface.

The paper's figures 5, 6, 13 and 16 are missing from the text; the layouts are therefore
chosen here and documented in each function.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay


def _grid_points(n: int, spacing: float) -> np.ndarray:
    """Vertices of an n x n grid, index ``j * n + i`` at (i * spacing, j * spacing)."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    return np.column_stack([i.ravel() * spacing, j.ravel() * spacing])


def _split_squares(n: int, towards_centre: bool) -> np.ndarray:
    """Triangles of an n x n vertex grid, each square cut by one diagonal.

    ``towards_centre=False``: every diagonal runs from the square's lower-left to its
    upper-right corner. ``towards_centre=True``: every diagonal points at the grid's centre,
    which makes the triangulation mirror-symmetric about both mid-lines and both diagonals.
    """
    tris = []
    c = (n - 1) / 2
    for j in range(n - 1):
        for i in range(n - 1):
            a, b = j * n + i, j * n + i + 1  # lower-left, lower-right
            d, e = a + n, b + n  # upper-left, upper-right
            rising = True
            if towards_centre:
                # the square's centre lies in the quadrant given by the signs below; the
                # diagonal through it that points at the grid centre rises when both signs agree
                sx, sy = np.sign(i + 0.5 - c), np.sign(j + 0.5 - c)
                rising = sx == sy
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
    return _grid_points(7, 0.5), _split_squares(7, towards_centre=True)


def pattern1p() -> tuple[np.ndarray, np.ndarray]:
    """Pattern 1 with parallel diagonals: V, E, F as :func:`pattern1`.

    Each 0.5 m square is split by its diagonal from lower-left to upper-right, so every
    interior vertex has degree 6 but the corners (0, 3) and (3, 0) have degree 2: the
    triangle there is hinged on one crease, a one-DOF flap independent of the rest of the
    mechanism. Kept as the other reading of the paper's Figure 5.
    """
    return _grid_points(7, 0.5), _split_squares(7, towards_centre=False)


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
    return pts, _counter_clockwise(pts, tri)


def grid11() -> tuple[np.ndarray, np.ndarray]:
    """11 x 11 grid, spacing 0.3 m, V = 121, E = 320, F = 200 (Sections 6.5-6.6).

    Every square's diagonal points towards the centre (1.5, 1.5): the triangulation is
    mirror-symmetric about x = 1.5, y = 1.5 and both diagonals of the square.
    """
    return _grid_points(11, 0.3), _split_squares(11, towards_centre=True)


def _counter_clockwise(pts: np.ndarray, tri: np.ndarray) -> np.ndarray:
    p = pts[tri]
    cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (
        p[:, 2, 0] - p[:, 0, 0]
    )
    out = tri.copy()
    out[cross < 0] = out[cross < 0][:, [0, 2, 1]]
    return out
