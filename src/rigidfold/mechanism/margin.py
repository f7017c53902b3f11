"""The margin of a DOF count: how far the singular values of the kinematic constraints lie
from the rank threshold that decides the DOF.

The DOF is the dimension of the kernel of the constraint matrix C
(:func:`rigidfold.mechanism.kinematics.constraint_matrix`, rows of unit norm): the singular
values below ``Settings.mechanism.rank_tol`` times the largest count as zero. A design whose
smallest non-zero singular value lies just above that threshold has a near-mechanism: a mode
that the count calls rigid but that a built structure feels as very soft (its stiffness goes
with the square of that value); one whose largest zero value lies just below it has a DOF
that depends on the tolerance. :func:`dof_margin` measures both sides of the gap; the count
is *clear* when each side is ``Settings.mechanism.dof_gap`` away from the threshold.

With the count of ``Settings.mechanism.dof_count`` "gap" (generation with the deployability
check), the DOF is the number of singular values below ``dof_gap`` times the threshold: the
near-mechanisms are counted as what they are for a builder, mechanisms. A mode of singular
value sigma (relative to the largest, rows of unit norm) has the stiffness of about sigma^2
times the bar stiffness k = EA/L of the panels' frame; below 1e-6 that is at most 1e-12 k,
1e-2 N/m for steel panels (k up to about 1e10 N/m), where the weight of one panel (some
100 N) would move it by kilometres: a mechanism, not a structure. Such a count has its gap by
construction (the next singular value is at least ``dof_gap`` times the paper's threshold);
it is *clear* where the mechanism analysis of the search (QR or Ritz values) counts the same.
The softer modes above it (sigma up to about 1e-2: k sigma^2 up to 1e5 N/m) are the
structure check's business (``rigidfold structure``), not the count's.

The singular values come from a dense SVD of C (values only) up to
``Settings.mechanism.second_order_vertices`` vertices; above, from the Ritz values of the
sparse analysis (:mod:`rigidfold.mechanism.sparse`), which approximate the smallest ones
from above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rigidfold.config import DEFAULTS, Settings
from rigidfold.mechanism import kinematics
from rigidfold.mechanism.sparse import row_scale, sparse_kernel
from rigidfold.mesh import CreasePattern


@dataclass(frozen=True)
class DofMargin:
    """The gap around the rank threshold of a DOF count.

    dof : the kernel's dimension at ``rank_tol``
    zero_max : the largest singular value counted as zero, over the largest (0 where the
        kernel has no singular value of its own: fewer rows than columns)
    nonzero_min : the smallest counted as non-zero, over the largest
    gap : ``Settings.mechanism.dof_gap``; threshold : ``Settings.mechanism.rank_tol``
    near : how many singular values lie within a factor ``gap`` of the threshold, either side
    method : "dense" or "sparse" (Ritz values)
    count : "threshold" (the paper's: ``dof`` counts the values at most ``threshold``) or
        "gap" (``dof`` counts those below ``gap`` times it; the module's text)
    dof_with_gap : the values below ``gap`` times the threshold (the DOF counting the
        near-mechanisms)
    counted : the DOF the search's mechanism analysis gave the design (None: not given)
    """

    dof: int
    zero_max: float
    nonzero_min: float
    threshold: float
    gap: float
    near: int
    method: str
    count: str = "threshold"
    dof_with_gap: int = 0
    counted: int | None = None

    @property
    def agrees(self) -> bool:
        """The search's count (``counted``) is the singular values' (or was not given)."""
        return self.counted is None or self.counted == self.dof

    @property
    def clear(self) -> bool:
        """The next singular value above those counted is at least ``gap`` times the
        threshold (and, with the paper's count, the largest counted at most 1/``gap`` of
        it): no near-mechanism, and the count does not hang on the tolerance; and the
        search counted the same."""
        above = self.nonzero_min >= self.gap * self.threshold
        below = self.count == "gap" or self.zero_max <= self.threshold / self.gap
        return above and below and self.agrees

    @property
    def message(self) -> str:
        """One sentence: the margin, and where it is not clear, what that means."""
        if not self.agrees:
            return (
                f"the search counted DOF {self.counted}, the singular values of the "
                f"constraints give DOF {self.dof} (below {self.limit:g} of the largest; "
                f"smallest non-zero {self.nonzero_min:.2g}, largest zero {self.zero_max:.2g}): "
                "the DOF has no clear gap"
            )
        if self.clear:
            return (
                f"DOF {self.dof} has a clear gap: the smallest non-zero singular value is "
                f"{self.nonzero_min:.2g} of the largest, the largest zero one {self.zero_max:.2g}"
                + (
                    f" (counted below {self.limit:g}: near-mechanisms are mechanisms)"
                    if self.count == "gap"
                    else ""
                )
            )
        return (
            f"DOF {self.dof} was reached only without a clear gap: {self.near} singular value"
            f"{'s' if self.near != 1 else ''} of the constraints "
            f"{'lie' if self.near != 1 else 'lies'} within a factor "
            f"{self.gap:g} of the rank threshold {self.threshold:g} (smallest non-zero "
            f"{self.nonzero_min:.2g}, largest zero {self.zero_max:.2g} of the largest): "
            "near-mechanisms, very soft modes of the built design; counting them, DOF "
            f"{self.dof_with_gap}"
        )

    @property
    def limit(self) -> float:
        """The singular values at most this (over the largest) are counted in ``dof``."""
        return self.threshold * (self.gap if self.count == "gap" else 1.0)

    def to_dict(self) -> dict:
        return {
            "dof": self.dof,
            "clear": self.clear,
            "zero_max": self.zero_max,
            "nonzero_min": self.nonzero_min,
            "threshold": self.threshold,
            "gap": self.gap,
            "near": self.near,
            "method": self.method,
            "count": self.count,
            "dof_with_gap": self.dof_with_gap,
            "counted": self.counted,
            "message": self.message,
        }


def dof_margin(
    pattern: CreasePattern,
    support_face: int,
    settings: Settings = DEFAULTS,
    *,
    count: str = "threshold",
    counted: int | None = None,
) -> DofMargin:
    """The :class:`DofMargin` of ``pattern`` held by its triangle ``support_face``, with the
    ``count`` "threshold" or "gap" (the module's text; ``settings.mechanism.rank_tol`` is
    the paper's threshold either way) and the search's own count ``counted``."""
    C = kinematics.constraint_matrix(pattern, support_face)
    n = C.shape[1]
    if pattern.n_vertices <= settings.mechanism.second_order_vertices:
        values = scipy.linalg.svdvals(C.toarray())
        # a wide matrix: the columns beyond the rows are kernel directions of value 0
        values = np.concatenate([values, np.zeros(max(n - len(values), 0))])
        method = "dense"
    else:
        _, ritz, _ = sparse_kernel(C, settings)
        top = row_scale(C)
        values = np.concatenate([[top], np.sort(ritz)[::-1]])
        method = "sparse"
    values = values / values[0] if len(values) and values[0] > 0 else values
    tau = settings.mechanism.rank_tol
    gap = settings.mechanism.dof_gap
    limit = tau * gap if count == "gap" else tau
    zero = values[values <= limit]
    nonzero = values[values > limit]
    near = int(np.sum((values > tau / gap) & (values < tau * gap)))
    return DofMargin(
        dof=len(zero),
        zero_max=float(zero.max(initial=0.0)),
        nonzero_min=float(nonzero.min(initial=1.0)),
        threshold=tau,
        gap=gap,
        near=near,
        method=method,
        count=count,
        dof_with_gap=int(np.sum(values < tau * gap)),
        counted=counted,
    )
