"""The interactive 3D view of a final design: a plotly figure (as a plain dict).

The folded form is a ``mesh3d`` coloured by the signed distance to the target surface
(z - target(x, y), mm), its crease lines drawn by kind (the colours of
:data:`rigidfold.reporting.figures.KINDS`), the target surface a translucent overlay, and the
folding motion from flat to folded a slider with play and pause buttons. Each motion frame
is turned and moved as a rigid body to best fit the folded form, so the sheet folds in place.

:func:`thick_figure` shows the final design's thick panels (``generate --thickness``) the
same way: each solid moves with its panel's rigid motion along the folding slider, the two
panels that come closest (or meet first) in red.
"""

from __future__ import annotations

import html

import numpy as np

from rigidfold.mesh.geometry import best_fit, rigid_motions
from rigidfold.protocols import TargetSurface
from rigidfold.reporting.figures import KINDS
from rigidfold.rundir import SolutionFile, ThickPanels

GRID = 40
"""Samples per side of the target surface overlay."""

THICK_FRAMES = 21
"""Most motion frames of the thick panels' view (evenly chosen, flat and folded kept): its
solids have many more vertices than the sheet."""

SOLID_COLOUR = "#c8a878"
CLOSEST_COLOUR = "#d62728"

SURFACE_COLOUR = "#8c8c8c"
MESH_SCALE = [
    [k / 10, c]
    for k, c in enumerate(
        "#2d004b #542788 #8073ac #b2abd2 #d8daeb #f7f7f7 #fee0b6 #fdb863 #e08214 #b35806 "
        "#7f3b08".split()
    )
]
"""Colour scale of z - target (ColorBrewer PuOr): purple below the target, orange above,
white on it. Given as colours: plotly.js knows only a few scales by name."""


def _lines(coords: np.ndarray, edges: np.ndarray) -> tuple[list, list, list]:
    """x, y, z lists of the segments ``edges`` at ``coords``, None between segments."""
    if len(edges) == 0:
        return [], [], []
    seg = np.full((len(edges), 3, 3), np.nan)
    seg[:, :2] = coords[edges]
    x, y, z = (
        [None if np.isnan(v) else float(v) for v in axis]
        for axis in np.round(seg, 5).reshape(-1, 3).T
    )
    return x, y, z


def _shape_traces(
    coords: np.ndarray, design: SolutionFile, kinds: np.ndarray, driven: tuple[int, ...] = ()
) -> list[dict]:
    """The moving traces at ``coords``: the mesh, then one line trace per crease kind, then
    the driven creases' (edge indices ``driven``) where there are any."""
    x, y, z = np.round(coords, 5).T
    traces = [{"type": "mesh3d", "x": x.tolist(), "y": y.tolist(), "z": z.tolist()}]
    for letter in KINDS:
        lx, ly, lz = _lines(coords, design.edges[kinds == letter])
        traces.append({"type": "scatter3d", "x": lx, "y": ly, "z": lz})
    if driven:
        lx, ly, lz = _lines(coords, design.edges[list(driven)])
        traces.append({"type": "scatter3d", "x": lx, "y": ly, "z": lz})
    return traces


