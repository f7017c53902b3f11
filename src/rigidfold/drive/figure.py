"""``deploy.png``: the drive's effort against s, with its dead points, the sign changes and
the brake zones marked, and the energy below. matplotlib is imported here only."""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from rigidfold.drive.result import DriveResult


def drive_figure(result: DriveResult) -> Any:
    """The matplotlib Figure (Agg): above, the named drive's torque (N m; a pair's two, a
    cable's tension in N) against s, deploying (and folding back where friction makes them
    differ), its dead points as dashed lines, the sign changes as dots, the brake zones
    shaded, the axis cut at 1.5 times the peak; below, U(s) and its parts (J), the
    equilibria marked (filled: stable)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 7), dpi=110)
    top, bottom = fig.subplots(2, 1, sharex=True)
    s = result.s
    d = result.drive
    unit = "N" if d is not None and d.kind == "cable" else "N m"
    if d is not None:
        curves = d.effort if d.effort.ndim == 2 else d.effort[None]
        labels = (
            [f"crease {e}" for e in d.ids]
            if d.kind == "pair"
            else [f"{d.name}: {'tension' if d.kind == 'cable' else 'torque'}, deploying"]
        )
        for curve, label in zip(curves, labels, strict=True):
            top.plot(s, curve, lw=1.5, label=label)
        if d.kind == "crease" and result.options.friction > 0:
            from rigidfold.drive.energy import derivative

            with np.errstate(divide="ignore", invalid="ignore"):
                back = (result.slope - result.friction) / derivative(d.coordinate, s)
            top.plot(s, back, lw=1.0, ls="--", label="folding back")
        peak = d.peak if np.isfinite(d.peak) and d.peak > 0 else None
        if peak is not None:
            top.set_ylim(-1.5 * peak, 1.5 * peak)
        for k, x in enumerate(d.dead):
            top.axvline(x, color="k", ls=":", lw=1, label="dead point" if k == 0 else None)
        if d.sign_changes:
            top.plot(
                d.sign_changes, np.zeros(len(d.sign_changes)), "o", color="C3", label="sign change"
            )
        top.set_title(result.summary_line(), fontsize=8)
    for k, (a, b) in enumerate(result.brake_zones):
        top.axvspan(a, b, color="C1", alpha=0.2, label="brake (deploying)" if k == 0 else None)
    top.axhline(0.0, color="0.5", lw=0.5)
    top.set_ylabel(f"drive ({unit})")
    top.legend(loc="best", fontsize=8)
    bottom.plot(s, result.u, lw=1.5, label="U")
    bottom.plot(s, result.u_gravity, lw=1.0, label="gravity")
    if np.any(result.u_spring):
        bottom.plot(s, result.u_spring, lw=1.0, label="hinge springs")
    for e in result.equilibria:
        fill = "C2" if e.stable else "white"
        bottom.plot([e.s], [e.U_J], "o", mfc=fill, mec="C2")
    bottom.set_xlabel("s (0: flat, 1: built)")
    bottom.set_ylabel("energy (J)")
    bottom.legend(loc="best", fontsize=8)
    bottom.set_xlim(float(s[0]), float(s[-1]))
    return fig


def drive_png(result: DriveResult) -> bytes:
    """PNG bytes of :func:`drive_figure`."""
    buf = io.BytesIO()
    drive_figure(result).savefig(buf, format="png")
    return buf.getvalue()
