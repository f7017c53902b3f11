"""The figure of a structure check: the design's undeformed outline and its deflected shape
(scaled, coloured by the displacement, with its colour bar), the supports."""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from rigidfold.structure.check import StructureCheck


def drawable(check: StructureCheck) -> bool:
    """Whether the check has a response with finite displacements to draw."""
    return check.response is not None and check.mesh is not None and check.finite


def deflection_figure(check: StructureCheck) -> Any:
    """The matplotlib Figure (Agg) of the design's undeformed outline (its edges, grey,
    labelled ``undeformed``) and its deflected shape, coloured by the displacement (the
    colour bar in mm) and scaled so that the largest is a tenth of the plan's size, supports
    as red triangles; None when there is nothing finite to draw (:func:`drawable`).
    matplotlib is imported here only."""
    if not drawable(check):
        return None
    assert check.mesh is not None and check.response is not None
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    mesh, r = check.mesh, check.response
    x = mesh.coords
    u = r.displacements[:, :3]
    size = float(np.ptp(x[:, :2], axis=0).max())
    length = np.linalg.norm(u, axis=1)
    biggest = float(length.max(initial=0.0))
    scale = 0.1 * size / biggest if biggest > 0 and np.isfinite(0.1 * size / biggest) else 1.0
    moved = x + scale * u
    mag = length[mesh.triangles].mean(axis=1) * 1e3  # mm
    fig = Figure(figsize=(8, 6), dpi=110)
    ax = fig.add_subplot(projection="3d")
    pat = check.pattern
    outline = Line3DCollection(
        pat.coords[pat.edges], colors=[(0.3, 0.3, 0.3, 0.6)], linewidths=0.5, label="undeformed"
    )
    ax.add_collection3d(outline)
    norm = Normalize(vmin=0.0, vmax=biggest * 1e3 if biggest > 0 else 1.0)  # the largest node
    cmap = matplotlib.colormaps["viridis"]
    ax.add_collection3d(
        Poly3DCollection(moved[mesh.triangles], facecolor=cmap(norm(mag)), edgecolor="none")
    )
    fig.colorbar(
        ScalarMappable(norm=norm, cmap=cmap),
        ax=ax,
        shrink=0.6,
        pad=0.12,
        label="displacement (mm)",
    )
    s = pat.coords[check.rigidity.supports.vertices]
    ax.scatter(s[:, 0], s[:, 1], s[:, 2], marker="^", s=60, color="red", label="supports")
    lo, hi = np.minimum(x.min(0), moved.min(0)), np.maximum(x.max(0), moved.max(0))
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-9)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.legend(loc="upper left")
    ax.set_title(
        f"deflected shape x {scale:.3g}: largest displacement {biggest * 1e3:.3g} mm "
        f"(limit {check.allowed_displacement * 1e3:.3g} mm)",
        fontsize=9,
    )
    return fig


def deflection_png(check: StructureCheck) -> bytes | None:
    """PNG bytes of :func:`deflection_figure`; None when it has nothing to draw."""
    fig = deflection_figure(check)
    if fig is None:
        return None
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()
