"""Where the drawn and roof cases' solves go (session 45): every attempt's iterations, solver
status, outcome and solve time, for the cases of ``benchmarks/deploy_anywhere.py`` run as it
runs them (``generate()`` with its arguments and rigidfold's defaults).

Run with ``python -m rigidfold.pinned python benchmarks/child_solves.py --out FILE.jsonl
[--jobs 2] [--only TEXT[,TEXT...]]``; ``--summarize FILE.jsonl [FILE2.jsonl]`` prints, per
file, the passes, the median run, how many child solves converged and the most iterations
any took (the projections' steps and IPOPT's together), the children that did not converge
and their seconds, and those at an iteration limit; with two files, the cases whose attempts
differ between them (outcome and crease count, attempt by attempt).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import deploy_anywhere as da  # the cases, as that benchmark names them


def run(case: dict) -> dict:
    """One case with rigidfold's defaults: its attempts as (index, iterations, status,
    outcome, solve seconds, creases added)."""
    from rigidfold.config import DEFAULTS
    from rigidfold.generate import Stop, generate

    built = da.build(case, DEFAULTS)
    t0 = time.perf_counter()
    gen = generate(
        built,
        criterion=case["criterion"],
        seed=case["seed"],
        lookahead=True,
        deform=False,
        time_limit=case["limit"],
    )
    final = gen.final
    deploys = final is not None and final.path is not None and final.path.deploys
    margin = gen.dof_margin or {}
    return {
        "case": da.name(case),
        "t": time.perf_counter() - t0,
        "passed": bool(gen.stop is Stop.TARGET_REACHED and deploys and margin.get("clear")),
        "final": gen.final_dof,
        "stop": gen.stop_reason,
        "rows": [
            (
                a.index,
                a.iterations,
                a.status.value,
                a.outcome.value,
                a.solve_time,
                len(a.fixed_added),
            )
            for a in gen.attempts
        ],
    }


def summarize(paths: list[Path]) -> None:
    runs = [{(r := json.loads(line))["case"]: r for line in p.open()} for p in paths]
    for path, by in zip(paths, runs, strict=True):
        children = [row for r in by.values() for row in r["rows"][1:]]
        done = [row for row in children if row[2] == "converged"]
        failed = [row for row in children if row[2] != "converged"]
        limited = [row for row in children if row[2] == "iteration_limit"]
        print(
            f"{path}: {sum(r['passed'] for r in by.values())} / {len(by)} pass, median run "
            f"{statistics.median(r['t'] for r in by.values()):.1f} s, all runs "
            f"{sum(r['t'] for r in by.values()):.1f} s; child solves {len(children)}: "
            f"{len(done)} converged (most {max((r[1] for r in done), default=0)} iterations, "
            f"99 % within {sorted(r[1] for r in done)[int(0.99 * len(done))] if done else 0}), "
            f"{len(failed)} not ({sum(r[4] for r in failed):.1f} s), "
            f"{len(limited)} at a limit ({sum(r[4] for r in limited):.1f} s)"
        )
    if len(runs) == 2:
        a, b = runs
        for case in a:
            if case in b:
                sa = [(r[0], r[3], r[5]) for r in a[case]["rows"]]
                sb = [(r[0], r[3], r[5]) for r in b[case]["rows"]]
                if sa != sb:
                    same = next(
                        (k for k, (x, y) in enumerate(zip(sa, sb, strict=False)) if x != y),
                        min(len(sa), len(sb)),
                    )
                    print(f"  {case}: attempts differ from {same} ({len(sa)} against {len(sb)})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="results file (JSON lines)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--only", default=None, metavar="TEXT[,TEXT...]")
    parser.add_argument("--summarize", nargs="+", type=Path, metavar="FILE")
    args = parser.parse_args()
    if args.summarize:
        summarize(args.summarize)
        return
    if args.out is None:
        parser.error("--out is needed to run the cases")
    cases = da.cases()
    if args.only:
        keys = args.only.split(",")
        cases = [c for c in cases if any(k in da.name(c) for k in keys)]
    with ProcessPoolExecutor(args.jobs) as pool, args.out.open("w") as out:
        for result in pool.map(run, cases):
            out.write(json.dumps(result) + "\n")
            out.flush()
            print(
                f"{result['case']:34s} {result['t']:6.1f} s  "
                f"DOF {result['final']}  {result['stop']}"
            )


if __name__ == "__main__":
    main()
