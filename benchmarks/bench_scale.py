"""Benchmark of issue 19: build, solve and mechanism analysis of square grids up to 61 x 61.

Run with ``make bench`` (or ``python benchmarks/bench_scale.py [--grids 7,11,21,31,41,61]
[--repeat 3] [--no-solve | --solve-max V] [--dense-max 1681]``).

Cases: ``grid:NxN`` with ``--size 3x3`` (a 3 m square, every diagonal towards the centre,
:func:`rigidfold.patterns.grid`) lifted onto the dome, as in the issue's table. Per grid:

* build: ``case.problem(build_ipopt=True)`` (the elimination (7)-(11), CasADi's model and
  IPOPT), median of ``--repeat``;
* solve: one IPOPT solve of (6) from the lifted shape, no fixed crease, median of
  ``--repeat`` (``--no-solve`` skips it, ``--solve-max`` above that many vertices: the
  analyses then take the lifted shape);
* analysis: ``rigidfold.mechanism.analyze`` of the solution as ``generate`` runs it
  (method "auto"), the dense reference ("kinematic", up to ``--dense-max`` vertices) and the
  sparse method, each on a fresh copy of the shape (its topology caches rebuilt), median of
  ``--repeat``; the criterion S of the sparse analysis (``score_creases``); the DOF; where
  both ran, how far the sparse modes lie outside the span of the dense ones;
  ``--sparse-iterations`` sets ``Settings.mechanism.sparse_iterations`` for the analyses;
* memory: the peak resident set of a process that only reads the shape and runs the auto
  analysis (and of the build-and-solve process), from ``getrusage``, so that one method's
  peak does not hide another's.

Every measurement runs in a subprocess of its own, on one BLAS thread (as ``generate``). The
table is followed by the log-log slope of each column against V fitted over the grids from
121 to 1681 vertices (the issue's range) and over all grids, and by the ratio of the sparse
to the dense analysis time on the same shapes.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.generate.specs import case_from_specs
from rigidfold.mechanism import analyze
from rigidfold.selection import score_creases

COLUMNS = ("build", "solve", "auto", "dense", "sparse", "criteria")
SLOPE_RANGE = (121, 1681)


def grid_case(n: int):
    return case_from_specs("dome", f"grid:{n}x{n}", size="3x3")


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux


def timed(fn, repeat: int) -> tuple[float, object]:
    """Median seconds of ``repeat`` calls of ``fn`` and its last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def task_solve(n: int, repeat: int, solve: bool, coords_file: str) -> dict:
    """Build (and solve) grid n; the shape to analyse goes to ``coords_file`` (.npy)."""
    case = grid_case(n)
    build, problem = timed(lambda: case.problem(build_ipopt=True), repeat)
    row: dict = {"V": case.pattern.n_vertices, "E": case.pattern.n_edges, "build": build}
    coords = case.pattern.coords
    if solve:
        row["solve"], result = timed(problem.solve, repeat)
        row["converged"] = bool(result.converged)
        coords = result.pattern.coords
    np.save(coords_file, coords)
    row["solve_peak_mb"] = peak_mb()
    return row


def task_analyse(
    n: int, repeat: int, methods: list[str], coords_file: str, settings: Settings
) -> dict:
    """Analyse the shape in ``coords_file`` with each method; criterion S on the last one."""
    shape = grid_case(n).pattern.with_coords(np.load(coords_file))
    row: dict = {"base_mb": peak_mb()}
    mech, mechs = None, {}
    for method in methods:

        def run(method=method):
            return analyze(shape.with_coords(shape.coords), method=method, settings=settings)

        row[method], mech = timed(run, repeat)
        row[f"dof_{method}"] = mech.dof
        mechs[method] = mech
    if {"sparse", "kinematic"} <= set(mechs) and mechs["sparse"].dof == mechs["kinematic"].dof:
        H, ref = mechs["sparse"].H, mechs["kinematic"].H  # sparse modes outside the dense span
        row["outside"] = float(np.linalg.norm(H - ref @ (ref.T @ H), 2)) if H.size else 0.0
    if mech is not None and "sparse" in methods:
        with one_blas_thread():
            row["criteria"], _ = timed(lambda: score_creases(mech).of("s"), repeat)
    row["peak_mb"] = peak_mb()
    return row


def child(args: argparse.Namespace) -> None:
    n, repeat = args.task_grid, args.repeat
    with one_blas_thread():
        if args.task == "solve":
            row = task_solve(n, repeat, not args.no_solve, args.coords)
        else:
            settings = DEFAULTS.with_(sparse_iterations=args.sparse_iterations)
            row = task_analyse(n, repeat, args.task.split(","), args.coords, settings)
    print(json.dumps(row))


