"""The same search, faster: a change meant only to save work must leave every attempt as it was.

Each case is run without a time limit (so that no clock decides anything) as the command a
user types, ``rigidfold generate <case> --lookahead --no-deform --quiet --no-report``, once by
this checkout and once by ``--reference DIR`` (another checkout of rigidfold), each in a
subprocess with the pinned numerics (:func:`broad_set.run_environment`). The attempts of the
two ``log.jsonl`` files are compared field by field on what the search decided: the creases
fixed, the outcome, the DOF and the near-mechanism share. Prints one line per case and the
number of cases whose attempts differ; exits 1 if any does.

Usage::

    python benchmarks/same_search.py --reference <a checkout> [--work DIR]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from broad_set import run_environment

DRAWN = Path(__file__).resolve().parents[1] / "tests" / "data" / "origami_simulator"
CASES: dict[str, tuple[str, ...]] = {
    "paper1-bezier2027": ("--surface", "bezier", "--pattern", "1", "--seed", "2027"),
    "paper2-bezier2027": ("--surface", "bezier", "--pattern", "2", "--seed", "2027"),
    "paper11-bezier1013": ("--surface", "bezier", "--pattern", "11", "--seed", "1013"),
    "grid7x7-dome": (
        *("--surface", "dome", "--pattern", "grid:7x7", "--size", "3x3", "--seed", "7"),
        *("--criterion", "s"),
    ),
    "grid5x5-hp": (
        *("--surface", "hp", "--pattern", "grid:5x5", "--size", "3x3", "--seed", "3"),
        *("--criterion", "s"),
    ),
    "resch-dome": (
        *("--surface", "dome", "--pattern", str(DRAWN / "reschTriTessellation.svg")),
        *("--seed", "7"),
    ),
}
"""Cases of a few seconds each with near-mechanism candidates (the paper's patterns on Bezier
surfaces outside the study's seeds) and without (small grids); and one of about a minute
whose restarts at the fold limits meet rejected shapes again (Resch's triangles on the
dome: ``Attempt.path_from``)."""
FIELDS = ("fixed_added", "outcome", "dof", "near")
"""What the search decided in each attempt."""


def attempts(out: Path) -> list[tuple]:
    """The decided fields of every attempt in ``out/log.jsonl``, in order, and last whether
    its verdict was taken from an earlier attempt (``path_from``: not compared)."""
    rows = [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines()]
    return [
        (*(json.dumps(r.get(f)) for f in FIELDS), r.get("path_from") is not None)
        for r in rows
        if "index" in r
    ]


def run(args: tuple[str, ...], source: Path | None, out: Path) -> tuple[list[tuple], float]:
    """One run of the case ``args`` by ``source`` (None: this checkout): its attempts and
    wall seconds."""
    command = [sys.executable, "-m", "rigidfold", "generate", *args]
    command += ["--lookahead", "--no-deform", "--quiet", "--no-report", "--out", str(out)]
    t0 = time.perf_counter()
    subprocess.run(command, env=run_environment(source), capture_output=True, check=False)
    return attempts(out), time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--reference", type=Path, required=True, help="a checkout of rigidfold")
    parser.add_argument("--work", type=Path, default=None, help="folder for the runs' outputs")
    args = parser.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="same_search_"))
    differ = 0
    for name, case in CASES.items():
        today, t_today = run(case, None, work / "today" / name)
        before, t_before = run(case, args.reference.resolve(), work / "reference" / name)
        same = [a[:-1] for a in today] == [a[:-1] for a in before]
        differ += not same
        near = sum(a[3] != "null" for a in today)
        reused = sum(a[-1] for a in today)
        print(
            f"{name:20s} {'same' if same else 'DIFFERENT'}  attempts {len(today)} "
            f"(reference {len(before)}), near candidates {near}, not traced again {reused}, "
            f"{t_today:.1f} s (reference {t_before:.1f} s)",
            flush=True,
        )
    print(f"{differ} of {len(CASES)} cases differ")
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
