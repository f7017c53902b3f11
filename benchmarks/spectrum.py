"""The spectrum of a shape's kinematic constraints: is there a gap at the DOF count's bound?

The search counts a shape's DOF as the singular values of its constraint matrix C
(:func:`rigidfold.mechanism.kinematics.constraint_matrix`, rows of unit norm) below a bound
relative to the largest: ``mechanism_rank_tol`` (1e-9, the exact mechanisms) or, with the
gap count, ``dof_gap`` times that (1e-6: near-mechanisms count). The count means something
where the singular values leave a gap around the bound; on a large, nearly flat grid they
may run evenly across it, and then any single fix moves the count by chance (session 27,
``docs/broad_set.md``).

Run with ``python benchmarks/spectrum.py SHAPE.fold [SHAPE.fold ...]`` (the solutions a run
writes): for each shape, a dense SVD of C (values only; some 30 s for 1,681 vertices) and the
number of values below each decade from 1e-12 to 1e-3 of the largest, then the smallest
values past the exact kernel (log10).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.linalg

from rigidfold.io.fold import pattern_from_fold
from rigidfold.mechanism import kinematics

DECADES = tuple(10.0**k for k in range(-12, -2))


def relative_values(path: str) -> tuple[np.ndarray, tuple[int, int], float]:
    """The singular values of a shape's constraints over the largest, (n,) float64 with the
    columns beyond the rows counted as zeros; C's shape; the seconds of the SVD."""
    shape = pattern_from_fold(path)
    C = kinematics.constraint_matrix(shape, 0)
    t0 = time.perf_counter()
    values = scipy.linalg.svdvals(C.toarray())
    seconds = time.perf_counter() - t0
    values = np.concatenate([values, np.zeros(max(C.shape[1] - len(values), 0))])
    return values / values[0], C.shape, seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("shapes", nargs="+", help="FOLD files of shapes (a run's solutions)")
    parser.add_argument("--show", type=int, default=40, help="smallest values shown past 1e-9")
    args = parser.parse_args()
    for path in args.shapes:
        values, size, seconds = relative_values(path)
        print(f"{path}: C {size[0]} x {size[1]}, SVD {seconds:.1f} s")
        print("  below " + "  ".join(f"{d:.0e}: {int(np.sum(values < d))}" for d in DECADES))
        past = np.sort(values[values >= 1e-9])[: args.show]
        print("  next (log10): " + " ".join(f"{v:.1f}" for v in np.log10(past)))


if __name__ == "__main__":
    main()
