"""Benchmark of the pinned numerics: their cost against the machine's native ones, same run.

Run with ``python benchmarks/bench_numerics.py [--repeat 3] [--inner 7] [--skip-generate]``.

The script starts children of itself (``sys.executable``), one per mode and round, the modes
alternating over ``--repeat`` rounds so that drifts in the machine's load hit both alike:

* pinned: ``rigidfold.runtime.numerics.pinned_environ(os.environ)`` (OpenBLAS Prescott kernel and
  L2 size, NumPy's baseline SIMD, glibc's libm without its FMA/AVX variants: the child is
  *started* with them, as the command line restarts itself);
* native: ``RIGIDFOLD_NUMERICS=native`` and none of the pinning variables.

Each child runs on one BLAS thread (as ``generate``) and reports, as one JSON line:

* solve: one IPOPT solve of (6) on pattern 1 (Bezier seed 0) from the lifted shape with no
  fixed crease (the first solve of ``generate``, as ``bench_optimize.py``), median of
  ``--inner`` solves of the same built problem; the model build is not timed;
* generate: a whole ``generate`` of the demo case (``case_from_specs("bezier", "1", seed=1)``,
  criterion S-hat, seed 1, no Step 9), with its number of solves and the time per solve
  (the whole run's and the solves' own) and IPOPT iterations per solve, since the two modes
  may take different paths;
* analysis 41: ``rigidfold.mechanism.analyze`` (method "auto", the sparse analysis) of the
  lifted 41 x 41 grid on the dome (as ``bench_scale.py``), on a fresh copy of the shape,
  median of ``--inner``;
* the status and the canary of ``rigidfold.runtime.numerics.numeric_environment()``.

The parent prints, per metric, the median over the rounds of each mode and the ratio
pinned / native, then both statuses and canaries (they differ on a CPU with AVX2 and FMA).
The parent itself imports only ``rigidfold.runtime.numerics`` (not NumPy).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

from rigidfold.runtime.numerics import OPT_OUT_ENV, pinned_environ

MODES = ("pinned", "native")
PIN_VARIABLES = (
    "OPENBLAS_CORETYPE",
    "OPENBLAS_L2_SIZE",
    "NPY_ENABLE_CPU_FEATURES",
    "NPY_DISABLE_CPU_FEATURES",
    "GLIBC_TUNABLES",
)
METRICS = (  # key, label, unit scale, format
    ("solve_s", "solve (6), pattern 1 [ms]", 1e3, "9.1f"),
    ("solve_iterations", "  its IPOPT iterations", 1, "9.0f"),
    ("generate_s", "generate, demo [s]", 1, "9.3f"),
    ("n_solves", "  its solves", 1, "9.0f"),
    ("per_solve_s", "  run time per solve [ms]", 1e3, "9.1f"),
    ("gen_solve_s", "  solve time per solve [ms]", 1e3, "9.1f"),
    ("gen_iterations", "  IPOPT iterations per solve", 1, "9.1f"),
    ("analysis_41_s", "analysis 41 x 41 [ms]", 1e3, "9.1f"),
)


def child_environ(mode: str) -> dict[str, str]:
    base = {k: v for k, v in os.environ.items() if k != OPT_OUT_ENV}
    if mode == "pinned":
        return pinned_environ(base)
    native = {k: v for k, v in base.items() if k not in PIN_VARIABLES}
    native[OPT_OUT_ENV] = "native"
    return native


def child(args: argparse.Namespace) -> None:
    """Measure in this process (started with the numerics of ``args.child``)."""
    # imported here: the parent must not load NumPy, and rigidfold must come first
    from bench_scale import timed as median_time  # this folder is on sys.path (a script)
    from rigidfold.config import one_blas_thread
    from rigidfold.generate import generate
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.mechanism import analyze
    from rigidfold.runtime.numerics import numeric_environment

    env = numeric_environment()
    row: dict = {"mode": args.child, "status": env.status.value, "canary": env.canary}
    row["unpinned"] = list(env.unpinned)
    with one_blas_thread():
        problem = case_from_specs("bezier", "1", seed=0).problem(build_ipopt=True)
        row["solve_s"], result = median_time(problem.solve, args.inner)
        row["solve_iterations"] = result.iterations
        row["solve_converged"] = bool(result.converged)
        if not args.skip_generate:
            case = case_from_specs("bezier", "1", seed=1)
            t0 = time.perf_counter()
            run = generate(case, criterion="shat", seed=1)
            row["generate_s"] = time.perf_counter() - t0
            s = run.to_dict()
            row["n_solves"] = s["n_solves"]
            row["per_solve_s"] = row["generate_s"] / max(s["n_solves"], 1)
            row["gen_solve_s"] = s["time_s"]["solve"] / max(s["n_solves"], 1)
            row["gen_iterations"] = sum(a.iterations for a in run.attempts) / max(s["n_solves"], 1)
            row["path"] = f"DOF {s['initial_dof']} -> {s['final_dof']}, N_lock {s['n_lock']}"
        shape = case_from_specs("dome", "grid:41x41", size="3x3").pattern
        row["analysis_41_s"], mech = median_time(
            lambda: analyze(shape.with_coords(shape.coords)), args.inner
        )
        row["analysis_41_dof"] = mech.dof
    print(json.dumps(row))


def run_child(mode: str, args: argparse.Namespace) -> dict:
    cmd = [sys.executable, __file__, "--child", mode, "--inner", str(args.inner)]
    cmd += ["--skip-generate"] * args.skip_generate
    proc = subprocess.run(cmd, env=child_environ(mode), capture_output=True, text=True, check=False)
    if proc.returncode:
        sys.exit(f"{mode} child failed:\n{proc.stderr}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def ratio(a: float | None, b: float | None) -> str:
    return f"{a / b:8.3f}" if a is not None and b else f"{'-':>8}"


def report(rows: dict[str, list[dict]]) -> None:
    def med(mode: str, key: str) -> float | None:
        values = [r[key] for r in rows[mode] if key in r]
        return statistics.median(values) if values else None

    print(f"\n{'metric (median over rounds)':<30} {'pinned':>9} {'native':>9} {'pin/nat':>8}")
    for key, label, scale, spec in METRICS:
        p, n = med("pinned", key), med("native", key)
        if p is None and n is None:
            continue
        cells = [f"{v * scale:{spec}}" if v is not None else f"{'-':>9}" for v in (p, n)]
        print(f"{label:<30} {cells[0]} {cells[1]} {ratio(p, n)}")
    for mode in MODES:
        statuses = sorted({r["status"] for r in rows[mode]})
        canaries = sorted({r["canary"] for r in rows[mode]})
        paths = sorted({r["path"] for r in rows[mode] if "path" in r})
        dofs = sorted({r["analysis_41_dof"] for r in rows[mode]})
        print(
            f"{mode:<7} status {'/'.join(statuses)}, canary {'/'.join(canaries)}"
            + (f", generate {'; '.join(paths)}" if paths else "")
            + f", DOF 41 x 41 {'/'.join(map(str, dofs))}"
        )
        unpinned = sorted({u for r in rows[mode] for u in r["unpinned"]})
        if mode == "pinned" and unpinned:
            print("  not pinned: " + "; ".join(unpinned))
    if {r["canary"] for r in rows["pinned"]} & {r["canary"] for r in rows["native"]}:
        print("note: the same canary in both modes (a CPU without AVX2/FMA, or nothing pinned)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="rounds of (pinned, native)")
    parser.add_argument("--inner", type=int, default=7, help="timed repeats in a child (median)")
    parser.add_argument("--skip-generate", action="store_true", help="no generate of the demo")
    parser.add_argument("--child", choices=MODES, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.repeat < 1 or args.inner < 1:
        parser.error("--repeat and --inner must be >= 1")
    if args.child:
        child(args)
        return
    rows: dict[str, list[dict]] = {mode: [] for mode in MODES}
    t0 = time.perf_counter()
    for k in range(args.repeat):
        order = MODES if k % 2 == 0 else MODES[::-1]  # alternate which mode runs first
        for mode in order:
            row = run_child(mode, args)
            rows[mode].append(row)
            parts = [f"{key} {row[key]:.4g}" for key, *_ in METRICS if key in row]
            print(f"round {k + 1} {mode:<6} " + ", ".join(parts), flush=True)
    report(rows)
    print(f"({time.perf_counter() - t0:.0f} s in all)")


if __name__ == "__main__":
    main()
