"""Paper-style figures of a generate run (matplotlib, Agg backend, PNG).

:func:`render_figures` draws, as far as the run has the data: the final design's development
diagram with mountain, valley and fixed lines; DOF and F per attempt with the lock events
marked; the surface fit (max and RMS |z - target|) per solution; the final design's fold
angles; its large-deformation history (Step 9). matplotlib is imported only when drawing.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np

from rigidfold.rundir import RunData, SolutionFile

KINDS = {
    "F": ("flat crease", "#bbbbbb", 0.6, "-"),
    "J": ("fixed crease", "#2ca02c", 2.0, "-"),
    "M": ("mountain", "#d62728", 1.1, "-"),
    "V": ("valley", "#1f77b4", 1.1, "--"),
    "B": ("boundary", "#000000", 1.4, "-"),
}
"""FOLD letter -> (label, colour, line width, line style), drawn in this order (the boundary
last). The 3D view uses the same colours."""

F_SHOWN = (1 / math.sqrt(np.finfo(float).max), math.sqrt(np.finfo(float).max))
"""The range of F drawn on the log scale (about 1e-154 to 1e154, the square root of the
largest float): a value beyond it (a damaged log's F = 1e308) is drawn at the bound, so
that the axis' limits and margins stay within the floats (no overflow in matplotlib)."""


def _shown_f(value) -> float | None:
    """F as drawn: None where there is nothing to draw on a log scale (None, NaN, 0 or
    below), else clipped to :data:`F_SHOWN`."""
    if not isinstance(value, int | float) or not value > 0:  # NaN is not > 0
        return None
    return min(max(float(value), F_SHOWN[0]), F_SHOWN[1])


OUTCOME_STYLE = {
    "accepted": ("o", "#1f77b4", "accepted"),
    "lock": ("x", "#d62728", "lock (N_lock)"),
    "exceed": ("v", "#ff7f0e", "F > F_tol or not converged (N_exceed)"),
    "zero_dof": ("s", "#9467bd", "DOF 0"),
    "path": ("P", "#8c564b", "folding path does not reach flat (N_path)"),
    "second_order_rigid": ("p", "#bcbd22", "rigid at second order (N_rigid)"),
    "time_limit": ("|", "#000000", "cut by the time limit"),
    "no_gap": ("h", "#17becf", "target DOF without a clear gap"),
    "no_gain": ("1", "#aec7e8", "fix removed no DOF: not kept"),
    "initial_failed": ("D", "#7f7f7f", "initial solve failed"),
    "dead_end": ("*", "#e377c2", "retracted: no deployable candidate at its shape"),
}
"""Attempt outcome -> (marker, colour, legend label)."""


@dataclass(frozen=True)
class Figure:
    """One PNG of the report: name (file name), title, caption, png (bytes)."""

    name: str
    title: str
    caption: str
    png: bytes


def render_figures(run: RunData) -> list[Figure]:
    """Every figure the run has the data for, in the report's order."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    final = run.final
    with plt.rc_context({"font.size": 9, "axes.titlesize": 10}):
        if final is not None and final.coords2d is not None:
            out.append(_figure(plt, "development.png", *_development(plt, final)))
        if run.attempts:
            out.append(_figure(plt, "dof_and_F.png", *_attempts(plt, run)))
        fit = run.fit()
        if len(fit) and np.isfinite(fit).all():
            out.append(_figure(plt, "surface_fit.png", *_fit(plt, run, fit)))
        if final is not None:
            out.append(_figure(plt, "fold_angles.png", *_fold_angles(plt, final)))
        if final is not None and final.history:
            out.append(_figure(plt, "deformation.png", *_deformation(plt, final)))
    return out


def _figure(plt, name: str, fig, title: str, caption: str) -> Figure:
    """Save ``fig`` as PNG bytes and close it."""
    fig.tight_layout()
    png = io.BytesIO()
    fig.savefig(png, format="png")
    plt.close(fig)
    return Figure(name, title, caption, png.getvalue())


def plan_rotation(flat: np.ndarray, plan: np.ndarray) -> np.ndarray:
    """(V, 2) ``flat`` turned and moved (no mirror) to best fit ``plan`` (V, 2) in the
    least-squares sense: the development diagram drawn as the shape lies in plan."""
    a = flat - flat.mean(axis=0)
    b = plan - plan.mean(axis=0)
    angle = math.atan2(float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])), float(np.sum(a * b)))
    c, s = math.cos(angle), math.sin(angle)
    return a @ np.array([[c, s], [-s, c]]) + plan.mean(axis=0)


def _development(plt, design: SolutionFile):
    from matplotlib.collections import LineCollection

    assert design.coords2d is not None
    xy = plan_rotation(design.coords2d, design.coords[:, :2])
    fig, ax = plt.subplots(figsize=(6.0, 6.0), dpi=120)
    kinds = np.asarray(design.assignment)
    for letter, (label, colour, width, style) in KINDS.items():
        edges = design.edges[kinds == letter]
        if len(edges):
            ax.add_collection(
                LineCollection(
                    xy[edges], colors=colour, linewidths=width, linestyles=style, label=label
                )
            )
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    ax.set_title(f"Development diagram, DOF {design.dof}")
    n_fixed = int(np.sum(kinds == "J"))
    return (
        fig,
        "Development diagram of the final design",
        f"{design.name} flattened (Step 8), turned to lie as the design does in plan: "
        f"mountain lines red, valley lines blue dashed, the {n_fixed} fixed crease lines "
        "green, flat creases grey.",
    )


def _attempts(plt, run: RunData):
    attempts = run.attempts
    index = np.array([a.index for a in attempts])
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 4.6), dpi=120, sharex=True)
    accepted = [(i, a.dof) for i, a in zip(index, attempts, strict=True) if a.outcome == "accepted"]
    if accepted:
        top.step(*zip(*accepted, strict=True), where="post", color="#1f77b4", lw=1.0, alpha=0.6)
    for outcome, (marker, colour, label) in OUTCOME_STYLE.items():
        rows = [(i, a) for i, a in zip(index, attempts, strict=True) if a.outcome == outcome]
        if not rows:
            continue
        dof = [(i, a.dof) for i, a in rows if a.dof is not None]
        if dof:
            top.scatter(*zip(*dof, strict=True), marker=marker, color=colour, s=22, zorder=3)
        f = [(i, _shown_f(a.F)) for i, a in rows if _shown_f(a.F) is not None]
        if f:
            bottom.scatter(*zip(*f, strict=True), marker=marker, color=colour, s=22, label=label)
        if outcome == "lock":
            for i, _ in rows:
                for ax in (top, bottom):
                    ax.axvline(i, color=colour, lw=0.8, alpha=0.35)
    f_tol = _shown_f(run.summary.case.get("F_tol"))
    if f_tol:
        bottom.axhline(f_tol, color="k", ls=":", lw=0.9, label="F_tol")
    bottom.set_yscale("log")
    top.set_ylabel("DOF")
    bottom.set_ylabel("F")
    bottom.set_xlabel("attempt (solve of problem (6))")
    top.grid(alpha=0.3)
    bottom.grid(alpha=0.3)
    top.set_title(
        f"DOF and F per attempt: N_lock = {run.summary.n_lock}, "
        f"N_exceed = {run.summary.n_exceed}, N_path = {run.summary.n_path or 0}"
        + (f", retracted {run.summary.n_backtrack}" if run.summary.n_backtrack else "")
    )
    bottom.legend(fontsize=7, loc="best")
    return (
        fig,
        "DOF and F per attempt",
        "Every solve of problem (6) in the order made (log.jsonl): the DOF of the shape found "
        "and its objective F (drawn within 1e-154 to 1e154). Red crosses and lines mark the "
        "lock events (a crease locked, the fix replaced, Step 7); pink stars, solutions "
        "retracted by backtracking (no candidate of their shape gave a deployable solution).",
    )


def _fit(plt, run: RunData, fit: np.ndarray):
    rows = run.summary.per_solution[: len(fit)]
    steps = [r.step for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=120)
    ax.plot(steps, fit[:, 0] * 1e3, "o-", ms=3, label="max |z - target|")
    ax.plot(steps, fit[:, 1] * 1e3, "s-", ms=3, label="RMS |z - target|")
    dz = run.summary.case.get("dz_m")
    if dz:
        ax.axhline(dz * 1e3, color="k", ls=":", lw=0.9, label="bound |dz|")
    ax.set_xlabel("solution step")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_ylabel("mm")
    top = ax.secondary_xaxis("top")
    every = max(1, math.ceil(len(steps) / 12))
    top.set_xticks(steps[::every], [str(r.dof) for r in rows][::every])
    top.set_xlabel("DOF")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Surface fit per solution")
    return (
        fig,
        "Surface fit",
        "Distance of every vertex from the target surface, z - target(x, y), over each "
        "accepted solution: its largest and root-mean-square magnitude.",
    )


def _fold_angles(plt, design: SolutionFile):
    kinds = np.asarray(design.assignment)
    creases = np.flatnonzero(kinds != "B")
    fig, ax = plt.subplots(figsize=(6.4, 3.8), dpi=120)
    span = max(int(creases.max(initial=0)) + 1, 1)
    width_pt = float(np.clip(0.7 * 380 / span, 0.6, 6.0))  # ~70% of the axes' 380 pt per crease
    for letter in ("F", "M", "V", "J"):
        label, colour, _, _ = KINDS[letter]
        sel = creases[kinds[creases] == letter]
        if len(sel) and letter == "J":  # fixed flat: a tick where the bar would be
            ax.plot(sel, design.fold_deg[sel], "|", ms=9, mew=2, color=colour, label=label)
        elif len(sel):  # bars as lines: one artist however many creases
            ax.vlines(sel, 0.0, design.fold_deg[sel], color=colour, lw=width_pt, label=label)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("crease (edge index)")
    ax.set_ylabel("fold angle (deg)")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    ax.set_title(f"Fold angles of the final design, DOF {design.dof} (valley > 0)")
    return (
        fig,
        "Fold angles of the final design",
        f"Fold angle of every crease of {design.name}, degrees, valley positive; the fixed "
        "crease lines (kept flat: each joins two facets into one panel) are green ticks.",
    )


def _deformation(plt, design: SolutionFile):
    h = design.history
    lam = [s["load_factor"] for s in h]
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=120)
    ax.plot(lam, [s["max_dl_mm"] for s in h], "o-", ms=3, label="max |dl| (mm)")
    ax.plot(lam, [s["mean_dl_mm"] for s in h], "s-", ms=3, label="mean |dl| (mm)")
    ax.set_xlabel("load factor (share of the way to the plane)")
    ax.set_ylabel("bar length change (mm)")
    twin = ax.twinx()
    twin.plot(
        lam,
        [s["max_drho_fix_deg"] for s in h],
        "^-",
        ms=3,
        color="#2ca02c",
        label="max |drho_fix| (deg)",
    )
    twin.set_ylabel("max |drho_fix| (deg)", color="#2ca02c")
    ax.grid(alpha=0.3)
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="best", framealpha=0.9)
    ax.set_title(f"Large deformation of the final design (Step 9), DOF {design.dof}")
    return (
        fig,
        "Large-deformation history",
        "The frame model of the final design driven to the plane (OpenSees, Step 9): length "
        "change of the bars and largest rotation of a fixed crease at every load step.",
    )
