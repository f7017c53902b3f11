"""Reports of a study database: Tables 5-8 beside the paper's, and box plots of N_lock.

``tables_5_6`` and ``tables_7_8`` compute the numbers; ``write_report`` writes Markdown and
PNG figures (matplotlib, imported only here).
"""

from __future__ import annotations

import io
import itertools
import math
import re
from collections import Counter
from pathlib import Path

import numpy as np

from rigidfold.generate import AttemptOutcome, Stop
from rigidfold.io import atomic_write, prepare_output_dir
from rigidfold.selection import CRITERIA
from rigidfold.study.paper import CITATION, TABLE_7_8_ROWS, TABLES_5_6, TABLES_7_8
from rigidfold.study.runner import PRESETS
from rigidfold.study.store import ERROR_PREFIX, Store, run_stop

ORDER = tuple(sorted(CRITERIA, key=[c for _, c in TABLES_5_6].index))
"""The criteria in the order of the rows of the paper's Tables 5 and 6."""
PAPER_PATTERN = {"1p": "1"}
"""Layout variants compared with the paper's table of the pattern they vary."""
LABEL = {"s": "S", "shat": "S-hat", "ss": "S^S", "random": "random"}

_MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]|~@])")
"""Characters that make Markdown (GitHub's included) of text: escaped with a backslash."""


def _one_line(text: str) -> str:
    """``text`` with every character that is not printable (newlines, ESC, ...) written as
    its Python escape (``\\n``, ``\\x1b``)."""
    return "".join(
        c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text
    )


def md_text(value) -> str:
    """``str(value)`` as literal text in Markdown, a table cell included: one line
    (:func:`_one_line`); HTML's ``&``, ``<`` and ``>`` as entities (no tag, no script); the
    characters of :data:`_MARKDOWN_SPECIAL` escaped (no emphasis, link, image or code, no
    cell break); and no link made of a URL (``://`` and ``www.`` broken by an escape). A
    pattern named ``q<img src=x onerror=...>.fold`` or ``a|b.fold`` reads as its name."""
    text = _one_line(str(value))
    text = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    text = _MARKDOWN_SPECIAL.sub(r"\\\1", text)
    return re.sub(r"(?i)(?<=www)\.", r"\\.", text.replace("://", r":\/\/"))


