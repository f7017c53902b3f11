"""MeshSurface on the built-in dome given as a triangle mesh: build time, fit_error and the
largest |spline - analytic dome| ("max error") for several mesh resolutions and grid sizes
(``Settings.inputs.surface_grid_nodes``), on the whole 3 m square and on a disc footprint (radius
1.4 m, where the grid's corners are continued outside the footprint).

    python benchmarks/mesh_surface.py [--vertices 61 121 241] [--nodes 33 65 129 257]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.surfaces import Dome, MeshSurface, sample_mesh


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vertices", type=int, nargs="+", default=[61, 121, 241])
    ap.add_argument("--nodes", type=int, nargs="+", default=[33, 65, 129, 257])
    args = ap.parse_args()
    dome = Dome()
    g = np.linspace(0.0, 3.0, 601)
    x, y = np.meshgrid(g, g)
    in_disc = np.hypot(x - 1.5, y - 1.5) <= 1.35
    print("| footprint | vertices | triangles | grid nodes | build s | fit_error m | max error m |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for footprint in ("square", "disc"):
        for n in args.vertices:
            vertices, triangles = sample_mesh(dome, n)
            inside = np.ones(x.shape, dtype=bool)
            if footprint == "disc":
                r = np.hypot(vertices[:, 0] - 1.5, vertices[:, 1] - 1.5)
                triangles = triangles[(r[triangles] <= 1.4).all(axis=1)]
                inside = in_disc
            for nodes in args.nodes:
                t = time.perf_counter()
                surface = MeshSurface(
                    vertices, triangles, settings=DEFAULTS.with_(surface_grid_nodes=nodes)
                )
                build = time.perf_counter() - t
                error = np.abs(surface.height(x, y) - dome.height(x, y))[inside].max()
                print(
                    f"| {footprint} | {n}x{n} | {len(triangles)} | {nodes} | {build:.2f} | "
                    f"{surface.fit_error:.1e} | {error:.1e} |"
                )


if __name__ == "__main__":
    main()
