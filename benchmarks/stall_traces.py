"""The evidence behind ``Settings.generation.child_stall`` (session 46): how the best F of a
child's solve falls, iteration by iteration, in solves that converge and in solves that do
not, and what a stall window would have ended.

Each case runs as ``generate()`` with rigidfold's defaults (look-ahead, the deployability
check, its time limit) but with the stall window off (``child_stall`` of a million
iterations), and every solve after the first keeps, per IPOPT iteration, the least F of its
feasible iterates so far (inf before the first; :func:`rigidfold.optimize.solver.stalled`
reads the same list) and the time. Two sets of cases: ``drawn`` (the 25 drawn and roof
cases of ``benchmarks/deploy_anywhere.py``, as it runs them) and ``sample40`` (the broad
set's sample of 40, ``benchmarks/broad_cases.py``, through the library with the command
line's defaults; the three that end at their first solve are left out).

Run with ``python -m rigidfold.pinned python benchmarks/stall_traces.py --cases drawn --out
FILE.jsonl [--jobs 2] [--only TEXT[,TEXT...]]``; ``--summarize FILE.jsonl [...] [--window
K[,K...]]`` prints, per window: the converged child solves, how many the window would have
ended (and the largest ratio of the best F to the best F a window before, over iterates
above F_tol: 0.5 or more ends a solve), and the failing ones it ends with the seconds they
ran on after that iteration; ``--list`` adds every failing solve with its least F after
10, 40 and 80 iterations and at its end.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import deploy_anywhere as da  # the drawn and roof cases, as that benchmark names them
from broad_cases import SAMPLE_40, cases  # the broad set's sample

FIRST_SOLVE_ENDS = ("6ptHypar-anti/dome", "whirlpool-p11/dome", "origamisimulator/bezier")
"""The sample's cases that end at their first solve (no child solve to trace)."""

OFF = 10**6
"""A stall window no solve reaches: the rule is off, the history is kept."""


def run(job: tuple[str, dict, str, float]) -> dict:
    """One case: every child solve's status, iterations, seconds and (time, best F) trace."""
    name, kwargs, criterion, limit = job
    from rigidfold.config import DEFAULTS
    from rigidfold.generate import Stop, generate
    from rigidfold.generate.specs import case_from_specs
    from rigidfold.optimize import FormFindingProblem, ipopt

    solves: list[dict] = []
    trace: list[tuple[float, float]] = []
    eval_ = ipopt.EarlyStop.eval
    solve = FormFindingProblem.solve

    def recording_eval(self, arg):
        out = eval_(self, arg)
        if self.stall is not None and self.best:
            trace.append((time.perf_counter(), self.best[-1]))
        return out

    def recording_solve(self, *args, stall=None, **kw):
        trace.clear()
        result = solve(self, *args, stall=stall, **kw)
        if stall is not None:
            solves.append(
                {
                    "status": result.status.value,
                    "iterations": result.iterations,
                    "t": result.wall_time,
                    "trace": list(trace),
                }
            )
        return result

    ipopt.EarlyStop.eval = recording_eval
    FormFindingProblem.solve = recording_solve
    settings = DEFAULTS.with_(child_stall=OFF)
    built = case_from_specs(**kwargs, settings=settings)
    t0 = time.perf_counter()
    gen = generate(
        built,
        criterion=criterion,
        seed=kwargs["seed"],
        lookahead=True,
        deform=False,
        time_limit=limit,
    )
    final = gen.final
    deploys = final is not None and final.path is not None and final.path.deploys
    return {
        "case": name,
        "t": time.perf_counter() - t0,
        "passed": bool(
            gen.stop is Stop.TARGET_REACHED and deploys and (gen.dof_margin or {}).get("clear")
        ),
        "final": gen.final_dof,
        "solves": solves,
    }


