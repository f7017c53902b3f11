"""Near-mechanisms first: the candidates whose fix removes a near-mechanism and keeps the
shape's exact mechanisms.

Generation counts a shape's DOF with a gap (``Settings.mechanism.dof_count`` "gap"): the
singular values of the constraints below ``dof_gap`` times the rank threshold count, so a
near-mechanism (a motion that strains the constraints by less than 1e-6 of the stiffest) is
a DOF, as a builder would feel it. Such a shape of DOF d has fewer exact mechanisms: the
analysis at the rank threshold itself (``mechanism_rank_tol``) finds d_0 < d. Its near
mechanisms live where creases barely fold, typically at vertices whose creases are all
within a fraction of a degree of flat: at first order such a vertex moves out of its plane,
at second order it does not, and the second-order test finds the children that keep only
such a motion rigid.

Fixing a free crease c keeps the motions in which c does not turn. With gap-count rows
``H_phi`` (h x d) and the exact mechanisms' rows ``H0_phi`` (h x d_0) in the same hinge
order, both bases orthonormal in the same space of the frame's motions, the share

    r_c = |H0_phi[c]| / |H_phi[c]|

is small for a crease that turns in the near-mechanisms but hardly in the exact ones: its fix
removes one near-mechanism and keeps the exact mechanisms (up to r_c), so the child moves as
its parent really does. The search (:meth:`rigidfold.generate.steps._Steps.fix_near`) tries
those candidates first, the smallest r_c first, at every shape that has them: near the
target a DOF-1 child that keeps only a near-mechanism cannot fold, and one that keeps the
exact mechanism can; further up, a near-mechanism left in place is a DOF that no later fix of
a real fold removes. (Tried only at the shapes whose children are checked, DOF 2, it won 1 of
the broad set's 26 non-drawn cases instead of 4: ``docs/broad_set.md``, session 26.) A shape
without exact mechanisms (d_0 = 0: rigid but for its near-mechanisms; the search leaves it at
once, ``Settings.generation.near_rigid_backtrack``) or without near ones (d_0 = d) has
none, nor has one with many (d - d_0 above ``Settings.generation.near_max``): on large,
nearly flat grids the singular values run evenly across the gap's bound (a 41 x 41 grid on
the dome: from 5e-8 to 1e-5 of the largest, 68 near-mechanisms at the first shape), there
is no separate near-mechanism to remove, and a single fix moves the count up as often as
down. A fix whose solution counts more DOF than its shape is not kept
(``AttemptOutcome.NO_GAIN``); with ``Settings.generation.near_gain`` (off), neither is one of
the same count, and after a shape whose fixes all gained nothing the next 1, 2, 4, ... shapes
go without (docs/broad_set.md, session 43).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rigidfold.mechanism import Mechanism


def near_candidates(
    counted: Mechanism,
    exact: Mechanism,
    groups: Sequence[Sequence[int]] | None,
    ratio: float,
    floor: float,
    most: int | None = None,
) -> list[tuple[tuple[int, ...], float]]:
    """The crease groups whose fix removes a near-mechanism of ``counted`` (the gap count)
    and keeps the exact mechanisms ``exact`` (the same shape at the rank threshold), with
    their shares r (see the module's text), smallest first: those with r below ``ratio``
    whose rows in ``counted`` are at least ``floor`` of the largest. ``groups``: mirror
    groups of edges fixed together (None: every free crease alone); a group's share is its
    largest exact row over its largest counted one. ``most``: none where the shape has more
    near-mechanisms than this (``Settings.generation.near_max``; None: no bound).

    Returns
    -------
    list of (group : tuple of edge indices, r : float)
    """
    if exact.dof == 0 or exact.dof >= counted.dof:
        return []
    if most is not None and counted.dof - exact.dof > most:
        return []  # a continuum of soft modes, not a few near-mechanisms
    hinges = counted.hinges
    if not np.array_equal(hinges, exact.hinges):
        raise ValueError("the two analyses are of different shapes")
    rows = np.linalg.norm(counted.H_phi, axis=1)  # (h,)
    rows0 = np.linalg.norm(exact.H_phi, axis=1)  # (h,)
    top = float(rows.max(initial=0.0))
    if top <= 0:
        return []
    row_of = {int(e): j for j, e in enumerate(hinges.tolist())}
    sets = [(int(e),) for e in hinges] if groups is None else [tuple(g) for g in groups]
    out: list[tuple[tuple[int, ...], float]] = []
    for group in sets:
        js = [row_of.get(int(e), -1) for e in group]
        if min(js) < 0:  # a member is not free
            continue
        size = float(rows[js].max())
        if size < floor * top:
            continue
        share = float(rows0[js].max()) / size
        if share < ratio:
            out.append((tuple(int(e) for e in group), share))
    out.sort(key=lambda item: item[1])
    return out
