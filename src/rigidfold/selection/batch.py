"""Several creases per solve: the largest compatible set of ranked candidates (issue 49).

The mechanisms of a shape are ``H a`` for a in R^d, with hinge rotations ``H_phi a``
(:class:`~rigidfold.mechanism.Mechanism`). Fixing a set J of creases keeps the mechanisms
with ``H_phi[J] a = 0``; at first order, fixing J removes exactly |J| DOF when the rows
``H_phi[J]`` (the creases' rotations restricted to the current mechanism space) are
linearly independent, and locks a free crease p when p's row lies in their span (it keeps
no rotation: Property 2, :mod:`rigidfold.selection.lookahead`).

:func:`compatible_set` goes down the criterion's ranking and takes a candidate into the set
when (a) each of its rows keeps at least ``batch_tol`` of its norm outside the span of the
rows taken so far (so the set's rows are of full rank, well away from dependence: the solve
is asked for |J| independent fixes), and (b) with it, every folded free crease outside the
set (and not still in every mode) keeps at least ``batch_tol`` of its own rotations (no
crease locked at first order, with a margin). Candidates whose rows are ~0 (they
constrain nothing) are left to the one-crease order; a set is looked for among the first
``_SCAN`` times its size candidates. The set is made far from the target DOF only
(``batch_single_dof``), where the second-order forecast and the deployability check do not
apply (they are made for the children of shapes of few DOF): near the target the search
fixes one crease per solve, as the paper does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mechanism import Mechanism

_SCAN = 8
"""A set is looked for among the first ``_SCAN`` times its size candidates of the ranking:
further down, the criterion no longer favours them, and each look costs a product of H_phi."""


def compatible_set(
    mechanism: Mechanism,
    candidates: Sequence[Sequence[int]],
    size: int,
    *,
    settings: Settings = DEFAULTS,
    skip: Callable[[int], bool] | None = None,
) -> list[int]:
    """The positions (in ``candidates``, the ranked crease groups, best first) of at most
    ``size`` candidates that can be fixed together in one solve (see the module's text), in
    the ranking's order; ``skip(k)`` leaves candidate k out (e.g. one whose fix locked a
    crease at an earlier shape)."""
    hinges, H = mechanism.hinges, np.asarray(mechanism.H_phi, dtype=float)
    h, d = H.shape
    if size < 1 or d == 0 or h == 0:
        return []
    row_of = {int(e): j for j, e in enumerate(hinges.tolist())}
    norms = np.sqrt(np.einsum("hd,hd->h", H, H))
    top = float(norms.max(initial=0.0))
    if top <= 0:
        return []
    still = norms <= settings.mechanism.lock_tol * top
    folded = np.abs(mechanism.pattern.fold_angles[hinges]) > settings.geometry.flat_angle
    tol = settings.generation.batch_tol
    basis = np.zeros((0, d))
    inside = np.zeros(h, dtype=bool)
    chosen: list[int] = []
    for k, group in enumerate(candidates):
        if len(chosen) >= size or len(basis) >= d - 1 or k >= _SCAN * size:
            break
        if skip is not None and skip(k):
            continue
        rows = [row_of.get(int(e), -1) for e in group]
        if min(rows) < 0 or still[rows].any() or inside[rows].any():
            continue
        trial = basis
        for r in rows:
            v = H[r] / norms[r]
            res = v - trial.T @ (trial @ v)
            size_left = float(np.linalg.norm(res))
            if size_left <= tol:
                break
            trial = np.vstack([trial, res / size_left])
        else:
            within = inside.copy()
            within[rows] = True
            left = H - (H @ trial.T) @ trial
            kept = np.sqrt(np.einsum("hd,hd->h", left, left))
            watch = folded & ~within & ~still
            if not (kept[watch] < tol * norms[watch]).any():
                basis, inside = trial, within
                chosen.append(k)
    return chosen
