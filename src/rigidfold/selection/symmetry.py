"""Mirror groups of crease lines: creases fixed together under symmetry (Sections 6.5-6.6)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import mirror_pairs
from rigidfold.mesh.topology import edge_keys
from rigidfold.protocols import SymmetryPlane


def crease_groups(
    pattern: CreasePattern, planes: Sequence[SymmetryPlane], settings: Settings = DEFAULTS
) -> list[tuple[int, ...]]:
    """Orbits of the interior edges under the mirror planes (1, 2 or 4 creases each).

    Without planes every crease is its own group. Sorted by the smallest edge index.
    """
    E, V = pattern.n_edges, pattern.n_vertices
    keys = edge_keys(pattern.edges, V)
    order = np.argsort(keys)
    a, b = [np.arange(E)], [np.arange(E)]
    for plane in planes:
        image = mirror_pairs(pattern.coords, plane, settings.geometry.symmetry_match_tol)[
            pattern.edges
        ]
        pos = np.searchsorted(keys[order], edge_keys(image, V))
        a.append(np.arange(E))
        b.append(order[np.minimum(pos, E - 1)])
    graph = coo_matrix((np.ones(E * len(a)), (np.concatenate(a), np.concatenate(b))), (E, E))
    _, label = connected_components(graph, directed=False)
    groups: dict[int, list[int]] = {}
    for e in pattern.interior_edges:
        groups.setdefault(int(label[e]), []).append(int(e))
    return sorted((tuple(g) for g in groups.values()), key=lambda g: g[0])
