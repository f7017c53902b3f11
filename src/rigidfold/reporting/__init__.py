"""The report of a generate run: ``DIR/report.html`` and the PNG figures in ``DIR/figures/``.

:func:`load_run` reads the run back (:mod:`.run`), :func:`render_figures` draws the
paper-style figures (matplotlib, :mod:`.figures`), :func:`view_figure` makes the interactive
3D view (a plotly figure dict, :mod:`.view3d`) and :func:`page` puts them into one
self-contained HTML page (:mod:`.html`). ``rigidfold.workflows.report_run`` writes the files.
"""

from rigidfold.reporting.figures import Figure, render_figures
from rigidfold.reporting.html import page
from rigidfold.reporting.run import Check, Design, RunData, load_run, target_surface
from rigidfold.reporting.view3d import view_figure

__all__ = [
    "Check",
    "Design",
    "Figure",
    "RunData",
    "load_run",
    "page",
    "render_figures",
    "target_surface",
    "view_figure",
]
