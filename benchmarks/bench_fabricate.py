"""Benchmark of thick panels (issue 31): ``rigidfold fabricate`` of an 11 x 11 design.

Run with ``python benchmarks/bench_fabricate.py [--repeat 3] [--thickness 0.02]``.

Generates the paper's pattern 11 (11 x 11 vertices, 3 m x 3 m) on the Bezier surface of seed
1 down to DOF 1 (S-hat, look-ahead, the deployability check; not timed), then times, median
over ``--repeat`` runs in this process: the folding motion of the design
(:func:`rigidfold.fabricate.design_motion`: the traced path sampled so that no hinge turns
more than ``fabricate_frame_step`` between frames), and the thick panels with the check of
every pair of solids over the whole motion (:func:`rigidfold.fabricate.fabricate_panels`,
no thinner tries: ``search=False``). Target: the two together under 10 s.
"""

from __future__ import annotations

import argparse

from bench_scale import timed  # this folder is on sys.path (a script)
from rigidfold.case import make_case
from rigidfold.develop import develop
from rigidfold.fabricate import Panels, design_motion, fabricate_panels
from rigidfold.generate import generate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--thickness", type=float, default=0.02)
    args = parser.parse_args()
    case = make_case("bezier", "11", seed=1)
    run = generate(case, criterion="shat", seed=1, lookahead=True)
    final = run.final
    assert final is not None
    pattern = final.result.pattern
    panels = Panels(pattern, develop(pattern).coords2d, "bottom")
    t_motion, (motion, source) = timed(lambda: design_motion(panels), args.repeat)
    assert motion is not None, source
    t_fab, fab = timed(
        lambda: fabricate_panels(panels, motion, args.thickness, search=False), args.repeat
    )
    c = fab.clearance
    print(
        f"pattern 11 (V {pattern.n_vertices}, {panels.n} panels, {panels.n_hinges} hinges), "
        f"{args.thickness * 1e3:g} mm, median of {args.repeat}:"
    )
    print(f"  motion      {t_motion:7.2f} s  ({motion.n_frames} frames: {source})")
    print(
        f"  fabricate   {t_fab:7.2f} s  ({fab.status.value}; {c.distance_queries} distance "
        f"queries, {c.midpoints} midpoints, {fab.relief_rounds} relief rounds)"
    )
    total = t_motion + t_fab
    print(f"  total       {total:7.2f} s  (target < 10 s: {'met' if total < 10 else 'NOT met'})")


if __name__ == "__main__":
    main()
