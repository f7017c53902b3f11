"""The tables of a study database: Tables 5-8 of the paper and the measures beside them.

Each function asks the :class:`~rigidfold.study.store.Store` for runs and attempts and
returns rows (dicts of numbers); :mod:`rigidfold.study.markdown` writes them as Markdown.
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from collections.abc import Sequence

import numpy as np

from rigidfold.generate import AttemptOutcome, Stop
from rigidfold.selection import CRITERIA
from rigidfold.study.paper import TABLES_5_6, TABLES_7_8
from rigidfold.study.rows import ERROR_PREFIX
from rigidfold.study.runner import PRESETS
from rigidfold.study.store import Store

ORDER = tuple(sorted(CRITERIA, key=[c for _, c in TABLES_5_6].index))
"""The criteria in the order of the rows of the paper's Tables 5 and 6."""
PAPER_PATTERN = {"1p": "1"}
"""Layout variants compared with the paper's table of the pattern they vary."""
LABEL = {"s": "S", "shat": "S-hat", "ss": "S^S", "random": "random"}


def _mean_se(values: Sequence[float | None]) -> tuple[float, float]:
    x = np.asarray([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if len(x) == 0:
        return math.nan, math.nan
    se = float(x.std(ddof=1) / math.sqrt(len(x))) if len(x) > 1 else math.nan
    return float(x.mean()), se


def tables_5_6(store: Store) -> list[dict]:
    """Per (pattern, criterion) of the Bezier study: n, mean and standard error of N_reduce,
    N_lock, N_exceed and F, the runs that reached the target, and the paper's values."""
    runs = [r for r in store.runs("bezier") if r.stop is not None]
    rows = []
    for pattern in sorted({r.pattern for r in runs}):
        for crit in [c for c in ORDER if any(r.criterion == c for r in runs)]:
            sel = [r for r in runs if r.pattern == pattern and r.criterion == crit]
            row = {"pattern": pattern, "criterion": crit, "n": len(sel)}
            for name in ("n_reduce", "n_lock", "n_exceed", "mean_f_accepted"):
                row[name], row[name + "_se"] = _mean_se([getattr(r, name) for r in sel])
            row["reached_target"] = sum(r.stop is Stop.TARGET_REACHED for r in sel)
            row["seeds"] = (min(r.seed for r in sel), max(r.seed for r in sel))
            row["time_total_median"] = float(np.median([r.time_total for r in sel]))
            row["paper"] = TABLES_5_6.get((PAPER_PATTERN.get(pattern, pattern), crit))
            rows.append(row)
    return rows


PAPER_ORDER = ("shat", "s", "random", "ss")  # the paper's ranking by N_lock, best first
PAIRS = (("shat", "s"), ("s", "random"), ("random", "ss"), ("s", "ss"))


def paired_comparisons(store: Store) -> list[dict]:
    """N_lock of two criteria on the same surfaces (paired by seed), per pattern.

    For each pair (a, b) of ``PAIRS``: the seeds both ran, the mean of N_lock(a) - N_lock(b)
    with its standard error, how often a locked less / as often / more, and the two-sided
    Wilcoxon signed-rank p-value (SciPy; 1.0 when every difference is zero).
    """
    from scipy.stats import wilcoxon

    by: dict[tuple[str, str, int], int] = {
        (r.pattern, r.criterion, r.seed): r.n_lock
        for r in store.runs("bezier")
        if r.n_lock is not None
    }
    runs = {(p, c) for p, c, _ in by}
    out = []
    for pattern in sorted({p for p, _ in runs}):
        for a, b in PAIRS:
            seeds = sorted(
                seed for (p, c, seed) in by if p == pattern and c == a and (p, b, seed) in by
            )
            if len(seeds) < 2:
                continue
            d = np.array([float(by[(pattern, a, k)]) - float(by[(pattern, b, k)]) for k in seeds])
            p_value = 1.0 if not d.any() else float(wilcoxon(d).pvalue)
            mean, se = _mean_se(d.tolist())
            out.append(
                {
                    "pattern": pattern,
                    "a": a,
                    "b": b,
                    "n": len(seeds),
                    "mean_diff": mean,
                    "se": se,
                    "less": int((d < 0).sum()),
                    "equal": int((d == 0).sum()),
                    "more": int((d > 0).sum()),
                    "p_value": p_value,
                }
            )
    return out


def costs(store: Store) -> list[dict]:
    """Per (study, pattern, criterion): runs, solves of (6) per run, IPOPT iterations per
    solve, and run times (median and total CPU seconds in the workers)."""
    rows = []
    runs = store.runs()
    groups = sorted({(r.study, r.pattern, r.criterion) for r in runs})
    for study, pattern, crit in groups:
        sel = [r for r in runs if (r.study, r.pattern, r.criterion) == (study, pattern, crit)]
        its = store.solve_means(study, pattern, crit)
        t = [r.time_total for r in sel if r.time_total is not None]
        rows.append(
            {
                "study": study,
                "pattern": pattern,
                "criterion": crit,
                "runs": len(sel),
                "solves_per_run": float(np.mean([r.n_solves or 0 for r in sel])),
                "iterations_per_solve": its[0],
                "solve_s": its[1],
                "median_run_s": float(np.median(t)) if t else math.nan,
                "total_cpu_s": float(np.sum(t)),
            }
        )
    return rows


STAGES = ((6, None), (4, 5), (3, 3), (2, 2))
"""DOF of the shape being reduced, grouped as (low, high) for :func:`locks_by_stage`."""


def stage_label(lo: int, hi: int | None) -> str:
    return f">= {lo}" if hi is None else (f"{lo}" if lo == hi else f"{lo}-{hi}")


def locks_by_stage(store: Store) -> list[dict]:
    """Where the locks happen: per (pattern, criterion) of the Bezier study, mean N_lock per
    run split by the DOF of the accepted shape whose crease was being fixed (:data:`STAGES`),
    and the share of runs that ended with no candidate left."""
    counts: dict[tuple[str, str], dict] = {}
    for group, seed, attempts in store.attempt_runs("bezier", ("dof", "outcome")):
        c = counts.setdefault(group, {"seeds": set(), "locks": [0] * len(STAGES)})
        c["seeds"].add(seed)
        stage = None  # the DOF of the last accepted shape of this run
        for dof, outcome in attempts:
            # a solution retracted later (DEAD_END) was the shape reduced until then
            if outcome in (AttemptOutcome.ACCEPTED, AttemptOutcome.DEAD_END):
                stage = dof
            elif outcome == AttemptOutcome.LOCK and stage is not None:
                for k, (lo, hi) in enumerate(STAGES):
                    if stage >= lo and (hi is None or stage <= hi):
                        c["locks"][k] += 1
    ended = Counter(
        (r.pattern, r.criterion) for r in store.runs("bezier") if r.stop is Stop.NO_CANDIDATE
    )
    return _per_run_rows(
        counts,
        lambda group, c, n: {
            "per_stage": [k / n for k in c["locks"]],
            "no_candidate": ended[group],
        },
    )


def _per_run_rows(counts: dict, fields) -> list[dict]:
    """One row per (pattern, criterion) of ``counts`` (each with its "seeds"), sorted, with
    ``fields(group, counts[group], number of runs)`` merged in."""
    out = []
    for (pattern, crit), c in sorted(counts.items()):
        n = len(c["seeds"])
        out.append(
            {"pattern": pattern, "criterion": crit, "runs": n, **fields((pattern, crit), c, n)}
        )
    return out


STEP_KINDS = ("-1", "0", "+", "<= -2")
"""How one accepted fix changes the DOF, for :func:`dof_steps`."""


def _step_kind(change: int) -> str:
    if change == -1:
        return "-1"
    if change == 0:
        return "0"
    return "+" if change > 0 else "<= -2"


def dof_steps(store: Store) -> list[dict]:
    """How fixing a crease changes the DOF: per (pattern, criterion) of the Bezier study, the
    mean number per run of accepted solutions whose DOF is one less than the shape before
    (the rule), the same, higher, or two or more less (:data:`STEP_KINDS`).

    Fixing a crease that rotates removes one mode of a generic shape; the re-optimised shape
    may however gain modes (e.g. creases that became coplanar), so the DOF can stay or rise
    and the run needs more than one fix per DOF reduced.
    """
    counts: dict[tuple[str, str], dict] = {}
    for group, seed, attempts in store.attempt_runs(
        "bezier", ("dof",), outcome=AttemptOutcome.ACCEPTED
    ):
        c = counts.setdefault(group, {"seeds": set(), "kinds": Counter()})
        c["seeds"].add(seed)
        dofs = [dof for (dof,) in attempts]  # the first solution has no step
        c["kinds"].update(_step_kind(b - a) for a, b in itertools.pairwise(dofs))
    return _per_run_rows(
        counts, lambda group, c, n: {"per_kind": {k: c["kinds"][k] / n for k in STEP_KINDS}}
    )


def criterion_summary(store: Store) -> list[dict]:
    """The figures to compare criteria, and studies with and without look-ahead: per
    (pattern, criterion) of the Bezier study, mean N_reduce, N_lock, N_exceed and F, solves
    of (6) per run, mean N_path and the share of final designs whose folding path reaches the
    flat state, candidates skipped by the look-ahead and fixes of a group of nearly flat
    creases (``Attempt.carried``) per run (None where the database does not store them), and
    the mean selection and total seconds per run."""
    runs = [r for r in store.runs("bezier") if r.stop is not None]
    skipped: dict[tuple[str, str], list[int]] = {}
    carried: dict[tuple[str, str], list[int]] = {}
    for group, _, attempts in store.attempt_runs("bezier", ("skipped", "carried")):
        values = [s for s, _ in attempts if s is not None]
        if values:
            skipped.setdefault(group, []).append(sum(values))
        fixes = [bool(c) for _, c in attempts if c is not None]
        if fixes:
            carried.setdefault(group, []).append(sum(fixes))
    rows = []
    for pattern, crit in sorted({(r.pattern, r.criterion) for r in runs}):
        sel = [r for r in runs if (r.pattern, r.criterion) == (pattern, crit)]
        row: dict = {"pattern": pattern, "criterion": crit, "runs": len(sel)}
        for name in ("n_reduce", "n_lock", "n_exceed", "mean_f_accepted", "n_solves"):
            row[name] = _mean_se([getattr(r, name) for r in sel])[0]
        for name, counts in (("skipped_per_run", skipped), ("groups_per_run", carried)):
            done = counts.get((pattern, crit))
            row[name] = float(np.sum(done)) / len(sel) if done else None
        paths = [r.n_path for r in sel if r.n_path is not None]
        row["n_path"] = _mean_se(paths)[0] if paths else None
        deploys = [r.final_deploys for r in sel if r.final_deploys is not None]
        row["deploys_share"] = float(np.mean(deploys)) if deploys else None
        row["selection_s"] = _mean_se([r.time_selection for r in sel])[0]
        row["run_s"] = _mean_se([r.time_total for r in sel])[0]
        rows.append(row)
    return rows


FOLD_BINS = (0.1, 1.0, 5.0)
"""Bounds (degrees) of the bins of |fold angle| of locked creases (:func:`locked_fold_angles`)."""


def bin_labels() -> list[str]:
    edges = [f"{b:g}" for b in FOLD_BINS]
    return [f"< {edges[0]}", *(f"{a}-{b}" for a, b in itertools.pairwise(edges)), f">= {edges[-1]}"]


def locked_fold_angles(store: Store) -> list[dict]:
    """How folded the locked creases are: per (pattern, criterion) of the Bezier study, the
    locks (attempts with outcome "lock"), the locked creases whose fold angle at the locked
    shape is stored, their count per bin of |angle| (:data:`FOLD_BINS`, degrees) and the median
    |angle|. Locks of databases from before the angles were stored are counted but not
    binned."""
    counts: dict[tuple[str, str], dict] = {}
    for group, seed, attempts in store.attempt_runs("bezier", ("outcome", "locked_fold_deg")):
        c = counts.setdefault(group, {"seeds": set(), "locks": 0, "angles": []})
        c["seeds"].add(seed)
        locks = [angles for outcome, angles in attempts if outcome == AttemptOutcome.LOCK]
        c["locks"] += len(locks)
        c["angles"] += [abs(a) for angles in locks for a in angles or ()]

    def fields(group, c, n) -> dict:
        angles = np.asarray(c["angles"], dtype=float)
        bins = np.searchsorted(FOLD_BINS, angles, side="right")
        return {
            "locks": c["locks"],
            "creases": len(angles),
            "bins": np.bincount(bins, minlength=len(FOLD_BINS) + 1).tolist(),
            "median_deg": float(np.median(angles)) if len(angles) else None,
        }

    return _per_run_rows(counts, fields)


LOCK_CAUSES = ("predicted", "flat before", "missed")
"""Why a lock happened, from the forecast at the shape before the fix (:func:`lock_causes`)."""


def _lock_cause(predicted: list[bool], left: list[float | None]) -> tuple[str, float | None]:
    """The cause of one lock and, for "missed", the smallest rotation left (relative) that
    the forecast gave a locked crease it did not predict."""
    unpredicted = [x for p, x in zip(predicted, left, strict=True) if not p]
    if not unpredicted:
        return "predicted", None
    folded = [x for x in unpredicted if x is not None]
    return ("missed", min(folded)) if folded else ("flat before", None)


def lock_causes(store: Store) -> list[dict]:
    """Why the locks happen: per (pattern, criterion) of the Bezier study, the locks by cause
    (:data:`LOCK_CAUSES`): every locked crease was predicted by the first-order forecast at
    the shape before the fix (without look-ahead: a lock it would have skipped; with it: a
    candidate tried once every other had failed); a locked crease it did not predict was flat
    there (no forecast is made for flat creases); or it was folded and kept rotations at first
    order, and the re-optimised shape locked it ("missed", with the median of the smallest
    rotation left, relative, that the forecast gave such a crease). Locks without the forecast
    stored (earlier databases) count as "unknown"."""
    counts: dict[tuple[str, str], dict] = {}
    columns = ("outcome", "locked_predicted", "locked_left")
    for group, seed, attempts in store.attempt_runs("bezier", columns):
        c = counts.setdefault(group, {"seeds": set(), "causes": Counter(), "left": []})
        c["seeds"].add(seed)
        for _, predicted, left in (a for a in attempts if a[0] == AttemptOutcome.LOCK):
            if not predicted:
                c["causes"]["unknown"] += 1
                continue
            cause, smallest = _lock_cause(predicted, left)
            c["causes"][cause] += 1
            if smallest is not None:
                c["left"].append(smallest)

    def fields(group, c, n) -> dict:
        return {
            "locks": sum(c["causes"].values()),
            "causes": {k: c["causes"][k] for k in (*LOCK_CAUSES, "unknown")},
            "missed_left_median": float(np.median(c["left"])) if c["left"] else None,
        }

    return _per_run_rows(counts, fields)


def failed_runs(store: Store) -> list[dict]:
    """The runs stored with an error (status "error: <message>"), ordered by key: study,
    seed, pattern, criterion, symmetric (bool) and ``error`` (the message)."""
    return [
        {
            **{k: getattr(r, k) for k in ("study", "seed", "pattern", "criterion")},
            "symmetric": bool(r.symmetric),
            "error": r.status.removeprefix(ERROR_PREFIX),
        }
        for r in store.runs()
        if r.stop is None
    ]


def tables_7_8(store: Store) -> list[dict]:
    """Per preset run (dome / hp, with / without symmetry): the rows of Tables 7 and 8."""
    out = []
    for r in store.runs():
        if r.study not in PRESETS:
            continue
        values = (
            r.n_lock,
            r.n_exceed,
            r.final_dof,
            r.n_solves,
            r.mean_f_accepted,
            r.mean_d,
            r.mean_dl_mm,
            r.mean_drho_fix_deg,
        )
        out.append(
            {
                "preset": r.study,
                "symmetric": bool(r.symmetric),
                "values": values,
                "status": r.status,
                "time_total": r.time_total,
                "paper": TABLES_7_8.get((r.study, bool(r.symmetric))),
            }
        )
    return out
