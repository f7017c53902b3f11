"""Miura-ori: a reference rigid-foldable pattern with exactly one DOF."""

from __future__ import annotations

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern


def miura(
    nx: int = 3,
    ny: int = 3,
    *,
    length: float = 1.0,
    width: float = 1.0,
    offset: float = 0.4,
    height: float = 0.3,
) -> CreasePattern:
    """A folded Miura-ori of nx x ny parallelograms, each split by a fixed ("J") diagonal.

    The folded Miura-ori is the translational surface ``x_ij = a_i + b_j`` of two zigzags in
    perpendicular planes: ``a_i = (i length, 0, (i mod 2) height)`` and
    ``b_j = ((j mod 2) offset, j width, 0)``. Every quad is a planar parallelogram and every
    interior vertex has sector angles alpha, pi - alpha, alpha, pi - alpha (developable).
    ``height = 0`` gives the flat crease pattern.
    """
    if nx < 1 or ny < 1:
        raise RigidfoldError(f"a Miura-ori needs at least 1 x 1 cells, got {nx} x {ny}")
    gi, gj = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="xy")
    i, j = gi.ravel(), gj.ravel()
    coords = np.column_stack([i * length + (j % 2) * offset, j * width, (i % 2) * height])
    quads, diagonals = [], []
    for q in range(ny):
        for p in range(nx):
            v = q * (nx + 1) + p
            a, b, c, d = v, v + 1, v + nx + 2, v + nx + 1
            quads += [(a, b, c), (a, c, d)]
            diagonals.append((a, c))
    return CreasePattern.from_faces(coords, np.array(quads), np.array(diagonals))
