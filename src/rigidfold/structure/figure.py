"""The figure of a structure check: the design and its deflected shape (scaled), the supports."""

from __future__ import annotations

import io

import numpy as np

from rigidfold.structure.check import StructureCheck


def deflection_png(check: StructureCheck) -> bytes | None:
    """PNG bytes of the design (grey) and its deflected shape (coloured by the displacement,
    scaled so that the largest is a tenth of the plan's size), supports as red triangles;
    None when there is no response. matplotlib is imported here only."""
    if check.response is None or check.mesh is None:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh, r = check.mesh, check.response
    x = mesh.coords
    u = r.displacements[:, :3]
    size = float(np.ptp(x[:, :2], axis=0).max())
    biggest = float(np.linalg.norm(u, axis=1).max())
    scale = 0.1 * size / biggest if biggest > 0 else 1.0
    moved = x + scale * u
    mag = np.linalg.norm(u, axis=1)[mesh.triangles].mean(axis=1)
    fig = plt.figure(figsize=(8, 6), dpi=110)
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(
        Poly3DCollection(x[mesh.triangles], facecolor=(0.8, 0.8, 0.8, 0.25), edgecolor="none")
    )
    colours = plt.get_cmap("viridis")(mag / mag.max() if mag.max() > 0 else mag)
    ax.add_collection3d(
        Poly3DCollection(moved[mesh.triangles], facecolor=colours, edgecolor="none")
    )
    s = check.pattern.coords[check.rigidity.supports.vertices]
    ax.scatter(s[:, 0], s[:, 1], s[:, 2], marker="^", s=60, color="red", label="supports")
    lo, hi = np.minimum(x.min(0), moved.min(0)), np.maximum(x.max(0), moved.max(0))
    centre, half = (lo + hi) / 2, float((hi - lo).max()) / 2
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
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
