"""The broad set (issue 49, item 7): what a user runs, on patterns the search was not tuned on.

Each case of ``benchmarks/broad_cases.py`` (six families, >= 60 cases) is run as the command
a user types::

    rigidfold generate <the case's arguments> --lookahead --no-deform --time-limit 180 --out DIR

in a subprocess (``python -m rigidfold.cli``) with the pinned numerics of ``python -m
rigidfold.pinned`` (:func:`rigidfold.runtime.numerics.pinned_environ`), its wall time measured from
outside, so starting Python, drawing diagrams, writing files, exports and the report all count.
The result is read from ``DIR/summary.json``: ``final_dof``, ``dof_margin`` (a clear gap?),
``final_deploys``, the solves, and the ``time_s`` breakdown.

A case passes when its final design has DOF 1 with a clear gap (``dof_margin.clear``) and
deploys (``final_deploys``), and the run kept its time limit: a run that ends more than
max(10 s, 5 %) after the limit is flagged ``overrun`` and fails; one still going at
``--kill-after`` is killed and fails.

Usage::

    python benchmarks/broad_set.py [--jobs N] [--only TEXT[,TEXT...]] [--limit S]
        [--variants today[,NAME...]] [--reference DIR] [--out results.jsonl [--resume]]
        [--work DIR [--keep]]
    python benchmarks/broad_set.py --list                      # the cases, and those left out
    python benchmarks/broad_set.py --summarize results.jsonl   # the summary of a past run

A *variant* (:data:`VARIANTS`) is a named set of extra command-line flags; ``today`` adds
none; ``reference`` is ``today`` run by another checkout of rigidfold (``--reference DIR``),
to compare a change of the search with the search before it. With several variants, each
case is run with each of them in turn (jobs submitted case by case, so the variants run side
by side on the same machine load). Every finished run is
appended to ``--out`` as one JSON line at once, so an interrupted benchmark keeps its results;
``--resume`` runs only the (case, variant) pairs not in the file yet. At the end (and with
``--summarize``), per variant and per family: the share that passes, the median and 90th
percentile wall time, the median solves per DOF removed, the largest number of solves per DOF
removed above DOF 10 on runs of initial DOF 40 or more (issue 49's target: at most 0.25; read
from each run's log.jsonl), and the share of wall time in the development diagrams
(``time_s.develop``) and outside the search (everything but build, solve, analysis,
selection and path: start-up, diagrams, motion, writing, exports, report).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from broad_cases import FAMILIES, SAMPLE_40, BroadCase, cases

VARIANTS: dict[str, tuple[str, ...]] = {
    "today": (),
    "criterion-s": ("--criterion", "s"),
    "batch-auto": ("--batch", "auto"),
    "batch-on": ("--batch", "on"),
    "batch-off": ("--batch", "off"),
    "theta-none": ("--theta-widen", "none"),
    "accept-no-gap": ("--accept-no-gap",),
    "count-threshold": ("--dof-count", "threshold"),
    "count-gap": ("--dof-count", "gap"),
    "backtrack-10": ("--backtrack", "10"),
    "one-round": ("--reseeds", "0"),
    "projection-large": ("--projection", "large"),
    "reference": (),
}
"""Named sets of extra ``rigidfold generate`` flags, compared side by side (``--variants``):
``today`` the command line's defaults; ``criterion-s`` the criterion S instead of S-hat;
``batch-auto`` several creases fixed per solve where the first-order analysis allows, until
the first chain's first dead end (the default since session 31, as ``today``);
``batch-on`` the same in every chain (what ``batch-auto`` was before session 25);
``batch-off`` one crease per solve (the paper's order; the default before session 31);
``theta-none`` the sector-angle bounds as given, never widened to a drawn plan's angles
(the default before session 24); ``accept-no-gap`` a target-DOF design without a clear gap
ends the run (the default before session 24); ``count-threshold`` and ``count-gap`` the
search's DOF count (``--dof-count``): the paper's threshold, or with the near-mechanisms;
``backtrack-10`` ten retractions a chain instead of three (``--backtrack 10``);
``one-round`` the search without its later rounds of other seeds (``--reseeds 0``, the
search before session 34); ``projection-large`` the projection onto F = 0 before IPOPT
only on patterns of ``Settings.solver.projection_vertices`` or more (``--projection large``,
the search before session 38); ``reference``
the defaults of another checkout of rigidfold (``--reference DIR``: its ``src`` first on
PYTHONPATH), to compare a change of the search with the search before it in the same run."""

COMMON = ("--lookahead", "--no-deform", "--quiet")
"""The flags every run gets (besides ``--time-limit`` and ``--out``): the README's command;
``--quiet`` only drops the progress bar, which no one watches here."""
LIMIT_S = 180.0
"""Each run's ``--time-limit`` (``--limit`` overrides it)."""
SEARCH_KEYS = ("build", "solve", "analysis", "selection", "path")
"""The parts of ``time_s`` that are the search itself; the rest of the wall time is outside."""


def grace(limit: float) -> float:
    """How long after its time limit a run may end: max(10 s, 5 % of the limit)."""
    return max(10.0, 0.05 * limit)


def run_environment(source: Path | None = None) -> dict[str, str]:
    """This process's environment with the pinned numerics, as ``python -m rigidfold.pinned``
    starts a command, and this benchmark's ``src`` (or ``source``'s, a checkout of rigidfold)
    first on PYTHONPATH."""
    from rigidfold.runtime.numerics import RESTARTED_ENV, pinned_environ

    env = pinned_environ(os.environ)
    env[RESTARTED_ENV] = "1"
    src = str((source or Path(__file__).resolve().parents[1]) / "src")
    rest = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p and p != src]
    env["PYTHONPATH"] = os.pathsep.join([src, *rest])
    return env