def jobs(which: str, work: Path) -> list[tuple[str, dict, str, float]]:
    """The cases of ``which`` ("drawn" or "sample40") as (name, case_from_specs keywords,
    criterion, time limit)."""
    if which == "drawn":
        return [
            (
                da.name(c),
                {
                    "surface": c["surface"],
                    "pattern": c["pattern"],
                    "seed": c["seed"],
                    "size": c.get("size"),
                    "expr": c.get("expr"),
                },
                c["criterion"],
                c["limit"],
            )
            for c in da.cases()
        ]
    sample, _ = cases(work)
    return [
        (c.name, c.make_case_kwargs(work), "shat", 180.0)
        for c in sample
        if c.name in SAMPLE_40 and not any(k in c.name for k in FIRST_SOLVE_ENDS)
    ]


def list_failing(paths: list[Path]) -> None:
    """Every child solve that did not converge: its case, status, iterations, seconds and
    least feasible F after iterations 10, 40, 80 and at its end."""
    for p in paths:
        for line in p.open():
            run = json.loads(line)
            for s in run["solves"]:
                if s["status"] in ("tolerance_not_met", "iteration_limit"):
                    best = [b for _, b in s["trace"]]
                    marks = " ".join(f"{i}:{best[i]:.2g}" for i in (10, 40, 80) if i < len(best))
                    end = f"{best[-1]:.2g}" if best else "-"
                    print(
                        f"{run['case']:40s} {s['status']:18s} {s['iterations']:4d} it "
                        f"{s['t']:5.1f} s  best F {marks} end:{end}"
                    )


def summarize(paths: list[Path], windows: list[int]) -> None:
    from rigidfold.config import DEFAULTS

    f_tol = DEFAULTS.design.f_tol
    runs = [json.loads(line) for p in paths for line in p.open()]
    children = [s for r in runs for s in r["solves"]]
    print(
        f"{len(runs)} runs, {sum(r['passed'] for r in runs)} pass, {sum(r['t'] for r in runs):.0f}"
        f" s in all; {len(children)} child solves, "
        f"{sum(s['status'] == 'converged' for s in children)} converged"
    )
    for k in windows:
        ended, worst, caught, failing, after = 0, 0.0, 0, 0, 0.0
        for s in children:
            best = [b for _, b in s["trace"]]
            at = [i for i in range(k, len(best)) if math.isfinite(best[i - k]) and best[i] > f_tol]
            ratios = [best[i] / best[i - k] for i in at]
            stop = next((i for i, q in zip(at, ratios, strict=True) if q > 0.5), None)
            if s["status"] == "converged":
                worst = max([worst, *ratios])
                ended += stop is not None
            elif s["status"] in ("tolerance_not_met", "iteration_limit"):
                failing += 1
                if stop is not None:
                    caught += 1
                    after += s["trace"][-1][0] - s["trace"][stop][0]
        print(
            f"  window {k}: converged solves ended {ended} (largest ratio {worst:.3f}); "
            f"failing solves ended {caught} of {failing}, {after:.1f} s after that iteration"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", choices=("drawn", "sample40"), default="drawn")
    parser.add_argument("--out", type=Path, help="results file (JSON lines)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--only", default=None, metavar="TEXT[,TEXT...]")
    parser.add_argument("--summarize", nargs="+", type=Path, metavar="FILE")
    parser.add_argument("--window", default="40,50,60,80", metavar="K[,K...]")
    parser.add_argument(
        "--list", action="store_true", help="with --summarize: every failing child solve"
    )
    args = parser.parse_args()
    if args.summarize and args.list:
        list_failing(args.summarize)
    if args.summarize:
        summarize(args.summarize, [int(k) for k in args.window.split(",")])
        return
    if args.out is None:
        parser.error("--out is needed to run the cases")
    with tempfile.TemporaryDirectory() as tmp:
        todo = jobs(args.cases, Path(tmp))
        if args.only:
            keys = args.only.split(",")
            todo = [j for j in todo if any(k in j[0] for k in keys)]
        with ProcessPoolExecutor(args.jobs) as pool, args.out.open("w") as out:
            for result in pool.map(run, todo):
                out.write(json.dumps(result) + "\n")
                out.flush()
                print(
                    f"{result['case']:40s} {result['t']:6.1f} s  DOF {result['final']}  "
                    f"{len(result['solves'])} child solves"
                )


if __name__ == "__main__":
    main()
