"""Deployable anywhere, in minutes (issue 40): the share of runs on drawn patterns and a roof
grid that end at DOF 1 with a design that deploys, the time and the solves per run, and why
every rejected candidate was rejected; in each mode of :data:`MODES` (rigidfold's defaults,
``after``; the search without the restart with the fold limit, ``before``; without the
second-order test, ``no-second-order``; every solve bounded, ``bounded``), in the same
process.

Run with ``python benchmarks/deploy_anywhere.py [--jobs 2] [--out FILE.jsonl] [--only
TEXT[,TEXT...]] [--modes after,batch-off,before,no-second-order]``. Every run uses S-hat with the
look-ahead and the deployability check, as the README recommends, and ``--time-limit`` (180
s for a drawn pattern, 420 s for the roof; ``--limit S`` for all): a run that hits it ends
with its best design, counted as not reaching DOF 1. Each run's wall and CPU seconds are
printed: on a machine shared with other jobs, the CPU time is the run's own.

Cases: Origami Simulator's patterns in tests/data/origami_simulator (waterbomb, Huffman's
waterbomb, Resch's triangles, Miura-ori, Lang's wedge, the polygami cross, the sharp-angle
Miura-ori, the strip of squares) on the dome, the HP and the Bezier surface of seed 7; and a
15 x 9 grid on a 12 m x 8 m roof (a barrel vault with a cross fall) with the criterion S.

Each line: the case, whether it reached DOF 1 and deploys, whether the final design's DOF
has a clear gap (``clear_gap``; ``near`` and ``nonzero_min`` of its margin), its DOF, the
solves, the solves per DOF removed, the seconds, and the rejected candidates by cause
(``lock``, ``exceed``, ``second_order_rigid``, and for paths that do not reach the flat state
their status: ``turned_back``, ``stops_short``, ``collision``, ``max_steps``, ``stalled`` (the
tracer's failure), ``zero_dof``; ``dead_end``: retracted by backtracking), its seconds by
part (``time_split``: the run's ``time_s``) and the candidates' trace seconds by how each
trace ended (``path_s``: ``flat`` for the paths that deploy). At the end, per
mode: the share (and of it, those with a clear gap), the median time and the median solves
per DOF removed, the causes summed, and the runs' seconds in all and by part; where the
forecast ran, how its calls matched what the solve and trace found.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "origami_simulator"
DRAWN = (
    "waterbomb.svg",
    "huffmanWaterbomb.svg",
    "reschTriTessellation.svg",
    "miura-ori.svg",
    "langWedgeDoubleFaced.svg",
    "polygamiCross.svg",
    "miura_sharpangle.svg",
    "test.svg",
)
ROOF = {
    "surface": "expr",
    "pattern": "grid:15x9",
    "size": "12x8",
    "expr": "0.08*x*(12-x)/6 + 0.02*(y-4)**2 - 0.05*y",
}
MODES: dict[str, dict] = {
    "after": {},
    "before": {"fold_limits": ()},
    "no-second-order": {"second_order": False},
    "bounded": {"rho_max": math.radians(120.0)},
    "batch-auto": {},
    "batch-off": {},
    "count-threshold": {"dof_count": "threshold"},
    "count-gap": {"dof_count": "gap"},
    "backtrack-10": {"backtrack_max": 10},
    "check-dof-2": {"deploy_check_max_dof": 2},
    "trace-first": {"second_order_first": False, "same_shape_tol": 0.0},
    "one-round": {"reseeds": 0, "reseeds_timed": 0},
    "rewind": {"rewind": True},
    "idle-first": {"idle_last": False},
    "near-gain": {"near_gain": True},
    "search-43": {"unbatch_peel": False, "idle_gain": False},
    "first-set": {"unbatch_peel": False},
    "idle-kept": {"idle_gain": False},
    "peel": {"unbatch_peel": True},
    "spread-first": {"hinge_stiffness_spread": 1e-4},
    "projection-large": {},
}
"""Each mode's settings changed from rigidfold's defaults: ``after`` the defaults; ``before``
the search of session 17 (no restart with the fold limit); ``no-second-order`` without the
second-order test and forecast (the search before session 17); ``bounded`` bound (12) at 120
degrees on every solve from the start (``generate --rho-max 120``); ``batch-auto`` several
creases per solve far from the target (the default since session 31, as ``after``) and
``batch-off`` one crease per solve, the paper's order (:data:`MODE_OPTIONS`);
``count-threshold`` and ``count-gap`` the search's DOF count (``generate --dof-count``);
``backtrack-10`` ten retractions a chain instead of three (``generate --backtrack 10``);
``check-dof-2`` the deployability check on solutions of DOF 2 too (a probe of session 33);
``trace-first`` every candidate's path traced, a shape met again too, and the second-order
test only after a path that fails (the search before session 33, the same attempts);
``one-round`` the search without its later rounds of other seeds (``reseeds`` 0, the search
before session 34); ``spread-first`` the first round's K_j spread by 10 % too (a probe of
session 34); ``rewind`` backtracking back to the chain's lowest shape that deploys
(``Settings.generation.rewind``, a probe of session 41); ``idle-first`` the candidates
that remove no mechanism in the criterion's order (``idle_last`` False, the search before
session 41); ``near-gain`` a near-mechanism fix of the same DOF count as its shape not
kept, and the shapes after one whose near fixes all gained nothing skipping them
(``near_gain``, a probe of session 43); ``search-43`` the batched chain's first dead end
back to before its first set and an idle candidate that keeps its shape's DOF kept (the
search before session 44: ``unbatch_peel`` and ``idle_gain`` off), ``first-set`` and
``idle-kept`` each of the two alone; ``peel`` the sets peeled one at a time from the last
(``unbatch_peel``, a probe of session 45); ``projection-large`` see
:data:`MODE_OPTIONS`."""
MODE_OPTIONS: dict[str, dict] = {
    "batch-auto": {"batch": "auto"},
    "batch-off": {"batch": "off"},
    "projection-large": {"projection": "large"},
}
"""Each mode's options changed from ``generate``'s defaults: ``batch-auto`` several creases
per solve (``generate --batch auto``; session 25), ``batch-off`` one (``--batch off``);
``projection-large`` the projection onto F = 0 before IPOPT only from
``Settings.solver.projection_vertices`` vertices on, IPOPT alone on smaller patterns
(``--projection large``, the search before session 38)."""


def paper_cases(surfaces: int) -> list[dict]:
    """The paper's study (Tables 5-6): patterns 1 and 2, S-hat and S, Bezier seeds 0 to
    ``surfaces - 1``, as ``rigidfold study --lookahead --deploy-check`` runs it."""
    return [
        {"surface": "bezier", "pattern": p, "seed": seed, "criterion": c, "limit": 600.0}
        for p in ("1", "2")
        for c in ("shat", "s")
        for seed in range(surfaces)
    ]


def cases() -> list[dict]:
    """Every case: a drawn pattern on the dome, the HP and Bezier seed 7; the roof."""
    out = [
        {"surface": s, "pattern": str(DATA / f), "seed": 7, "criterion": "shat", "limit": 180.0}
        for f in DRAWN
        for s in ("dome", "hp", "bezier")
    ]
    out.append({**ROOF, "seed": 0, "criterion": "s", "limit": 420.0})
    return out


def name(case: dict) -> str:
    text = f"{case['surface']}:{Path(case['pattern']).name}"
    return (
        text
        if case["surface"] != "bezier" or case["seed"] == 7
        else (f"{text}:{case['criterion']}:{case['seed']}")
    )


def cause(attempt) -> str | None:
    """Why an attempt was rejected (None: accepted, or the initial solve)."""
    outcome = attempt.outcome.value
    if outcome == "accepted":
        return None
    if outcome == "path":
        return attempt.path["status"] if attempt.path else "path"
    return outcome


def path_seconds(attempts) -> Counter:
    """Seconds of the candidates' path traces by how each ended (a trace's time is the
    path check's: the second-order test and the trace)."""
    out: Counter = Counter()
    for a in attempts:
        if a.path_time > 0:
            key = a.path["status"] if a.path else (cause(a) or "accepted")
            out[key] += round(a.path_time, 2)
    return out


