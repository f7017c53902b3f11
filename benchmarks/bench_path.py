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

Then the corrector's bound (``Settings.path.corrector_factorizations``, session 40) against
no bound, both in this process, on the hard paths kept in ``tests/data``: the sharp-angled
Miura-ori's child that folds further before it unfolds (``turn_back/``) and the two paths
along a second near flex (``near_flex/``): the trace's median time, steps and
factorisations each way, and the ratio.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bench_scale import timed  # this folder is on sys.path (a script)
from legacy_motion import legacy_folding_motion
from rigidfold.config import DEFAULTS
from rigidfold.deform import folding_motion
from rigidfold.develop import develop
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism.path import trace_path
from rigidfold.mesh import CreasePattern
from rigidfold.patterns import miura

DATA = Path(__file__).resolve().parents[1] / "tests/data"
RESCH = DATA / "origami_simulator/reschTriTessellation.svg"
HARD_PATHS = (
    "turn_back/miura_sharpangle_dome_0",
    "near_flex/paper1_shat_20",
    "near_flex/paper2_shat_32",
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
    for name in HARD_PATHS:
        print(bounded_row(name, args.repeat), flush=True)


def bounded_row(name: str, repeat: int) -> str:
    """One line: the trace of the DOF-1 shape ``tests/data/<name>.npz`` with the corrector's
    bound (the default) and without it."""
    data = np.load(DATA / f"{name}.npz")
    shape = CreasePattern(
        coords=data["coords"],
        faces=data["faces"].astype(np.int64),
        edges=data["edges"].astype(np.int64),
        fixed=data["fixed"],
    )
    dof = int(data["dof"])
    unbounded = DEFAULTS.with_(path_corrector_factorizations=0)
    t_bound, bound = timed(lambda: trace_path(shape, dof=dof), repeat)
    t_free, free = timed(lambda: trace_path(shape, dof=dof, settings=unbounded), repeat)
    return (
        f"{name} (V {shape.n_vertices}, DOF {dof}): bound "
        f"{DEFAULTS.path.corrector_factorizations} {t_bound:.2f} s median, "
        f"{bound.status.value}, {bound.steps} steps, {bound.factorizations} factorisations | "
        f"no bound {t_free:.2f} s median, {free.status.value}, {free.steps} steps, "
        f"{free.factorizations} factorisations | ratio {t_free / t_bound:.2f}"
    )


if __name__ == "__main__":
    main()
