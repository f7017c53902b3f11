"""Benchmark of the first-order analysis behind the second-order test (session 47): the
dense SVD of the constraint matrix against the sparse smallest singular values of each side.

Run with ``python benchmarks/bench_second_order.py [--repeat 3] [--cases 21x21,25x25]``.

The building-size grids of the broad set (``benchmarks/broad_cases.py``: 21 x 21 on the HP,
10 m x 10 m, seed 5; 25 x 25 on the Bezier surface, 8 m x 8 m, seed 31) are solved once
(the run's first shape, Steps 2-5 with the defaults); the shape is then analysed with 0,
a quarter, a half and all but five of its DOF taken away by random fixed creases (fixed on
the solved geometry, not re-solved: the matrices have a run's sizes and self-stresses).
For each: the DOF, :func:`rigidfold.mechanism.second_order.first_order` dense and sparse
(``Settings.mechanism.sparse_analysis_vertices`` moved to force each; median of
``--repeat`` calls in this process, and their ratio), the sine of the largest principal
angle between the two methods' flexes and self-stresses, and whether the second-order
forecast (:class:`~rigidfold.mechanism.second_order.ChildForecast`) of ``--children`` free
creases is the same both ways. In a generation run this analysis is made for every checked
solution and every shape whose children get the deployability check; the profile of the
25 x 25 run (``python -m cProfile -m rigidfold generate --surface bezier --pattern
grid:25x25 --seed 31 --size 8x8 --lookahead --no-deform --time-limit 180``) spent 72 s of
its 184 s in the dense SVD before this change.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

from bench_scale import timed  # this folder is on sys.path (a script)
from rigidfold.config import DEFAULTS
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.mechanism.second_order import ChildForecast, first_order
from rigidfold.mesh import CreasePattern

CASES = {
    "21x21": ("hp", "grid:21x21", 5, "10x10"),
    "25x25": ("bezier", "grid:25x25", 31, "8x8"),
}
DENSE = DEFAULTS.with_(sparse_analysis_vertices=10**6)
SPARSE = DEFAULTS.with_(sparse_analysis_vertices=3)


def first_shape(name: str) -> CreasePattern:
    """The solved first shape of a building-size case."""
    surface, pattern, seed, size = CASES[name]
    case = case_from_specs(surface, pattern, seed=seed, size=size)
    run = generate(case, target_dof=10**6)
    assert run.solutions, f"{name}: the first solve found no shape"
    return run.solutions[0].result.pattern


def with_fixed(shape: CreasePattern, dof: int, keep: int, rng: np.random.Generator):
    """``shape`` with random free creases fixed until about ``keep`` DOF are left."""
    free = [int(c) for c in shape.interior_edges if not shape.fixed[c]]
    fixed = shape.fixed.copy()
    fixed[rng.choice(free, max(dof - keep, 0), replace=False)] = True
    return shape.with_fixed(fixed)


def spanned(P: np.ndarray, Q: np.ndarray) -> float:
    """The sine of the largest principal angle between the spans of P and Q."""
    if P.shape[1] == 0 or P.shape != Q.shape:
        return float("nan") if P.shape != Q.shape else 0.0
    cosines = np.linalg.svd(np.linalg.qr(P)[0].T @ np.linalg.qr(Q)[0], compute_uv=False)
    return float(np.sqrt(max(0.0, 1.0 - cosines.min() ** 2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cases", default="21x21,25x25")
    parser.add_argument("--children", type=int, default=100, help="creases forecast each way")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    ratios = []
    for name in args.cases.split(","):
        shape = first_shape(name)
        dof0 = analyze(shape, support_face=0).dof
        print(f"{name}: V {shape.n_vertices}, first shape DOF {dof0}")
        for keep in (dof0, 3 * dof0 // 4, dof0 // 2, 5):
            s = with_fixed(shape, dof0, keep, rng)
            dof = analyze(s, support_face=0).dof
            td, dense = timed(lambda s=s, dof=dof: first_order(s, 0, dof, DENSE), args.repeat)
            ts, sparse = timed(lambda s=s, dof=dof: first_order(s, 0, dof, SPARSE), args.repeat)
            ratios.append(td / ts)
            same = "-"
            if dof >= 2:
                fa = ChildForecast.at(s, 0, dof, DENSE)
                fb = ChildForecast.at(s, 0, dof, SPARSE)
                free = [int(c) for c in s.interior_edges if not s.fixed[c]][: args.children]
                a = [fa.rigid((c,)) for c in free]
                b = [fb.rigid((c,)) for c in free]
                same = (
                    f"{sum(x == y for x, y in zip(a, b, strict=True))}/{len(free)} ({sum(a)} rigid)"
                )
            print(
                f"  DOF {dof:3d}, {dense.stresses.shape[1]:3d} self-stresses: dense "
                f"{td:6.2f} s, sparse {ts:5.2f} s, ratio {td / ts:5.1f}; principal angle "
                f"flexes {spanned(dense.flexes, sparse.flexes):.1e}, self-stresses "
                f"{spanned(dense.stresses, sparse.stresses):.1e}; same forecast {same}"
            )
    print(f"median ratio dense / sparse: {statistics.median(ratios):.1f}")


if __name__ == "__main__":
    main()
