"""The report of a generate run: ``DIR/report.html`` and ``DIR/figures/*.png``, made from the
run directory as it was written (``rigidfold report``, and the run writer at the end of a
run)."""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rigidfold.io import atomic_write, prepare_output_dir
from rigidfold.reporting import page, render_figures, thick_figure, view_figure
from rigidfold.rundir import RunData, load_run
from rigidfold.rundir.layout import FIGURES_DIR, REPORT_FILE


def write_report(
    directory: Path, html: str, figures: Sequence[tuple[str, bytes]]
) -> tuple[Path, tuple[Path, ...]]:
    """The report of the run in ``directory``: each (name, PNG) of ``figures`` as
    ``DIR/figures/NAME`` and the page ``html`` as ``DIR/report.html``, each written
    atomically. Returns (the page, the figures)."""
    figure_dir = prepare_output_dir(directory / FIGURES_DIR, within=directory)
    written = tuple(atomic_write(figure_dir / name, png) for name, png in figures)
    return atomic_write(directory / REPORT_FILE, html), written


@dataclass(frozen=True, eq=False)
class RunReport:
    """The report of a generate run: the run read back, the files written and the time.

    run : RunData; html : ``DIR/report.html``; figures : the PNG files in ``DIR/figures/``;
    seconds : wall time of reading, drawing and writing.
    """

    run: RunData
    html: Path
    figures: tuple[Path, ...]
    seconds: float

    def to_dict(self) -> dict:
        final = self.run.final
        return {
            "report": str(self.html),
            "size_bytes": self.html.stat().st_size,
            "figures": [str(p) for p in self.figures],
            "final_design": None if final is None else final.name,
            "final_dof": self.run.summary.final_dof,
            "n_lock": self.run.summary.n_lock,
            "checks": {c.name: c.word for c in self.run.checks()},
            "seconds": self.seconds,
        }


def report_run(directory: str | os.PathLike) -> RunReport:
    """Write ``DIR/report.html`` (one self-contained page: the answer, the 3D view with the
    folding motion, the figures, the tables) and ``DIR/figures/*.png`` for the generate run
    in ``directory``. ValueError (one line) when it is not a generate run."""
    t0 = time.perf_counter()
    run = load_run(directory)
    figures = render_figures(run)
    view = None if run.final is None else view_figure(run.final, run.surface, run.driven_creases())
    thick, note = run.thick_panels()
    solids = None if thick is None or run.final is None else thick_figure(thick, run.final)
    text = page(run, figures, view, solids, note)
    html, written = write_report(run.directory, text, [(f.name, f.png) for f in figures])
    return RunReport(run, html, written, time.perf_counter() - t0)