def view_figure(
    design: SolutionFile, surface: TargetSurface | None, driven: tuple[int, ...] = ()
) -> dict:
    """The plotly figure dict of ``design`` (see the module's text); without ``surface`` the
    mesh is coloured by height and no overlay is drawn. ``driven``: the edges of the
    deployment drive's creases (``generate --deploy``), drawn thick in orange."""
    driven = tuple(e for e in driven if 0 <= e < len(design.edges))
    kinds = np.asarray(design.assignment)
    coords = design.coords
    if surface is not None:
        colour = design.dz(surface) * 1e3
        bound = max(float(np.abs(colour).max()), 1e-6)
        scale = {"cmin": -bound, "cmax": bound, "colorscale": MESH_SCALE}
        title = "z - target (mm)"
    else:
        colour = coords[:, 2]
        scale = {"colorscale": "Viridis"}
        title = "z (m)"
    traces = _shape_traces(coords, design, kinds, driven)
    traces[0].update(
        i=design.faces[:, 0].tolist(),
        j=design.faces[:, 1].tolist(),
        k=design.faces[:, 2].tolist(),
        intensity=np.round(colour, 4).tolist(),
        intensitymode="vertex",
        colorbar={"title": {"text": title}, "len": 0.6, "x": 1.0},
        flatshading=True,
        lighting={"ambient": 0.65, "diffuse": 0.5, "specular": 0.05},
        name="folded form",
        hovertemplate="x %{x:.3f} m<br>y %{y:.3f} m<br>z %{z:.3f} m<extra></extra>",
        **scale,
    )
    kinds_traces = traces[1 : 1 + len(KINDS)]
    for trace, (label, line, width, style) in zip(kinds_traces, KINDS.values(), strict=True):
        trace.update(
            mode="lines",
            name=label,
            line={
                "color": line,
                "width": 2 * width + 1,
                "dash": "dash" if style == "--" else "solid",
            },
            hoverinfo="skip",
        )
    if driven:
        traces[-1].update(
            mode="lines",
            name="driven crease",
            line={"color": "#ff7f0e", "width": 9},
            hoverinfo="skip",
        )
    moving = list(range(len(traces)))
    placed = best_fit(design.motion, coords) if len(design.motion) > 1 else design.motion[:0]
    frames = [
        {
            "name": f"{100 * share:.0f}%",
            "data": _shape_traces(shape, design, kinds, driven),
            "traces": moving,
        }
        for shape, share in zip(placed, design.fraction, strict=True)
    ]
    points = [coords, placed.reshape(-1, 3)]
    if surface is not None:
        overlay, samples = _surface_trace(surface, coords)
        traces.append(overlay)
        points.append(samples)
    return {"data": traces, "layout": _layout(np.vstack(points), design, frames), "frames": frames}


def thick_figure(thick: ThickPanels, design: SolutionFile) -> dict:
    """The plotly figure dict of the thick panels of ``design`` (see the module's text):
    one ``mesh3d`` of the solids, one of the closest pair, moved along ``design``'s motion
    (at most :data:`THICK_FRAMES` frames) by each panel's rigid motion (Kabsch over its
    vertices: :func:`rigidfold.mesh.geometry.rigid_motions`)."""
    pair = set(thick.closest or ())
    hot = np.array([k in pair for k in thick.panel.tolist()], dtype=bool)
    groups = design.panel_vertices()
    known = np.array([0 <= k < len(groups) for k in thick.panel.tolist()], dtype=bool)
    hot &= known
    placed = best_fit(design.motion, design.coords) if len(design.motion) > 1 else None
    chosen = np.arange(0)
    if placed is not None:
        chosen = np.unique(np.linspace(0, len(placed) - 1, THICK_FRAMES).round().astype(int))
        rotations, translations = rigid_motions(design.coords, placed[chosen], groups)

    def traces(frame: int | None) -> list[dict]:
        out = []
        for which in (~hot & known, hot):
            verts, faces, base = [], [], 0
            for s in np.flatnonzero(which):
                v = thick.vertices[s]
                if frame is not None:
                    k = thick.panel[s]
                    v = v @ rotations[frame, k].T + translations[frame, k]
                verts.append(v)
                faces.append(thick.faces[s] + base)
                base += len(v)
            xyz = np.round(np.vstack(verts), 5) if verts else np.zeros((0, 3))
            tri = np.vstack(faces) if faces else np.zeros((0, 3), dtype=np.int64)
            out.append(
                {
                    "type": "mesh3d",
                    "x": xyz[:, 0].tolist(),
                    "y": xyz[:, 1].tolist(),
                    "z": xyz[:, 2].tolist(),
                    "i": tri[:, 0].tolist(),
                    "j": tri[:, 1].tolist(),
                    "k": tri[:, 2].tolist(),
                }
            )
        return out

    data = traces(None)
    a, b = thick.closest if thick.closest is not None else (None, None)
    for trace, (name, colour) in zip(
        data,
        (
            ("thick panels", SOLID_COLOUR),
            (f"closest pair: panels {a} and {b}", CLOSEST_COLOUR),
        ),
        strict=True,
    ):
        trace.update(
            name=name,
            color=colour,
            flatshading=True,
            showlegend=True,
            lighting={"ambient": 0.55, "diffuse": 0.6, "specular": 0.05},
            hoverinfo="skip",
        )
    share = design.fraction[chosen] if len(chosen) else np.zeros(0)
    frames = [
        {"name": f"{100 * f:.0f}%", "data": traces(i), "traces": [0, 1]}
        for i, f in enumerate(share)
    ]
    points = np.vstack([*thick.vertices, design.coords])
    if placed is not None:
        points = np.vstack([points, placed[chosen].reshape(-1, 3)])
    layout = _layout(points, design, frames)
    t = thick.figures.get("thickness_m")
    layout["title"]["text"] = f"{html.escape(design.name, quote=False)}: thick panels" + (
        f" {1e3 * t:g} mm" if isinstance(t, int | float) else ""
    )
    return {"data": data, "layout": layout, "frames": frames}


