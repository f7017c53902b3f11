"""Benchmark of the folding-path tracer (issue 29) against the tracer it replaced.

Run with ``python benchmarks/bench_path.py [--repeat 3] [--legacy-max 250]``.

Times, median over ``--repeat`` runs in this process, the folding motion of a design
(:func:`rigidfold.deform.folding_motion`: the path traced from the design to flat by sparse
continuation, then the frames) and the old dense tracer (``benchmarks/legacy_motion.py``) on
the same shapes, and prints the ratio. Shapes:

* the final design (DOF 1) of a drawn crease pattern of about 200 vertices: Resch's triangle
  tessellation of Origami Simulator (243 vertices) on the HP, generated here (seed 7, S-hat,
  look-ahead, the deployability check); target <= 2 s for its check;
* folded Miura-ori of 11 x 11, 21 x 21 and 41 x 41 vertices (DOF 1, quads rigid); target
  <= 30 s for 41 x 41. The old tracer runs on shapes of at most ``--legacy-max`` vertices
  (its dense least squares on 41 x 41 take far longer than the target).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from bench_scale import timed  # this folder is on sys.path (a script)
from legacy_motion import legacy_folding_motion
from rigidfold.deform import folding_motion
from rigidfold.develop import develop
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.patterns import miura

RESCH = (
    Path(__file__).resolve().parents[1] / "tests/data/origami_simulator/reschTriTessellation.svg"
)


def shapes():
    case = case_from_specs("hp", str(RESCH), seed=7)
    run = generate(case, criterion="shat", seed=7, lookahead=True)
    final = run.final
    assert final is not None
    yield f"Resch on the HP, final design (V {final.result.pattern.n_vertices}, DOF "
    yield final.result.pattern, final.mechanism.dof
    for n in (10, 20, 40):
        shape = miura(n, n)
        yield f"Miura-ori {n + 1} x {n + 1} (V {shape.n_vertices}, DOF "
        yield shape, 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--legacy-max", type=int, default=250)
    args = parser.parse_args()
    items = iter(shapes())
    for label in items:
        shape, dof = next(items)
        flat = develop(shape).coords2d
        t_new, motion = timed(
            lambda s=shape, f=flat, d=dof: folding_motion(s, f, dof=d), args.repeat
        )
        line = (
            f"{label}{dof}): new {t_new:.2f} s median, {motion.status.value}, "
            f"{motion.path['steps']} steps, max |dl|/l {motion.max_length_error:.1e}"
        )
        if shape.n_vertices <= args.legacy_max:
            t_old, old = timed(lambda s=shape, f=flat: legacy_folding_motion(s, f), args.repeat)
            line += (
                f" | old {t_old:.2f} s median, {'ok' if old.traced else 'failed'}, max |dl|/l "
                f"{old.max_length_error:.1e} | ratio old/new {t_old / t_new:.1f}"
            )
        else:
            line += " | old: not run (--legacy-max)"
        print(line, flush=True)


if __name__ == "__main__":
    main()