def command(case: BroadCase, variant: str, limit: float, out: Path, work: Path) -> list[str]:
    """The ``rigidfold generate`` command line of one run."""
    return [
        sys.executable,
        "-m",
        "rigidfold.cli",
        "generate",
        *case.cli_args(work),
        *COMMON,
        *VARIANTS[variant],
        "--time-limit",
        f"{limit:g}",
        "--out",
        str(out),
    ]


def _wait(proc: subprocess.Popen, deadline: float) -> tuple[int, float, bool]:
    """(exit status, CPU seconds of the child, killed): waits for ``proc`` with ``os.wait4``
    (its own CPU time) until ``deadline`` (perf_counter), then kills it."""
    killed = False
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        if not killed and time.perf_counter() > deadline:
            proc.kill()
            killed = True
        time.sleep(0.02)
    code = os.waitstatus_to_exitcode(status)
    proc.returncode = code  # reaped here: Popen must not wait for it again
    return code, usage.ru_utime + usage.ru_stime, killed


def run_one(
    case: BroadCase,
    variant: str,
    limit: float,
    kill_after: float,
    work: Path,
    keep: bool,
    reference: Path | None = None,
) -> dict:
    """Run one case with one variant (``reference``: the checkout of the variant of that
    name); the result row (JSON data)."""
    out = work / "runs" / variant / case.name.replace("/", "__").replace(":", "_")
    if out.exists():
        _remove(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    argv = command(case, variant, limit, out, work)
    log = out.parent / (out.name + ".log")
    with log.open("wb") as sink:
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            argv,
            stdout=sink,
            stderr=subprocess.STDOUT,
            env=run_environment(reference if variant == "reference" else None),
            cwd=work,
        )
        code, cpu, killed = _wait(proc, t0 + kill_after)
        wall = time.perf_counter() - t0
    row = {
        "case": case.name,
        "family": case.family,
        "variant": variant,
        "flags": list(VARIANTS[variant]),
        "limit_s": limit,
        "exit": code,
        "killed": killed,
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "overrun": killed or wall > limit + grace(limit),
        "args": argv[4:],
    }
    row.update(_read_summary(out / "summary.json"))
    row.update(_read_descent(out / "log.jsonl"))
    if row.get("summary") is False:
        tail = log.read_text(encoding="utf-8", errors="replace").strip().splitlines()
        row["error"] = tail[-1] if tail else f"exit {code}, nothing printed"
    row["passed"] = bool(
        row.get("final_dof") == 1 and row.get("clear") and row.get("deploys") and not row["overrun"]
    )
    if not keep:
        _remove(out)
        log.unlink(missing_ok=True)
    return row


