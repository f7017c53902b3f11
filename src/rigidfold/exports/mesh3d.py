"""The folded form of a design as a 3D mesh: OBJ, STL, PLY and glTF binary (GLB).

Every format holds the pattern's vertices ``coords`` (V, 3) in metres and its triangles
``faces`` (F, 3), counter-clockwise seen from +z (normals up). A *panel* is a facet of the
pattern, triangles joined by fixed creases (:attr:`rigidfold.mesh.CreasePattern.facets`);
where the format can hold groups, each panel is one:

* OBJ (text, written here so that the panels share the vertex list): every vertex once,
  in pattern order, then one group ``g panel_K`` per panel with its faces; z up.
* STL (binary, trimesh): the triangles, no groups (the format has none); z up, float32.
* PLY (binary, trimesh): every vertex once, the faces with an integer face property
  ``panel`` and a colour per panel; z up, float32.
* GLB (trimesh): one node ``panel_K`` per panel, its own mesh with its vertices and a colour,
  all children of a node ``rigidfold`` that turns rigidfold's z-up frame into glTF's y-up
  frame ((x, y, z) -> (x, z, -y)); the vertex data stay in rigidfold's frame.

trimesh is imported inside the functions, so ``import rigidfold`` stays light.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.io.files import atomic_write, text_bytes
from rigidfold.mesh import CreasePattern
from rigidfold.runtime.interrupts import held_import

MESH_FORMATS = ("obj", "stl", "ply", "glb")
"""The 3D formats of :func:`write_mesh` (file suffixes, without the dot)."""

Y_UP = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)
"""(4, 4) rigid transform from rigidfold's z-up frame to glTF's y-up frame."""

_PALETTE = np.array(
    [
        [166, 206, 227],
        [178, 223, 138],
        [251, 154, 153],
        [253, 191, 111],
        [202, 178, 214],
        [255, 255, 153],
        [141, 211, 199],
        [217, 217, 217],
    ],
    dtype=np.uint8,
)


def panel_names(pattern: CreasePattern) -> list[str]:
    """``panel_K`` of every panel K (zero-padded to one width), length ``n_facets``."""
    width = len(str(pattern.n_facets - 1))
    return [f"panel_{k:0{width}d}" for k in range(pattern.n_facets)]


def panel_colours(pattern: CreasePattern) -> np.ndarray:
    """(n_facets, 4) uint8 RGBA colour of each panel, light, cycling through eight."""
    rgb = _PALETTE[np.arange(pattern.n_facets) % len(_PALETTE)]
    return np.column_stack([rgb, np.full(len(rgb), 255, dtype=np.uint8)])


def obj_text(pattern: CreasePattern, *, title: str = "") -> str:
    """The Wavefront OBJ text of the folded form, one group per panel (see the module).

    Coordinates are written with 17 significant digits (exact doubles).
    """
    lines = [f"# {line}" for line in title.splitlines()] if title else []
    lines += [
        "# rigidfold folded form: metres, z up; one group per panel (triangles joined by fixed "
        "creases)",
        "o rigidfold",
    ]
    lines += [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in pattern.coords.tolist()]
    for k, name in enumerate(panel_names(pattern)):
        lines.append(f"g {name}")
        faces = pattern.faces[pattern.facets == k] + 1
        lines += [f"f {a} {b} {c}" for a, b, c in faces.tolist()]
    return "\n".join(lines) + "\n"


def stl_bytes(pattern: CreasePattern) -> bytes:
    """Binary STL of the folded form (float32, metres, z up)."""
    export_stl = held_import("trimesh.exchange.stl").export_stl
    return export_stl(_trimesh(pattern))


def ply_bytes(pattern: CreasePattern) -> bytes:
    """Binary little-endian PLY of the folded form: vertices (float32, metres, z up), faces
    with the integer property ``panel`` and the panel's colour."""
    export_ply = held_import("trimesh.exchange.ply").export_ply
    mesh = _trimesh(pattern)
    mesh.visual.face_colors = panel_colours(pattern)[pattern.facets]
    mesh.face_attributes["panel"] = pattern.facets.astype(np.int32)
    return export_ply(mesh, encoding="binary", include_attributes=True)


def glb_bytes(pattern: CreasePattern) -> bytes:
    """glTF binary of the folded form: one node per panel under a y-up node (module)."""
    trimesh = held_import("trimesh")
    scene = trimesh.Scene()
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to="rigidfold", matrix=Y_UP)
    colours = panel_colours(pattern)
    for k, name in enumerate(panel_names(pattern)):
        faces = pattern.faces[pattern.facets == k]
        used, local = np.unique(faces, return_inverse=True)
        mesh = trimesh.Trimesh(
            vertices=pattern.coords[used],
            faces=local.reshape(faces.shape),
            face_colors=np.repeat(colours[k : k + 1], len(faces), axis=0),
            process=False,
        )
        scene.add_geometry(mesh, node_name=name, geom_name=name, parent_node_name="rigidfold")
    return scene.export(file_type="glb")


def mesh_bytes(pattern: CreasePattern, fmt: str, *, title: str = "") -> bytes:
    """The file content of the folded form in ``fmt`` (:data:`MESH_FORMATS`); ``title`` goes
    into the OBJ header. Raises ValueError for an unknown format."""
    if fmt == "obj":
        return text_bytes(obj_text(pattern, title=title))
    writers = {"stl": stl_bytes, "ply": ply_bytes, "glb": glb_bytes}
    if fmt not in writers:
        raise RigidfoldError(f"3D format must be one of {', '.join(MESH_FORMATS)}, got {fmt!r}")
    return writers[fmt](pattern)


def write_mesh(path: str | os.PathLike, pattern: CreasePattern, *, title: str = "") -> Path:
    """Write the folded form to ``path`` in the format of its suffix (``.obj``, ``.stl``,
    ``.ply`` or ``.glb``), atomically (:func:`rigidfold.io.atomic_write`); returns ``path``.

    Raises ValueError for another suffix, or ``"cannot write '<path>': <reason>"``.
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in MESH_FORMATS:
        raise RigidfoldError(
            f"cannot tell the 3D format of '{path}': its suffix must be one of "
            f"{', '.join('.' + f for f in MESH_FORMATS)}"
        )
    return atomic_write(path, mesh_bytes(pattern, fmt, title=title))


def _trimesh(pattern: CreasePattern):
    """The folded form as one ``trimesh.Trimesh`` (vertices and faces as they are)."""
    trimesh = held_import("trimesh")
    return trimesh.Trimesh(vertices=pattern.coords, faces=pattern.faces, process=False)
