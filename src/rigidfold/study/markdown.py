"""A study's report as Markdown (``results.md``) and PNG box plots of N_lock.

The numbers come from :mod:`rigidfold.study.tables`; this module words and draws them
(matplotlib, imported only here). Every text from a database (pattern names, messages) is
written as text, never as Markdown (:func:`md_text`, :func:`md_code`).
"""

from __future__ import annotations

import io
import itertools
import math
import re
from pathlib import Path

from rigidfold.io import atomic_write, prepare_output_dir
from rigidfold.study.paper import CITATION, TABLE_7_8_ROWS
from rigidfold.study.store import Store
from rigidfold.study.tables import (
    LABEL,
    LOCK_CAUSES,
    ORDER,
    PAPER_ORDER,
    PAPER_PATTERN,
    STAGES,
    STEP_KINDS,
    bin_labels,
    costs,
    criterion_summary,
    dof_steps,
    failed_runs,
    lock_causes,
    locked_fold_angles,
    locks_by_stage,
    paired_comparisons,
    stage_label,
    tables_5_6,
    tables_7_8,
)

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
    versions = sorted({r.version for r in store.runs()})
    if not config:
        return []
    settings = config.get("settings") or {}
    solver = config.get("solver")
    if solver == "ipopt":
        solver = f"ipopt ({settings.get('ipopt_hessian')} Hessian)"
    lookahead = config.get("lookahead")
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
    """Which numeric environments computed the runs (rigidfold.runtime.numerics); none before they
    were recorded."""
    numerics = store.numerics()
    keys = {r.numerics for r in store.runs()} - {None}
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
                f"| {_fmt(r['mean_f_accepted'])} | {r['reached_target']}/{r['n']} "
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
            *(f"DOF {stage_label(lo, hi)}" for lo, hi in STAGES),
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
                _fmt(r["mean_f_accepted"]),
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
        [*GROUP_HEAD, "locks", "locked creases", *bin_labels(), "median"],
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

    runs = [r for r in store.runs("bezier") if r.n_lock is not None]
    files = {}
    used = set() if used is None else used
    for pattern in sorted({r.pattern for r in runs}):
        crits = [c for c in ORDER if any(r.criterion == c and r.pattern == pattern for r in runs)]
        data = [
            [float(r.n_lock or 0) for r in runs if r.pattern == pattern and r.criterion == c]
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
