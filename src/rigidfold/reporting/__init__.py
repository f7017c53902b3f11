"""The report of a generate run: ``DIR/report.html`` and the PNG figures in ``DIR/figures/``.

A view over the run read back by :func:`rigidfold.rundir.load_run`: :func:`render_figures`
draws the paper-style figures (matplotlib, :mod:`.figures`), :func:`view_figure` makes the
interactive 3D view (a plotly figure dict, :mod:`.view3d`) and :func:`page` puts them into
one self-contained HTML page (:mod:`.html`). ``rigidfold.pipeline.workflows.report_run`` writes the
files.
"""

from rigidfold.reporting.figures import Figure, render_figures
from rigidfold.reporting.html import page
from rigidfold.reporting.view3d import thick_figure, view_figure

__all__ = ["Figure", "page", "render_figures", "thick_figure", "view_figure"]