def _surface_trace(surface: TargetSurface, coords: np.ndarray) -> tuple[dict, np.ndarray]:
    """The target over the design's plan bounding box, translucent, one grey; and its
    finite samples (n, 3)."""
    (x0, y0), (x1, y1) = coords[:, :2].min(axis=0), coords[:, :2].max(axis=0)
    gx, gy = np.meshgrid(np.linspace(x0, x1, GRID), np.linspace(y0, y1, GRID))
    with np.errstate(invalid="ignore"):
        gz = np.broadcast_to(np.asarray(surface.height(gx, gy), dtype=float), gx.shape)
    z = [[float(v) if np.isfinite(v) else None for v in row] for row in np.round(gz, 5)]
    samples = np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()])
    trace = {
        "type": "surface",
        "x": np.round(gx[0], 5).tolist(),
        "y": np.round(gy[:, 0], 5).tolist(),
        "z": z,
        "opacity": 0.3,
        "colorscale": [[0, SURFACE_COLOUR], [1, SURFACE_COLOUR]],
        "showscale": False,
        "name": "target surface",
        "showlegend": True,
        "hoverinfo": "skip",
    }
    return trace, samples[np.isfinite(samples[:, 2])]


def _layout(points: np.ndarray, design: SolutionFile, frames: list[dict]) -> dict:
    """Fixed axes around every frame (so the view does not jump), legend, and the slider."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    pad = 0.03 * float((hi - lo).max())
    lo, hi = lo - pad, hi + pad
    span = hi - lo
    ratio = span / span.max()
    axis = {"showbackground": False, "gridcolor": "#dddddd"}
    layout = {
        "height": 640,
        "margin": {"l": 0, "r": 0, "t": 30, "b": 70},
        "legend": {"x": 0.0, "y": 1.0, "bgcolor": "rgba(255,255,255,0.7)"},
        "scene": {
            "xaxis": {**axis, "title": {"text": "x (m)"}, "range": [lo[0], hi[0]]},
            "yaxis": {**axis, "title": {"text": "y (m)"}, "range": [lo[1], hi[1]]},
            "zaxis": {**axis, "title": {"text": "z (m)"}, "range": [lo[2], hi[2]]},
            "aspectmode": "manual",
            "aspectratio": dict(zip("xyz", (float(r) for r in ratio), strict=True)),
            "camera": {"eye": {"x": 1.25, "y": -1.25, "z": 0.8}},
        },
        # plotly.js reads a title as HTML (<a href> makes a link): the file name as text
        "title": {"text": f"{html.escape(design.name, quote=False)}: DOF {design.dof}", "x": 0.5},
    }
    if frames:
        animate = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}}
        layout["sliders"] = [
            {
                "active": len(frames) - 1,
                "currentvalue": {"prefix": "folded: "},
                "x": 0.12,
                "len": 0.88,
                "y": 0.0,
                "yanchor": "top",
                "pad": {"t": 10},
                "steps": [
                    {"label": f["name"], "method": "animate", "args": [[f["name"]], animate]}
                    for f in frames
                ],
            }
        ]
        layout["updatemenus"] = [
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.11,
                "y": 0.0,
                "xanchor": "right",
                "yanchor": "top",
                "pad": {"t": 45},
                "buttons": [
                    {
                        "label": "fold",
                        "method": "animate",
                        "args": [
                            None,
                            {
                                **animate,
                                "frame": {"duration": 250, "redraw": True},
                                "fromcurrent": False,
                            },
                        ],
                    },
                    {"label": "pause", "method": "animate", "args": [[None], animate]},
                ],
            }
        ]
    return layout
