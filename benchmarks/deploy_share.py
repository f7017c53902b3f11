"""The share of generate runs that reach DOF 1 with a deployable design, before and after
the deployability check (issue 29).

Run with ``python benchmarks/deploy_share.py [--jobs 2] [--out FILE.jsonl]``.

``--cases failing`` runs the 7 cases whose runs with the check stopped above DOF 1 with "no
deployable solution" before backtracking (session 15); ``--backtrack 0,3`` runs the check
with each of these ``Settings.generation.backtrack_max`` (0: no backtracking) and
``--no-paper`` leaves out the runs with the paper's Step 5.

Each case runs twice with S-hat and the look-ahead: with the paper's Step 5
(``deploy_check=False``; the final design's folding path is traced afterwards, as delivered)
and with the deployability check (rigidfold's default). A run *deploys* when it reaches its
target DOF 1 and the final design's folding path reaches the flat state (every fold angle
below ``Settings.path.flat_tol``, every length kept). Cases: the crease patterns of Origami
Simulator drawn by users (waterbomb, Resch's triangle tessellation, Miura-ori; tests/data)
on the dome, the HP and a Bezier surface; the paper's patterns 1 and 2 on ten Bezier surfaces
each; the paper's pattern 11 and a 9 x 9 grid on the dome and the HP: 33 cases. Prints one
line per run, then the shares and the median times.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "origami_simulator"
DRAWN = ("waterbomb.svg", "reschTriTessellation.svg", "miura-ori.svg")


CASES = ("all", "drawn", "paper", "grids", "failing")
FAILING = (
    ("bezier", "2", 110),
    ("dome", str(DATA / "miura-ori.svg"), 7),
    ("bezier", str(DATA / "miura-ori.svg"), 7),
    ("dome", str(DATA / "reschTriTessellation.svg"), 7),
    ("dome", "11", 0),
    ("hp", str(DATA / "waterbomb.svg"), 7),
    ("bezier", str(DATA / "waterbomb.svg"), 7),
)
"""The cases whose runs with the check (and no backtracking) stopped above DOF 1."""


def cases(which: str = "all") -> list[tuple[str, str, int]]:
    """The cases of ``which``: the drawn patterns, the paper's 1 and 2 on Bezier surfaces,
    pattern 11 and the 9 x 9 grid on the dome and the HP, or all; or the failing ones."""
    if which == "failing":
        return list(FAILING)
    out = []
    if which in ("all", "drawn"):
        out += [(s, str(DATA / f), 7) for f in DRAWN for s in ("dome", "hp", "bezier")]
    if which in ("all", "paper"):
        out += [("bezier", p, seed) for p in ("1", "2") for seed in range(101, 111)]
    if which in ("all", "grids"):
        out += [(s, p, 0) for p in ("11", "grid:9x9") for s in ("dome", "hp")]
    return out


def _name(case: tuple[str, str, int]) -> str:
    surface, pattern, seed = case
    return f"{surface}:{Path(pattern).name}:{seed}"


def run(case: tuple[str, str, int], deploy: bool, backtrack: int | None = None) -> dict:
    """One run of ``case``, with the check (``deploy``) and ``backtrack_max`` = ``backtrack``
    (None: the default) or with the paper's Step 5."""
    from rigidfold.config import DEFAULTS
    from rigidfold.generate import Stop, generate
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.mechanism.path import trace_path

    surface, pattern, seed = case
    settings = DEFAULTS if backtrack is None else DEFAULTS.with_(backtrack_max=backtrack)
    t0 = time.perf_counter()
    built = case_from_specs(surface, pattern, seed=seed, settings=settings)
    gen = generate(built, criterion="shat", seed=seed, lookahead=True, deploy_check=deploy)
    final = gen.final
    if final is not None and final.path is None:
        final.path = trace_path(final.result.pattern, dof=final.mechanism.dof)
    deploys = final is not None and final.path is not None and final.path.deploys
    return {
        "surface": surface,
        "pattern": Path(pattern).name,
        "seed": seed,
        "deploy_check": deploy,
        "backtrack_max": settings.generation.backtrack_max if deploy else None,
        "stop": gen.stop_reason,
        "final_dof": None if final is None else final.mechanism.dof,
        "reached": gen.stop is Stop.TARGET_REACHED,
        "deploys": bool(deploys),
        "dof1_deploys": bool(gen.stop is Stop.TARGET_REACHED and deploys),
        "path_status": None if final is None or final.path is None else final.path.status.value,
        "N_lock": gen.n_lock,
        "N_path": gen.n_path,
        "N_backtrack": gen.n_backtrack,
        "solves": len(gen.attempts),
        "time_s": time.perf_counter() - t0,
        "path_s": sum(a.path_time for a in gen.attempts),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--cases", choices=CASES, default="all")
    parser.add_argument(
        "--backtrack",
        default=None,
        help="comma-separated backtrack_max values for the runs with the check (default: "
        "Settings' default)",
    )
    parser.add_argument("--no-paper", action="store_true", help="only the runs with the check")
    parser.add_argument(
        "--only",
        default=None,
        metavar="TEXT",
        help="only the cases whose 'surface:pattern:seed' holds TEXT (e.g. dome:miura)",
    )
    args = parser.parse_args()
    backtracks = [None] if args.backtrack is None else [int(b) for b in args.backtrack.split(",")]
    modes = ([] if args.no_paper else [(False, None)]) + [(True, b) for b in backtracks]
    chosen = [c for c in cases(args.cases) if args.only is None or args.only in _name(c)]
    work = [(c, d, b) for c in chosen for d, b in modes]
    rows = []
    with ProcessPoolExecutor(args.jobs) as pool:
        for row in pool.map(run, *zip(*work, strict=True)):
            rows.append(row)
            print(json.dumps(row), flush=True)
            if args.out:
                with args.out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
    for deploy, backtrack in modes:
        sel = [
            r
            for r in rows
            if r["deploy_check"] is deploy
            and (backtrack is None or r["backtrack_max"] == backtrack)
        ]
        share = sum(r["dof1_deploys"] for r in sel) / len(sel)
        name = (
            f"deployability check, backtrack_max {sel[0]['backtrack_max']}"
            if deploy
            else "paper's Step 5"
        )
        print(
            f"{name}: {sum(r['dof1_deploys'] for r in sel)}/{len(sel)} runs reach DOF 1 with a "
            f"deployable design ({100 * share:.0f} %), DOF 1 reached "
            f"{sum(r['reached'] for r in sel)}, median run "
            f"{statistics.median(r['time_s'] for r in sel):.1f} s, "
            f"N_path {sum(r['N_path'] for r in sel)}, "
            f"retractions {sum(r['N_backtrack'] for r in sel)}"
        )


if __name__ == "__main__":
    main()