def run_child(task: str, n: int, args: argparse.Namespace, coords: str) -> dict:
    cmd = [sys.executable, __file__, "--task", task, "--task-grid", str(n)]
    solve = not args.no_solve and n * n <= args.solve_max
    cmd += ["--repeat", str(args.repeat), "--coords", coords] + (["--no-solve"] * (not solve))
    cmd += ["--sparse-iterations", str(args.sparse_iterations)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode:
        sys.exit(f"grid {n}, task {task} failed:\n{proc.stderr}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def measure(n: int, args: argparse.Namespace) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        coords = str(Path(tmp) / "coords.npy")
        row = run_child("solve", n, args, coords)
        auto = run_child("auto", n, args, coords)
        row.update(auto=auto["auto"], dof=auto["dof_auto"], analysis_peak_mb=auto["peak_mb"])
        row["analysis_base_mb"] = auto["base_mb"]
        methods = ["sparse"] + (["kinematic"] if row["V"] <= args.dense_max else [])
        both = run_child(",".join(methods), n, args, coords)
        row.update(sparse=both["sparse"], criteria=both["criteria"], dof_sparse=both["dof_sparse"])
        if "kinematic" in both:
            row.update(dense=both["kinematic"], dof_dense=both["dof_kinematic"])
        if "outside" in both:
            row["outside"] = both["outside"]
    return row


def fmt(value, width: int = 8, digits: int = 3) -> str:
    return f"{value:{width}.{digits}f}" if isinstance(value, float) else f"{'-':>{width}}"


def print_row(n: int, row: dict) -> None:
    dofs = {row["dof"], row["dof_sparse"], row.get("dof_dense", row["dof"])}
    ratio = row["sparse"] / row["dense"] if "dense" in row else None
    print(
        f"{n:>3} x {n:<3} {row['V']:>5} {row['E']:>6} "
        + " ".join(fmt(row.get(c)) for c in COLUMNS)
        + f" {fmt(ratio, 7, 3)} {row['dof']:>4}{'' if len(dofs) == 1 else ' (differs!)'}"
        + f" {row['analysis_peak_mb']:8.0f} {row['solve_peak_mb']:8.0f}",
        flush=True,
    )


def slope(rows: dict, column: str, lo: int, hi: int) -> float | None:
    pts = [(r["V"], r[column]) for r in rows.values() if lo <= r["V"] <= hi and column in r]
    if len(pts) < 2:
        return None
    v, t = np.log(np.array(pts, dtype=float)).T
    return float(np.polyfit(v, t, 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grids", default="7,11,21,31,41,61", help="vertices per side")
    parser.add_argument("--repeat", type=int, default=3, help="repetitions (median)")
    parser.add_argument("--no-solve", action="store_true", help="analyse the lifted shapes")
    parser.add_argument(
        "--solve-max", type=int, default=10**9, help="largest V to solve (lifted above)"
    )
    parser.add_argument(
        "--dense-max", type=int, default=1681, help="largest V for the dense reference"
    )
    parser.add_argument(
        "--sparse-iterations",
        type=int,
        default=DEFAULTS.mechanism.sparse_iterations,
        help="filterings of the sparse analysis's subspace (Settings.mechanism.sparse_iterations)",
    )
    parser.add_argument("--task", help=argparse.SUPPRESS)
    parser.add_argument("--task-grid", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--coords", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1, got {args.repeat}")
    if args.task:
        child(args)
        return
    try:
        grids = [int(g) for g in args.grids.split(",")]
    except ValueError:
        parser.error(f"--grids must be integers separated by commas, got {args.grids!r}")
    print(
        f"grid       {'V':>5} {'E':>6} "
        + " ".join(f"{c:>8}" for c in COLUMNS)
        + f" {'sp/dense':>7} {'DOF':>4} {'peak MB':>8} {'solve MB':>8}"
        + "   (seconds, medians)"
    )
    rows = {}
    for n in grids:
        rows[n] = measure(n, args)
        print_row(n, rows[n])
    lo, hi = SLOPE_RANGE
    for label, (a, b) in ((f"V {lo}..{hi}", SLOPE_RANGE), ("all grids", (0, 10**9))):
        parts = [f"{c} {s:.2f}" for c in COLUMNS if (s := slope(rows, c, a, b)) is not None]
        print(f"log-log slope vs V, {label}: " + ", ".join(parts))
    pairs = [(n, r["sparse"] / r["dense"]) for n, r in rows.items() if "dense" in r]
    print("sparse / dense analysis time: " + ", ".join(f"{n}x{n} {x:.3f}" for n, x in pairs))
    errors = [(n, r["outside"]) for n, r in rows.items() if "outside" in r]
    print(
        "sparse modes outside the dense span (2-norm): "
        + ", ".join(f"{n}x{n} {x:.1e}" for n, x in errors)
    )


if __name__ == "__main__":
    main()
