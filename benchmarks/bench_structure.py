"""Benchmark of ``rigidfold structure`` on an 11 x 11 design (target: under 10 s).

Run with ``python benchmarks/bench_structure.py [--repeat 3]``.

The design is tests/data/dome_sym_dof1.fold (121 vertices, 200 triangles, DOF 1). Timed,
median over ``--repeat`` runs: the whole workflow behind the command (read, ``--supports
auto``, shell model in OpenSees under self-weight and 0.5 kPa of snow, 3 natural
frequencies, structure.json and structure.png) with free hinges and with hinges of
1000 N m/rad per m, its support search alone, and the geometrically nonlinear analysis
(``--nonlinear``, hinges of 1000 N m/rad per m, timed once: it is not under the target).

Then the README's 12 m x 8 m roof (tests/data/roof_12x8_dof1.fold: ``rigidfold generate
--pattern grid:9x6 --size 12x8 --surface expr --expr "0.06*x*(12-x)/6 + 0.05*y*(8-y)"
--no-deform``, its final design, 54 vertices, DOF 1): the command with ``--supports auto``
under self-weight alone (18 mm plywood, 3 frequencies), the reactions' balance, and each
support removed in turn, reported as a mechanism (first- and second-order check).

Last, ``--supports service`` (auto's pins, then more where the design deflects most until
L/250 is met) on the roof and on the 11 x 11 design with free hinges under self-weight:
the pins, the analyses of the search, the largest displacement, the wall time (once each).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from rigidfold.io import read_fold
from rigidfold.pipeline.workflows import structure
from rigidfold.structure import (
    Service,
    StructureOptions,
    Supports,
    Uniform,
    auto_supports,
    check_supports,
    support_candidates,
)

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
DESIGN = DATA / "dome_sym_dof1.fold"
ROOF = DATA / "roof_12x8_dof1.fold"


def timed(repeat: int, run) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    pattern = read_fold(DESIGN).pattern
    t_sup, rigidity = timed(
        args.repeat, lambda: auto_supports(pattern, support_candidates(pattern))
    )
    with tempfile.TemporaryDirectory() as tmp:
        for nonlinear, k in ((False, 0.0), (False, 1000.0), (True, 1000.0)):
            t, run = timed(
                1 if nonlinear else args.repeat,
                lambda k=k, nonlinear=nonlinear: structure(
                    DESIGN,
                    Path(tmp) / "out",
                    StructureOptions(
                        loads=(Uniform(0.5),),
                        hinge_stiffness=k,
                        nonlinear=nonlinear,
                        modes=0 if nonlinear else 3,
                    ),
                    overwrite=True,
                ),
            )
            c = run.check
            print(
                f"{'nonlinear' if nonlinear else 'linear   '}, hinges {k:g} N m/rad/m: "
                f"{c.status}, "
                f"{len(c.rigidity.supports.pinned)} supports, {c.mesh.n_elements} shells, "
                f"max displacement {c.max_displacement * 1e3:.3g} mm, balance "
                f"{c.balance_error:.1e}; median {t:.2f} s over "
                f"{1 if nonlinear else args.repeat}",
                flush=True,
            )
    print(
        f"support search (auto, {len(rigidity.supports.pinned)} of "
        f"{len(pattern.boundary_vertices)} boundary vertices): median {t_sup:.2f} s"
    )
    print("target: the structure command on an 11 x 11 design under 10 s")
    roof(args.repeat)
    service()


def service() -> None:
    """--supports service on the roof and the 11 x 11 design (free hinges, self-weight)."""
    with tempfile.TemporaryDirectory() as tmp:
        for name, path in (("roof", ROOF), ("11 x 11", DESIGN)):
            t, run = timed(
                1,
                lambda path=path: structure(
                    path,
                    Path(tmp) / "s",
                    StructureOptions(supports=Service(), modes=0),
                    overwrite=True,
                ),
            )
            c = run.check
            g = c.growth
            print(
                f"{name}, --supports service: {c.status}, pins {len(g.rigid)} for rigidity + "
                f"{len(g.added)} for the deflection of {g.candidates} candidates, "
                f"{len(g.trail)} analyses; largest displacement {c.max_displacement * 1e3:.4g} "
                f"mm (limit {c.allowed_displacement * 1e3:.3g} mm; auto's pins: "
                f"{g.trail[0][3] * 1e3:.4g} mm); {t:.2f} s"
            )


def roof(repeat: int) -> None:
    """The 12 m x 8 m roof on auto supports under self-weight; each support removed."""
    with tempfile.TemporaryDirectory() as tmp:
        t, run = timed(repeat, lambda: structure(ROOF, Path(tmp) / "roof", overwrite=True))
    c = run.check
    pinned = c.rigidity.supports.pinned
    print(
        f"roof 12 m x 8 m ({c.pattern.n_vertices} vertices, DOF {c.rigidity.dof}), auto "
        f"supports {pinned.tolist()} ({c.rigidity.stability}), self-weight "
        f"{-c.total_load[2] / 1e3:.4g} kN, reactions balance to {c.balance_error:.1e}, "
        f"{c.mesh.n_elements} shells, largest displacement {c.max_displacement * 1e3:.4g} mm "
        f"({c.status}); median {t:.2f} s over {repeat}"
    )
    for v in pinned:
        t0 = time.perf_counter()
        left = check_supports(c.pattern, Supports(np.setdiff1d(pinned, [v])))
        print(f"  without {v}: {left.stability}: {left.detail} ({time.perf_counter() - t0:.2f} s)")


if __name__ == "__main__":
    main()