def _read_summary(path: Path) -> dict:
    """The fields of a run's summary.json that the benchmark reports; ``summary: False``
    when there is none (a refused input, a crash, a killed run)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {"summary": False}
    margin = data.get("dof_margin") or {}
    initial, final = data.get("initial_dof"), data.get("final_dof")
    solves = data.get("n_solves")
    removed = initial - final if isinstance(initial, int) and isinstance(final, int) else None
    return {
        "summary": True,
        "stop": data.get("stop"),
        "verdict": (data.get("verdict") or {}).get("outcome"),
        "initial_dof": initial,
        "final_dof": final,
        "lowest_dof": data.get("lowest_dof"),
        "clear": margin.get("clear"),
        "near": margin.get("near"),
        "nonzero_min": margin.get("nonzero_min"),
        "deploys": data.get("final_deploys"),
        "solves": solves,
        "solves_per_dof": solves / removed if removed and solves is not None else None,
        "N_lock": data.get("n_lock"),
        "N_path": data.get("n_path"),
        "N_backtrack": data.get("n_backtrack"),
        "time_s": data.get("time_s") or {},
    }


ABOVE_DOF = 10
"""Issue 49's target: solves per DOF removed above this DOF, on runs of initial DOF at least
``LARGE_DOF``."""
LARGE_DOF = 40


def _read_descent(path: Path) -> dict:
    """From a run's log.jsonl: ``solves_above`` (the attempts after the first solve up to the
    first accepted solution at DOF <= ``ABOVE_DOF``, those retracted later included, the
    repeats of an earlier attempt, ``solve_from``, not) per
    DOF removed above it, ``solves_above_per_dof`` (None where the run started at or below
    it, or never got there)."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError:
        return {}
    attempts = []
    for line in lines:
        try:
            record = json.loads(line)
        except ValueError:
            continue
        if isinstance(record, dict) and "outcome" in record:
            attempts.append(record)
    if not attempts or not isinstance(attempts[0].get("dof"), int):
        return {}
    initial = attempts[0]["dof"]
    if initial <= ABOVE_DOF:
        return {}
    n = 0
    for record in attempts[1:]:
        n += record.get("solve_from") is None  # a repeat is no solve
        dof = record.get("dof")
        if record.get("outcome") == "accepted" and isinstance(dof, int) and dof <= ABOVE_DOF:
            return {"solves_above": n, "solves_above_per_dof": n / (initial - ABOVE_DOF)}
    return {}


def _remove(path: Path) -> None:
    import shutil

    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


# --- the summary -----------------------------------------------------------------------


