"""Where failed runs stop: the DOF of their last shapes counted two ways (session 26).

For every run folder under the given folders (``broad_set.py --keep`` writes them) that did
not reach its target, the last three solutions at its lowest DOF are analysed with the gap
count the search uses (near-mechanisms count: ``mechanism_rank_tol`` x ``dof_gap``) and at
the rank threshold itself (the exact mechanisms). A shape of gap DOF d with d_0 < d exact
mechanisms has near-mechanisms; d_0 = 0: rigid but for them.

Run with ``python benchmarks/dof_census.py FOLDER [FOLDER ...]``; each line: the run, its
stop, its lowest DOF, and (gap, exact) for those shapes, the last one last; at the end, how
many runs' last shape has no exact mechanism, one or more.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

from rigidfold.config import DEFAULTS
from rigidfold.io.fold import pattern_from_fold
from rigidfold.mechanism import analyze


def census(run: Path) -> tuple[str, int, list[tuple[int, int]]] | None:
    """(stop, lowest DOF, [(gap DOF, exact DOF)] of the last three shapes at it) of a run
    folder that did not reach its target; None for one that did, or has no solution."""
    summary = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    low = summary.get("lowest_dof")
    if summary.get("stop") == "target_reached" or low is None:
        return None
    m = DEFAULTS.mechanism
    gap = DEFAULTS.with_(mechanism_rank_tol=m.rank_tol * m.dof_gap)
    counts = []
    for f in sorted(run.glob(f"solutions/step_*_dof_{low:02d}.fold"))[-3:]:
        shape = pattern_from_fold(f)
        counts.append((analyze(shape, settings=gap).dof, analyze(shape).dof))
    return summary["stop"], low, counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path)
    args = parser.parse_args()
    last: Counter = Counter()
    for folder in args.folders:
        for s in sorted(folder.rglob("summary.json")):
            found = census(s.parent)
            if found is None or not found[2]:
                continue
            stop, low, counts = found
            print(
                f"{s.parent.relative_to(folder)}  {stop}  lowest DOF {low}  (gap, exact): {counts}"
            )
            last["no exact mechanism" if counts[-1][1] == 0 else "exact mechanisms"] += 1
    print(dict(last))


if __name__ == "__main__":
    main()
