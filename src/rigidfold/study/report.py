"""Reports of a study database: Tables 5-8 beside the paper's, and box plots of N_lock.

``tables_5_6`` and ``tables_7_8`` compute the numbers; ``write_report`` writes Markdown and
PNG figures (matplotlib, imported only here).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rigidfold.study.paper import CITATION, TABLE_7_8_ROWS, TABLES_5_6, TABLES_7_8
from rigidfold.study.store import Store

ORDER = ("s", "shat", "ss", "random")
LABEL = {"s": "S", "shat": "S-hat", "ss": "S^S", "random": "random"}


def _mean_se(values: list[float]) -> tuple[float, float]:
    x = np.asarray([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if len(x) == 0:
        return math.nan, math.nan
    se = float(x.std(ddof=1) / math.sqrt(len(x))) if len(x) > 1 else math.nan
    return float(x.mean()), se


def tables_5_6(store: Store) -> list[dict]:
    """Per (pattern, criterion) of the Bezier study: n, mean and standard error of N_reduce,
    N_lock, N_exceed and F, the runs that reached the target, and the paper's values."""
    runs = [r for r in store.runs("bezier") if not r["status"].startswith("error")]
    rows = []
    for pattern in sorted({r["pattern"] for r in runs}):
        for crit in [c for c in ORDER if any(r["criterion"] == c for r in runs)]:
            sel = [r for r in runs if r["pattern"] == pattern and r["criterion"] == crit]
            row = {"pattern": pattern, "criterion": crit, "n": len(sel)}
            for name in ("n_reduce", "n_lock", "n_exceed", "mean_f"):
                row[name], row[name + "_se"] = _mean_se([r[name] for r in sel])
            row["reached_target"] = sum(r["status"].startswith("target DOF") for r in sel)
            row["seeds"] = (min(r["seed"] for r in sel), max(r["seed"] for r in sel))
            row["time_total_median"] = float(np.median([r["time_total"] for r in sel]))
            row["paper"] = TABLES_5_6.get((pattern, crit))
            rows.append(row)
    return rows


def tables_7_8(store: Store) -> list[dict]:
    """Per preset run (dome / hp, with / without symmetry): the rows of Tables 7 and 8."""
    out = []
    for r in store.runs():
        if r["study"] not in ("dome", "hp"):
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


def markdown(store: Store, figures: dict[str, str] | None = None) -> str:
    """The report as Markdown (figures: pattern -> PNG file name to link)."""
    lines = [f"Paper values: {CITATION}.", ""]
    t56 = tables_5_6(store)
    for pattern in sorted({r["pattern"] for r in t56}):
        rows = [r for r in t56 if r["pattern"] == pattern]
        lo, hi = rows[0]["seeds"]
        number = {"1": "Table 5", "2": "Table 6"}.get(pattern, "")
        lines += [
            f"### Crease pattern {pattern}" + (f" (paper's {number})" if number else ""),
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
        if figures and pattern in figures:
            lines += ["", f"![N_lock per criterion, pattern {pattern}]({figures[pattern]})"]
        lines.append("")
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
            lines.append(f"| {label} | {cells} |")
        lines.append("")
    return "\n".join(lines)


def box_plots(store: Store, out: Path) -> dict[str, str]:
    """One PNG per pattern: N_lock per criterion. Returns pattern -> file name."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [r for r in store.runs("bezier") if r["n_lock"] is not None]
    files = {}
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
        ax.set_title(f"Crease pattern {pattern}: locked shapes per run ({len(data[0])} surfaces)")
        fig.tight_layout()
        name = f"n_lock_pattern_{pattern}.png"
        fig.savefig(out / name)
        plt.close(fig)
        files[pattern] = name
    return files


def write_report(store: Store, out: str | Path) -> Path:
    """Write DIR/results.md and the box plots; returns the Markdown path."""
    from rigidfold.case import prepare_output_dir

    out = prepare_output_dir(out)
    figures = box_plots(store, out)
    path = out / "results.md"
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("# rigidfold study report\n\n" + markdown(store, figures) + "\n")
    tmp.replace(path)
    return path