def _percentile(values: list[float], q: float) -> float:
    """The ``q`` quantile (0..1) by linear interpolation between order statistics."""
    data = sorted(values)
    if not data:
        return math.nan
    pos = q * (len(data) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def stats(rows: list[dict]) -> dict:
    """The figures of a group of runs (one variant, or one variant's family)."""
    n = len(rows)
    walls = [r["wall_s"] for r in rows]
    cpus = [r["cpu_s"] for r in rows]
    per_dof = [r["solves_per_dof"] for r in rows if r.get("solves_per_dof") is not None]
    above = [
        r["solves_above_per_dof"]
        for r in rows
        if r.get("solves_above_per_dof") is not None and (r.get("initial_dof") or 0) >= LARGE_DOF
    ]
    wall_total = sum(walls)
    develop = sum((r.get("time_s") or {}).get("develop", 0.0) for r in rows)
    search = sum(sum((r.get("time_s") or {}).get(k, 0.0) for k in SEARCH_KEYS) for r in rows)
    return {
        "runs": n,
        "passed": sum(r["passed"] for r in rows),
        "dof1": sum(r.get("final_dof") == 1 for r in rows),
        "clear": sum(r.get("final_dof") == 1 and bool(r.get("clear")) for r in rows),
        "deploys": sum(bool(r.get("deploys")) for r in rows),
        "overrun": sum(r["overrun"] for r in rows),
        "no_summary": sum(not r.get("summary") for r in rows),
        "median_s": statistics.median(walls) if walls else math.nan,
        "p90_s": _percentile(walls, 0.9),
        "max_s": max(walls) if walls else math.nan,
        "median_cpu_s": statistics.median(cpus) if cpus else math.nan,
        "median_solves_per_dof": statistics.median(per_dof) if per_dof else math.nan,
        "large": len(above),
        "max_solves_above": max(above) if above else math.nan,
        "develop_share": develop / wall_total if wall_total else math.nan,
        "outside_search_share": (wall_total - search) / wall_total if wall_total else math.nan,
    }


def _line(label: str, s: dict) -> str:
    share = s["passed"] / s["runs"] if s["runs"] else math.nan
    return (
        f"{label:<22} {s['passed']:>3}/{s['runs']:<3} {share:>5.0%}  "
        f"dof1 {s['dof1']:>3} clear {s['clear']:>3} deploys {s['deploys']:>3} "
        f"overrun {s['overrun']:>2}  median {s['median_s']:>6.1f} s  p90 {s['p90_s']:>6.1f} s  "
        f"max {s['max_s']:>6.1f} s  (CPU median {s['median_cpu_s']:>6.1f} s)  "
        f"solves/DOF {s['median_solves_per_dof']:>5.2f}  "
        f"above {ABOVE_DOF} (initial >= {LARGE_DOF}: {s['large']} runs) "
        f"max {s['max_solves_above']:>4.2f}  "
        f"develop {s['develop_share']:>4.0%}  outside search {s['outside_search_share']:>4.0%}"
    )


def summarize(rows: list[dict]) -> str:
    """The summary text: per variant, all cases then each family; then, with several
    variants, how each compares with the first on the cases both ran."""
    latest: dict[tuple[str, str], dict] = {}
    for r in rows:
        latest[(r["case"], r["variant"])] = r
    by_variant: dict[str, list[dict]] = defaultdict(list)
    for r in latest.values():
        by_variant[r["variant"]].append(r)
    lines = [
        "passed = final DOF 1 with a clear gap, a design that deploys, and the time limit kept "
        "(ended by limit + max(10 s, 5 %)); times are wall seconds of the whole command"
    ]
    for variant, sel in by_variant.items():
        lines.append(_line(f"{variant}: all", stats(sel)))
        families = [f for f in FAMILIES if any(r["family"] == f for r in sel)]
        families += sorted({r["family"] for r in sel} - set(families))
        for family in families:
            lines.append(_line(f"  {family}", stats([r for r in sel if r["family"] == family])))
        over = [r for r in sel if r["overrun"]]
        for r in over:
            lines.append(
                f"  OVERRUN {r['case']}: {r['wall_s']:.1f} s with --time-limit {r['limit_s']:g}"
                f"{' (killed)' if r['killed'] else ''}"
            )
        for r in sel:
            if not r.get("summary"):
                lines.append(f"  NO SUMMARY {r['case']}: exit {r['exit']}: {r.get('error', '')}")
    variants = list(by_variant)
    if len(variants) > 1:
        first = {r["case"]: r for r in by_variant[variants[0]]}
        for variant in variants[1:]:
            pairs = [(first[r["case"]], r) for r in by_variant[variant] if r["case"] in first]
            gained = sum(b["passed"] and not a["passed"] for a, b in pairs)
            lost = sum(a["passed"] and not b["passed"] for a, b in pairs)
            ratio = [b["wall_s"] / a["wall_s"] for a, b in pairs if a["wall_s"] > 0]
            lines.append(
                f"{variant} vs {variants[0]} on {len(pairs)} cases: passes {gained} more, "
                f"{lost} fewer; median wall-time ratio "
                f"{statistics.median(ratio) if ratio else math.nan:.2f}"
            )
    return "\n".join(lines)


def read_rows(path: Path) -> list[dict]:
    """The rows of a results file; a last line torn by an interruption is skipped."""
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:
            continue
    return rows


def stratified(chosen: list[BroadCase], n: int) -> list[BroadCase]:
    """About ``n`` of ``chosen``, the same share of each family (every k-th case in the
    family's order, so the pick does not depend on the machine), at least
    ``min(6, family size)`` of each."""
    by_family: dict[str, list[BroadCase]] = defaultdict(list)
    for c in chosen:
        by_family[c.family].append(c)
    share = min(1.0, n / max(1, len(chosen)))
    picked: list[BroadCase] = []
    for members in by_family.values():
        want = max(min(6, len(members)), round(share * len(members)))
        step = len(members) / want
        picked += [members[int(i * step)] for i in range(want)]
    return picked


# --- the command line --------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1)")
    parser.add_argument(
        "--only",
        default=None,
        metavar="TEXT[,TEXT...]",
        help="cases whose name holds one; sample40: the 40 cases of broad_cases.SAMPLE_40",
    )
    parser.add_argument(
        "--sample",
        type=int,
        default=None,
        metavar="N",
        help="about N cases, every k-th of each family (at least 6 of each where it has them)",
    )
    parser.add_argument(
        "--limit",
        type=float,
        default=LIMIT_S,
        help=f"--time-limit of every run (default {LIMIT_S:g})",
    )
    parser.add_argument(
        "--kill-after",
        type=float,
        default=None,
        metavar="S",
        help="kill a run still going after S seconds (default: 2 x limit + 60)",
    )
    parser.add_argument(
        "--variants", default="today", help=f"comma-separated, of {', '.join(VARIANTS)}"
    )
    parser.add_argument(
        "--reference",
        type=Path,
        default=None,
        metavar="DIR",
        help="a checkout of rigidfold whose search the variant 'reference' runs",
    )
    parser.add_argument("--out", type=Path, default=None, help="results file (JSON lines)")
    parser.add_argument("--resume", action="store_true", help="skip the runs already in --out")
    parser.add_argument("--work", type=Path, default=None, help="folder for the runs' outputs")
    parser.add_argument("--keep", action="store_true", help="keep each run's output folder")
    parser.add_argument(
        "--list", action="store_true", help="list the cases (of --only, --sample) and exit"
    )
    parser.add_argument(
        "--summarize", type=Path, default=None, metavar="FILE", help="summarize a results file"
    )
    args = parser.parse_args(argv)
    if args.summarize is not None:
        print(summarize(read_rows(args.summarize)))
        return 0
    variants = [v for v in args.variants.split(",") if v]
    unknown = [v for v in variants if v not in VARIANTS]
    if unknown or not variants:
        parser.error(f"unknown variants {unknown} (choose from {', '.join(VARIANTS)})")
    if ("reference" in variants) != (args.reference is not None):
        parser.error("the variant 'reference' and --reference DIR go together")
    if args.reference is not None and not (args.reference / "src" / "rigidfold").is_dir():
        parser.error(
            f"--reference {args.reference}: not a checkout of rigidfold (no src/rigidfold)"
        )
    if args.resume and args.out is None:
        parser.error("--resume needs --out")
    if args.jobs < 1:
        parser.error("--jobs must be at least 1")
    with tempfile.TemporaryDirectory(prefix="broad_set_") as tmp:
        work = (args.work or Path(tmp)).resolve()
        work.mkdir(parents=True, exist_ok=True)
        every, left = cases(work)
        wanted = None if args.only is None else [w for w in args.only.split(",") if w]
        sample = set(SAMPLE_40) if wanted and "sample40" in wanted else set()
        chosen = [
            c
            for c in every
            if wanted is None or c.name in sample or any(w in c.name for w in wanted)
        ]
        if args.sample is not None:
            chosen = stratified(chosen, args.sample)
        if args.list:
            counts: dict[str, int] = defaultdict(int)
            for c in chosen:
                counts[c.family] += 1
                shown = [
                    Path(a).name if a.endswith((".svg", ".fold")) else a for a in c.cli_args(work)
                ]
                print(f"{c.name}\t{' '.join(shown)}")
            print(f"{len(chosen)} cases: " + ", ".join(f"{f} {n}" for f, n in counts.items()))
            for name, reason in left:
                print(f"left out {name}: {reason}")
            return 0
        done: set[tuple[str, str]] = set()
        if args.resume and args.out.is_file():
            done = {(r["case"], r["variant"]) for r in read_rows(args.out)}
        todo = [(c, v) for c in chosen for v in variants if (c.name, v) not in done]
        for c, _ in todo:
            c.pattern_spec(work)  # perturbed FOLD files, written once before the runs
        kill_after = args.kill_after or 2 * args.limit + 60
        print(
            f"{len(todo)} runs ({len(chosen)} cases x {len(variants)} variants, "
            f"{len(done)} done before); left out: {len(left)} drawn cases "
            f"({', '.join(n for n, _ in left)})",
            flush=True,
        )
        rows = [r for r in read_rows(args.out) if r["variant"] in variants] if done else []
        lock = threading.Lock()
        with ThreadPoolExecutor(args.jobs) as pool:
            futures = [
                pool.submit(run_one, c, v, args.limit, kill_after, work, args.keep, args.reference)
                for c, v in todo
            ]
            for future in as_completed(futures):
                row = future.result()
                with lock:
                    rows.append(row)
                    if args.out is not None:
                        from rigidfold.io import append_json_line

                        append_json_line(args.out, row, create=not args.out.exists())
                print(
                    f"{row['case']:<44} {row['variant']:<10} "
                    f"{'PASS' if row['passed'] else 'fail'} DOF {row.get('initial_dof')}"
                    f" -> {row.get('final_dof')} clear {row.get('clear')} deploys "
                    f"{row.get('deploys')} {row['wall_s']:.1f} s "
                    f"(develop {row.get('time_s', {}).get('develop', 0.0):.1f} s) "
                    f"solves {row.get('solves')}{' OVERRUN' if row['overrun'] else ''}",
                    flush=True,
                )
    print(summarize(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