def build(case: dict, settings):
    """The initial shape of ``case`` under ``settings`` (a :class:`rigidfold.generate.Case`)."""
    from rigidfold.generate.specs import case_from_specs

    return case_from_specs(
        case["surface"],
        case["pattern"],
        seed=case["seed"],
        size=case.get("size"),
        expr=case.get("expr"),
        settings=settings,
    )


def run(case: dict, mode: str) -> dict:
    """One run of ``case`` with the settings of ``mode`` (:data:`MODES`)."""
    from rigidfold.config import DEFAULTS
    from rigidfold.generate import Stop, generate

    settings = DEFAULTS.with_(**MODES[mode])
    t0, cpu0 = time.perf_counter(), time.process_time()
    built = build(case, settings)
    gen = generate(
        built,
        criterion=case["criterion"],
        seed=case["seed"],
        lookahead=case.get("lookahead", True),
        deform=False,
        time_limit=case["limit"],
        **MODE_OPTIONS.get(mode, {}),
    )
    final = gen.final
    deploys = final is not None and final.path is not None and final.path.deploys
    margin = gen.dof_margin or {}
    summary = gen.to_dict()
    removed = (gen.initial_dof or 0) - (gen.lowest_dof or gen.initial_dof or 0)
    forecast = Counter(
        f"{'rigid' if a.rigid_forecast else 'free'}->{cause(a) or 'accepted'}"
        for a in gen.attempts
        if a.rigid_forecast is not None
    )
    return {
        "case": name(case),
        "mode": mode,
        "stop": gen.stop_reason,
        "initial_dof": gen.initial_dof,
        "final_dof": gen.final_dof,
        "lowest_dof": gen.lowest_dof,
        "dof1_deploys": bool(gen.stop is Stop.TARGET_REACHED and deploys),
        "clear_gap": bool(margin.get("clear")),
        "near": margin.get("near"),
        "nonzero_min": margin.get("nonzero_min"),
        "solves": summary["n_solves"],
        "repeats": summary["n_repeats"],
        "solves_per_dof": summary["n_solves"] / removed if removed else None,
        "time_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - cpu0,
        "N_lock": gen.n_lock,
        "N_path": gen.n_path,
        "N_rigid": gen.n_rigid,
        "N_backtrack": gen.n_backtrack,
        "causes": dict(Counter(c for a in gen.attempts if (c := cause(a)) is not None)),
        "time_split": {k: round(v, 2) for k, v in summary["time_s"].items()},
        "path_s": dict(path_seconds(gen.attempts)),
        "forecast": dict(forecast),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument(
        "--only",
        default=None,
        metavar="TEXT[,TEXT...]",
        help="cases whose name holds one of these comma-separated texts",
    )
    parser.add_argument("--modes", default="after,before", help="comma-separated modes of MODES")
    parser.add_argument(
        "--paper",
        type=int,
        default=0,
        metavar="N",
        help="instead: the paper's study on N Bezier surfaces (patterns 1 and 2, S-hat and S)",
    )
    parser.add_argument(
        "--no-lookahead", action="store_true", help="the runs without the look-ahead"
    )
    parser.add_argument(
        "--seeds", default=None, help="with --paper: only these comma-separated seeds"
    )
    parser.add_argument(
        "--criteria", default=None, help="with --paper: only these comma-separated criteria"
    )
    parser.add_argument("--limit", type=float, default=None, help="each run's time limit, s")
    args = parser.parse_args()
    modes = [m for m in args.modes.split(",") if m]
    every = paper_cases(args.paper) if args.paper else cases()
    if args.seeds:
        every = [c for c in every if c["seed"] in {int(v) for v in args.seeds.split(",")}]
    if args.criteria:
        every = [c for c in every if c["criterion"] in args.criteria.split(",")]
    for c in every:
        c["lookahead"] = not args.no_lookahead
        c["limit"] = args.limit or c["limit"]
    wanted = None if args.only is None else args.only.split(",")
    chosen = [c for c in every if wanted is None or any(w in name(c) for w in wanted)]
    work = [(c, m) for c in chosen for m in modes]
    rows = []
    with ProcessPoolExecutor(args.jobs) as pool:
        for row in pool.map(run, *zip(*work, strict=True)):
            rows.append(row)
            print(json.dumps(row), flush=True)
            if args.out:
                with args.out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
    for mode in modes:
        sel = [r for r in rows if r["mode"] == mode]
        if not sel:
            continue
        share = sum(r["dof1_deploys"] for r in sel)
        clear = sum(r["dof1_deploys"] and r["clear_gap"] for r in sel)
        per_dof = [r["solves_per_dof"] for r in sel if r["solves_per_dof"] is not None]
        causes: Counter = Counter()
        forecast: Counter = Counter()
        for r in sel:
            causes.update(r["causes"])
            forecast.update(r["forecast"])
        print(
            f"{mode}: {share}/{len(sel)} reach DOF 1 and deploy, {clear} with a clear DOF gap; "
            f"median run "
            f"{statistics.median(r['time_s'] for r in sel):.1f} s, longest "
            f"{max(r['time_s'] for r in sel):.1f} s (CPU: median "
            f"{statistics.median(r['cpu_s'] for r in sel):.1f} s, longest "
            f"{max(r['cpu_s'] for r in sel):.1f} s); median solves per DOF removed "
            f"{statistics.median(per_dof) if per_dof else float('nan'):.2f}"
        )
        print(f"{mode}: rejected candidates by cause {dict(causes.most_common())}")
        split: Counter = Counter()
        for r in sel:
            split.update(r["time_split"])
        total = sum(r["time_s"] for r in sel)
        print(f"{mode}: {total:.0f} s in all, by part { {k: round(v) for k, v in split.items()} }")
        if forecast:
            print(f"{mode}: forecast -> found {dict(forecast.most_common())}")


if __name__ == "__main__":
    main()
