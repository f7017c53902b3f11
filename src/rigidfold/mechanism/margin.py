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
from rigidfold.mechanism.sparse import sparse_kernel
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
    """

    dof: int
    zero_max: float
    nonzero_min: float
    threshold: float
    gap: float
    near: int
    method: str

    @property
    def clear(self) -> bool:
        """Each side of the threshold at least ``gap`` away from it: no near-mechanism, and
        the count does not hang on the tolerance."""
        return (
            self.nonzero_min >= self.gap * self.threshold
            and self.zero_max <= self.threshold / self.gap
        )

    @property
    def message(self) -> str:
        """One sentence: the margin, and where it is not clear, what that means."""
        if self.clear:
            return (
                f"DOF {self.dof} is clear: the smallest non-zero singular value is "
                f"{self.nonzero_min:.2g} of the largest, the largest zero one {self.zero_max:.2g}"
            )
        return (
            f"DOF {self.dof} has no clear margin: {self.near} singular value"
            f"{'s' if self.near != 1 else ''} of the constraints "
            f"{'lie' if self.near != 1 else 'lies'} within a factor "
            f"{self.gap:g} of the rank threshold {self.threshold:g} (smallest non-zero "
            f"{self.nonzero_min:.2g}, largest zero {self.zero_max:.2g} of the largest): "
            "near-mechanisms, very soft modes of the built design"
        )

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
            "message": self.message,
        }


def dof_margin(
    pattern: CreasePattern, support_face: int, settings: Settings = DEFAULTS
) -> DofMargin:
    """The :class:`DofMargin` of ``pattern`` held by its triangle ``support_face``."""
    C = kinematics.constraint_matrix(pattern, support_face)
    n = C.shape[1]
    if pattern.n_vertices <= settings.mechanism.second_order_vertices:
        values = scipy.linalg.svdvals(C.toarray())
        # a wide matrix: the columns beyond the rows are kernel directions of value 0
        values = np.concatenate([values, np.zeros(max(n - len(values), 0))])
        method = "dense"
    else:
        _, ritz, _ = sparse_kernel(C, settings)
        top = float(np.sqrt(C.multiply(C).sum(axis=1).max()))
        values = np.concatenate([[top], np.sort(ritz)[::-1]])
        method = "sparse"
    values = values / values[0] if len(values) and values[0] > 0 else values
    tau = settings.mechanism.rank_tol
    zero = values[values <= tau]
    nonzero = values[values > tau]
    gap = settings.mechanism.dof_gap
    near = int(np.sum((values > tau / gap) & (values < tau * gap)))
    return DofMargin(
        dof=len(zero),
        zero_max=float(zero.max(initial=0.0)),
        nonzero_min=float(nonzero.min(initial=1.0)),
        threshold=tau,
        gap=gap,
        near=near,
        method=method,
    )