def md_code(value, *, cell: bool = False) -> str:
    """``str(value)`` as a Markdown code span, on one line: fenced by more backticks than
    it holds in a row, and in a table ``cell`` its ``|`` escaped (GitHub reads ``\\|``
    there as ``|``, also in code)."""
    text = _one_line(str(value))
    if cell:
        text = text.replace("|", "\\|")
    fence = "`" * (max((len(run) for run in re.findall("`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def _mean_se(values: list[float]) -> tuple[float, float]:
    x = np.asarray([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if len(x) == 0:
        return math.nan, math.nan
    se = float(x.std(ddof=1) / math.sqrt(len(x))) if len(x) > 1 else math.nan
    return float(x.mean()), se


def tables_5_6(store: Store) -> list[dict]:
    """Per (pattern, criterion) of the Bezier study: n, mean and standard error of N_reduce,
    N_lock, N_exceed and F, the runs that reached the target, and the paper's values."""
    runs = [r for r in store.runs("bezier") if run_stop(r["status"]) is not None]
    rows = []
    for pattern in sorted({r["pattern"] for r in runs}):
        for crit in [c for c in ORDER if any(r["criterion"] == c for r in runs)]:
            sel = [r for r in runs if r["pattern"] == pattern and r["criterion"] == crit]
            row = {"pattern": pattern, "criterion": crit, "n": len(sel)}
            for name in ("n_reduce", "n_lock", "n_exceed", "mean_f"):
                row[name], row[name + "_se"] = _mean_se([r[name] for r in sel])
            row["reached_target"] = sum(run_stop(r["status"]) is Stop.TARGET_REACHED for r in sel)
            row["seeds"] = (min(r["seed"] for r in sel), max(r["seed"] for r in sel))
            row["time_total_median"] = float(np.median([r["time_total"] for r in sel]))
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

    runs = [r for r in store.runs("bezier") if r["n_lock"] is not None]
    by = {(r["pattern"], r["criterion"], r["seed"]): r["n_lock"] for r in runs}
    out = []
    for pattern in sorted({r["pattern"] for r in runs}):
        for a, b in PAIRS:
            seeds = sorted(
                seed for (p, c, seed) in by if p == pattern and c == a and (p, b, seed) in by
            )
            if len(seeds) < 2:
                continue
            d = np.array([by[(pattern, a, k)] - by[(pattern, b, k)] for k in seeds], dtype=float)
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
    groups = sorted({(r["study"], r["pattern"], r["criterion"]) for r in runs})
    for study, pattern, crit in groups:
        sel = [
            r for r in runs if (r["study"], r["pattern"], r["criterion"]) == (study, pattern, crit)
        ]
        its = store.solve_means(study, pattern, crit)
        t = [r["time_total"] for r in sel if r["time_total"] is not None]
        rows.append(
            {
                "study": study,
                "pattern": pattern,
                "criterion": crit,
                "runs": len(sel),
                "solves_per_run": float(np.mean([r["n_solves"] or 0 for r in sel])),
                "iterations_per_solve": its[0],
                "solve_s": its[1],
                "median_run_s": float(np.median(t)) if t else math.nan,
                "total_cpu_s": float(np.sum(t)),
            }
        )
    return rows


STAGES = ((6, None), (4, 5), (3, 3), (2, 2))
"""DOF of the shape being reduced, grouped as (low, high) for :func:`locks_by_stage`."""


def _stage_label(lo: int, hi: int | None) -> str:
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
            if outcome == AttemptOutcome.ACCEPTED:
                stage = dof
            elif outcome == AttemptOutcome.LOCK and stage is not None:
                for k, (lo, hi) in enumerate(STAGES):
                    if stage >= lo and (hi is None or stage <= hi):
                        c["locks"][k] += 1
    ended = Counter(
        (r["pattern"], r["criterion"])
        for r in store.runs("bezier")
        if run_stop(r["status"]) is Stop.NO_CANDIDATE
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
    runs = [r for r in store.runs("bezier") if run_stop(r["status"]) is not None]
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
    for pattern, crit in sorted({(r["pattern"], r["criterion"]) for r in runs}):
        sel = [r for r in runs if (r["pattern"], r["criterion"]) == (pattern, crit)]
        row: dict = {"pattern": pattern, "criterion": crit, "runs": len(sel)}
        for name in ("n_reduce", "n_lock", "n_exceed", "mean_f", "n_solves"):
            row[name] = _mean_se([r[name] for r in sel])[0]
        for name, counts in (("skipped_per_run", skipped), ("groups_per_run", carried)):
            done = counts.get((pattern, crit))
            row[name] = float(np.sum(done)) / len(sel) if done else None
        paths = [r["n_path"] for r in sel if r.get("n_path") is not None]
        row["n_path"] = _mean_se(paths)[0] if paths else None
        deploys = [r["final_deploys"] for r in sel if r.get("final_deploys") is not None]
        row["deploys_share"] = float(np.mean(deploys)) if deploys else None
        row["selection_s"] = _mean_se([r["time_selection"] for r in sel])[0]
        row["run_s"] = _mean_se([r["time_total"] for r in sel])[0]
        rows.append(row)
    return rows


FOLD_BINS = (0.1, 1.0, 5.0)
"""Bounds (degrees) of the bins of |fold angle| of locked creases (:func:`locked_fold_angles`)."""


def _bin_labels() -> list[str]:
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
            **{k: r[k] for k in ("study", "seed", "pattern", "criterion")},
            "symmetric": bool(r["symmetric"]),
            "error": r["status"].removeprefix(ERROR_PREFIX),
        }
        for r in store.runs()
        if run_stop(r["status"]) is None
    ]


def tables_7_8(store: Store) -> list[dict]:
    """Per preset run (dome / hp, with / without symmetry): the rows of Tables 7 and 8."""
    out = []
    for r in store.runs():
        if r["study"] not in PRESETS:
            continue
        values = (
            r["n_lock"],
            r["n_exceed"],
            r["final_dof"],
            r["n_solves"],
            r["mean_f"],
            r["mean_d"],
            r["mean_dl_mm"],
            r["mean_drho_fix_deg"],
        )
        out.append(
            {
                "preset": r["study"],
                "symmetric": bool(r["symmetric"]),
                "values": values,
                "status": r["status"],
                "time_total": r["time_total"],
                "paper": TABLES_7_8.get((r["study"], bool(r["symmetric"]))),
            }
        )
    return out


def _fmt(x, se=None, digits=2) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float) and (abs(x) < 1e-2 and x != 0):
        s = f"{x:.2e}"
    elif isinstance(x, float):
        s = f"{x:.{digits}f}"
    else:
        s = str(x)
    if se is not None and not math.isnan(se):
        s += f" ± {se:.2e}" if abs(se) < 1e-2 and se != 0 else f" ± {se:.{digits}f}"
    return s


def markdown(stores: Store | list[Store], figures: list[dict] | dict | None = None) -> str:
    """The report of one or several databases as Markdown.

    figures : per database, pattern -> PNG file name to link (from :func:`box_plots`).
    """
    stores = [stores] if isinstance(stores, Store) else list(stores)
    if isinstance(figures, dict) or figures is None:
        figures = [figures or {}] * len(stores)
    lines = [f"Paper values: {CITATION}.", ""]
    for store, figs in zip(stores, figures, strict=True):
        if len(stores) > 1:
            lines += [f"## {md_text(store.path.name)}", ""]
        lines += _configuration_lines(store)
        lines += _store_lines(store, figs)
    return "\n".join(lines)


def _configuration_lines(store: Store) -> list[str]:
    config = store.config() or {}
    versions = sorted({r["version"] for r in store.runs()})
    if not config:
        return []
    from rigidfold.study.store import LEGACY_CONFIG, LEGACY_SETTINGS

    settings = config.get("settings") or {}
    hessian = settings.get("ipopt_hessian", LEGACY_SETTINGS["ipopt_hessian"])
    solver = config.get("solver")
    if solver == "ipopt":
        solver = f"ipopt ({hessian} Hessian)"
    lookahead = config.get("lookahead", LEGACY_CONFIG["lookahead"])
    return [
        f"Configuration: solver {md_text(solver)}, target DOF {md_text(config.get('target_dof'))}, "
        f"Steps 8-9 {'on' if config.get('deform') else 'off'}, "
        f"look-ahead {'on' if lookahead else 'off'}; {len(store.runs())} runs, "
        f"{store.count_attempts()} solves of (6); rigidfold "
        f"{', '.join(md_text(v) for v in versions) or '-'}.",
        "",
        *_numerics_lines(store),
    ]


def _numerics_lines(store: Store) -> list[str]:
    """Which numeric environments computed the runs (rigidfold.numerics); none before they
    were recorded."""
    numerics = store.numerics()
    keys = {r.get("numerics") for r in store.runs()} - {None}
    if numerics is None and not keys:
        return []
    status = (numerics or {}).get("status", "?")
    key = (numerics or {}).get("key", "?")
    mixed = f"; the runs come from {len(keys)} numeric environments" if len(keys) > 1 else ""
    return [f"Numerics: {md_text(status)}, {md_code(key)}{mixed}.", ""]


def _store_lines(store: Store, figures: dict[str, str]) -> list[str]:
    lines: list[str] = []
    t56 = tables_5_6(store)
    for pattern in sorted({r["pattern"] for r in t56}):
        rows = [r for r in t56 if r["pattern"] == pattern]
        lo, hi = rows[0]["seeds"]
        number = {"1": "Table 5", "2": "Table 6"}.get(PAPER_PATTERN.get(pattern, pattern), "")
        lines += [
            f"### Crease pattern {md_text(pattern)}" + (f" (paper's {number})" if number else ""),
            "",
            f"Bezier seeds {lo}-{hi}; mean ± standard error over runs; paper: 100 surfaces.",
            "",
            "| criterion | runs | N_reduce | N_lock | N_exceed | mean F | reached DOF target "
            "| paper N_reduce | paper N_lock | paper N_exceed | paper F |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in rows:
            p = r["paper"] or (None,) * 4
            lines.append(
                f"| {LABEL[r['criterion']]} | {r['n']} | {_fmt(r['n_reduce'], r['n_reduce_se'])} "
                f"| {_fmt(r['n_lock'], r['n_lock_se'])} | {_fmt(r['n_exceed'], r['n_exceed_se'])} "
                f"| {_fmt(r['mean_f'])} | {r['reached_target']}/{r['n']} "
                f"| {_fmt(p[0])} | {_fmt(p[1])} | {_fmt(p[2])} | {_fmt(p[3])} |"
            )
        if pattern in figures:
            alt = f"N_lock per criterion, pattern {md_text(pattern)}"
            lines += ["", f"![{alt}]({figures[pattern]})"]  # a file name: figure_name
        lines.append("")
    pairs = paired_comparisons(store)
    if pairs:
        lines += _ordering_lines(t56, pairs)
    sections = (
        (locks_by_stage, _stage_lines),
        (dof_steps, _step_lines),
        (criterion_summary, _summary_lines),
        (locked_fold_angles, _angle_lines),
        (lock_causes, _cause_lines),
    )
    for compute, write in sections:
        found = compute(store)
        if found:
            lines += write(found)
    lost = failed_runs(store)
    if lost:
        lines += _section(
            "Runs that failed",
            ["study", "seed", "pattern", "criterion", "symmetric", "why"],
            [
                [
                    *(r[k] for k in ("study", "seed", "pattern", "criterion", "symmetric")),
                    r["error"],
                ]
                for r in lost
            ],
        )
    t78 = tables_7_8(store)
    for name, number in (("dome", "Table 7"), ("hp", "Table 8")):
        runs = [r for r in t78 if r["preset"] == name]
        if not runs:
            continue
        runs.sort(key=lambda r: not r["symmetric"])
        head = " | ".join(
            f"{'symmetric' if r['symmetric'] else 'asymmetric'} | paper" for r in runs
        )
        lines += [
            f"### {name.upper() if name == 'hp' else 'Dome'} (paper's {number}), criterion S, "
            "11 x 11 grid",
            "",
            f"| | {head} |",
            "|---|" + "---|---|" * len(runs),
        ]
        for k, label in enumerate(TABLE_7_8_ROWS):
            cells = " | ".join(
                f"{_fmt(r['values'][k])} | {_fmt(r['paper'][k]) if r['paper'] else '-'}"
                for r in runs
            )
            cell = label.replace("|", "\\|")  # |dl| inside a Markdown table cell
            lines.append(f"| {cell} | {cells} |")
        lines.append("")
    lines += _cost_lines(store)
    return lines


def _ordering_lines(t56: list[dict], pairs: list[dict]) -> list[str]:
    lines = ["### Ordering of N_lock", ""]
    paper = " <= ".join(LABEL[c] for c in PAPER_ORDER)
    for pattern in sorted({r["pattern"] for r in t56}):
        rows = sorted(
            (r for r in t56 if r["pattern"] == pattern), key=lambda r: (r["n_lock"], r["criterion"])
        )
        ours = f"{LABEL[rows[0]['criterion']]} ({rows[0]['n_lock']:.2f})"
        for prev, r in itertools.pairwise(rows):
            sign = "=" if r["n_lock"] == prev["n_lock"] else "<"
            ours += f" {sign} {LABEL[r['criterion']]} ({r['n_lock']:.2f})"
        same = [r["criterion"] for r in rows] == [
            c for c in PAPER_ORDER if any(r["criterion"] == c for r in rows)
        ]
        lines.append(
            f"- Pattern {md_text(pattern)}: {ours}; "
            + ("the paper's order." if same else f"the paper's order is {paper}.")
        )
    lines += [
        "",
        "Paired by surface (same seed): mean difference of N_lock, how often the first "
        "criterion locked less / as often / more, and the two-sided Wilcoxon signed-rank p-value.",
        "",
        "| pattern | pair | surfaces | mean difference | less / equal / more | p |",
        "|---|---|---|---|---|---|",
    ]
    for c in pairs:
        lines.append(
            f"| {md_text(c['pattern'])} | {LABEL[c['a']]} - {LABEL[c['b']]} | {c['n']} "
            f"| {_fmt(c['mean_diff'], c['se'])} | {c['less']} / {c['equal']} / {c['more']} "
            f"| {c['p_value']:.2g} |"
        )
    return [*lines, ""]


SECTION_TEXT = {
    "Where the locks happen": (
        "Mean N_lock per run by the DOF of the accepted shape whose crease was being fixed, and "
        "the runs that ended because every candidate crease locked (or missed F_tol)."
    ),
    "How fixing a crease changes the DOF": (
        "Mean number of accepted solutions per run by the change of DOF from the shape before "
        "(one more fixed crease): a generic shape loses one mode (-1); after a 0 or + step the "
        "re-optimised shape has as many or more modes, and the run needs more than one fix per "
        "DOF reduced."
    ),
    "Summary per criterion": (
        "Means per run; skipped: candidates the look-ahead skipped (predicted to lock, or "
        "locked at an earlier shape; not solved); groups: fixes of a skipped candidate "
        "together with the nearly flat creases it would lock; selection: ranking (and "
        "look-ahead) time, CPU ms per run; run: CPU s per run in the workers."
    ),
    "Fold angles of the locked creases": (
        "Locked creases of every lock by |fold angle| at the locked shape (degrees): nearly "
        "flat creases or real folds."
    ),
    "Runs that failed": (
        "Runs stored with an error instead of results (no numbers of theirs in the tables): a "
        "configuration that cannot run, or a run whose Dask workers died every time it was "
        "tried. A later `rigidfold study` does not run them again."
    ),
    "Why the locks happen": (
        "Each lock against the first-order forecast at the shape before the fix: every locked "
        "crease predicted (without look-ahead: a lock it would skip; with it: tried once every "
        "other candidate had failed), a locked crease flat before (not forecast), or missed "
        "(the re-optimised shape locked a crease that kept rotations at first order; median of "
        "its rotation left relative to the largest, against `lookahead_tol`)."
    ),
}
"""The paragraph under the title of each section written by :func:`_section`."""


def _section(title: str, head: list[str], rows: list[list]) -> list[str]:
    """A Markdown section of the report: its title, its paragraph (:data:`SECTION_TEXT`) and a
    table (``head``: the column titles, ``rows``: one list of cells each, written as text:
    :func:`md_text`)."""
    return [
        f"### {title}",
        "",
        SECTION_TEXT[title],
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
        *("| " + " | ".join(md_text(cell) for cell in row) + " |" for row in rows),
        "",
    ]


GROUP_HEAD = ("pattern", "criterion", "runs")


def _group_cells(r: dict) -> list:
    """The first cells of a per-(pattern, criterion) row: :data:`GROUP_HEAD`."""
    return [r["pattern"], LABEL.get(r["criterion"], r["criterion"]), r["runs"]]


def _stage_lines(stages: list[dict]) -> list[str]:
    return _section(
        "Where the locks happen",
        [
            *GROUP_HEAD,
            *(f"DOF {_stage_label(lo, hi)}" for lo, hi in STAGES),
            "ended with no candidate",
        ],
        [
            _group_cells(r)
            + [f"{v:.2f}" for v in r["per_stage"]]
            + [f"{r['no_candidate']}/{r['runs']}"]
            for r in stages
        ],
    )


def _step_lines(steps: list[dict]) -> list[str]:
    return _section(
        "How fixing a crease changes the DOF",
        [*GROUP_HEAD, *(f"DOF {k}" for k in STEP_KINDS)],
        [_group_cells(r) + [f"{r['per_kind'][k]:.2f}" for k in STEP_KINDS] for r in steps],
    )


def _summary_lines(rows: list[dict]) -> list[str]:
    return _section(
        "Summary per criterion",
        [
            *GROUP_HEAD,
            *("N_reduce", "N_lock", "N_exceed", "N_path", "deploys", "mean F", "solves"),
            *("skipped", "groups", "selection ms", "run s"),
        ],
        [
            _group_cells(r)
            + [_fmt(r[k]) for k in ("n_reduce", "n_lock", "n_exceed", "n_path")]
            + [
                "-" if r["deploys_share"] is None else f"{100 * r['deploys_share']:.0f} %",
                _fmt(r["mean_f"]),
            ]
            + [_fmt(r["n_solves"], digits=1), _fmt(r["skipped_per_run"])]
            + [_fmt(r["groups_per_run"])]
            + [_fmt(r["selection_s"] * 1e3, digits=1), _fmt(r["run_s"], digits=1)]
            for r in rows
        ],
    )


def _angle_lines(rows: list[dict]) -> list[str]:
    return _section(
        "Fold angles of the locked creases",
        [*GROUP_HEAD, "locks", "locked creases", *_bin_labels(), "median"],
        [
            _group_cells(r)
            + [r["locks"], r["creases"]]
            + [b if r["creases"] else "-" for b in r["bins"]]
            + [_fmt(r["median_deg"], digits=3)]
            for r in rows
        ],
    )


def _cause_lines(rows: list[dict]) -> list[str]:
    return _section(
        "Why the locks happen",
        [*GROUP_HEAD, "locks", *LOCK_CAUSES, "unknown", "missed: rotation left"],
        [
            _group_cells(r)
            + [r["locks"]]
            + [r["causes"][k] for k in (*LOCK_CAUSES, "unknown")]
            + [_fmt(r["missed_left_median"])]
            for r in rows
        ],
    )


def _cost_lines(store: Store) -> list[str]:
    lines = [
        "### Cost",
        "",
        "CPU seconds in the workers (one thread each); a solve is one solution of problem (6).",
        "",
        "| study | pattern | criterion | runs | solves per run | IPOPT iterations per solve "
        "| s per solve | median s per run | total CPU s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for c in costs(store):
        lines.append(
            f"| {md_text(c['study'])} | {md_text(c['pattern'])} "
            f"| {md_text(LABEL.get(c['criterion'], c['criterion']))} "
            f"| {c['runs']} | {c['solves_per_run']:.1f} "
            f"| {_fmt(c['iterations_per_solve'], digits=1)} "
            f"| {_fmt(c['solve_s'], digits=3)} | {_fmt(c['median_run_s'], digits=1)} "
            f"| {c['total_cpu_s']:.0f} |"
        )
    inv = store.invocations()
    if inv:
        lines += [
            "",
            "Commands that ran on this database (wall time of each command):",
            "",
            "| started (UTC) | command | workers | runs done / already there / in the study "
            "| wall s | outcome | version |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in inv:
            where = r["workers"] if r["workers"] is not None else f"scheduler {r['scheduler']}"
            lines.append(
                f"| {md_text(r['started'])} | {md_code(' '.join(map(str, r['argv'])), cell=True)} "
                f"| {md_text(where)} | {r['ran']} / {r['skipped']} / {r['total']} "
                f"| {r['wall_s']:.0f} | {md_text(r['outcome'])} | {md_text(r['version'])} |"
            )
    return [*lines, ""]


def figure_name(text: str, used: set[str]) -> str:
    """A file name for a figure of ``text`` (a pattern spec, a database name): its letters,
    digits, ``.``, ``-`` and ``_``, any other run of characters (``/``, ``:``, ``#``, spaces)
    one ``_``, then ``.png``; made unique among ``used`` (``_2``, ``_3``, ...) and added to it.
    """
    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._")[:120] or "figure"
    name, n = f"{slug}.png", 1
    while name.lower() in used:  # lower: distinct on case-insensitive file systems too
        n += 1
        name = f"{slug}_{n}.png"
    used.add(name.lower())
    return name


def box_plots(
    store: Store, out: Path, prefix: str = "", used: set[str] | None = None
) -> dict[str, str]:
    """One PNG per pattern: N_lock per criterion. Returns pattern -> file name, a slug of
    ``prefix`` and the pattern's spec (:func:`figure_name`: a spec with a directory,
    ``sub/t.fold``, names a file in ``out``), unique among ``used``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [r for r in store.runs("bezier") if r["n_lock"] is not None]
    files = {}
    used = set() if used is None else used
    for pattern in sorted({r["pattern"] for r in runs}):
        crits = [
            c for c in ORDER if any(r["criterion"] == c and r["pattern"] == pattern for r in runs)
        ]
        data = [
            [r["n_lock"] for r in runs if r["pattern"] == pattern and r["criterion"] == c]
            for c in crits
        ]
        fig, ax = plt.subplots(figsize=(5, 3.5), dpi=120)
        ax.boxplot(data, tick_labels=[LABEL[c] for c in crits])
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_ylabel("N_lock per run")
        shown = _one_line(pattern).replace("$", r"\$")  # text, not matplotlib's mathtext
        ax.set_title(f"Pattern {shown}: N_lock per run, {len(data[0])} surfaces", fontsize=10)
        fig.tight_layout()
        name = figure_name(f"{prefix}n_lock_pattern_{pattern}", used)
        png = io.BytesIO()
        fig.savefig(png, format="png")
        plt.close(fig)
        atomic_write(out / name, png.getvalue())  # like every other file: no link followed
        files[pattern] = name
    return files


def write_report(stores: Store | list[Store], out: str | Path) -> Path:
    """Write DIR/results.md and the box plots of one or several databases; returns the
    Markdown path. With several databases the figures are prefixed by the database's name."""

    stores = [stores] if isinstance(stores, Store) else list(stores)
    out = prepare_output_dir(out)
    used: set[str] = set()
    figures = [
        box_plots(s, out, prefix=f"{s.path.stem}_" if len(stores) > 1 else "", used=used)
        for s in stores
    ]
    path = out / "results.md"
    return atomic_write(path, "# rigidfold study report\n\n" + markdown(stores, figures) + "\n")
