"""The files of thick panels: 3D solids, a Rhino model, the hinge and vertex schedules.

All lengths are metres unless a column says mm; the solids are in the design's place (z up),
one per panel, named ``panel_K`` as in the design's own exports
(:func:`rigidfold.exports.mesh3d.panel_names`).

* ``NAME_solids.glb``: one node ``panel_K`` per panel, each its own mesh, under a node that
  turns z up into glTF's y up (as :mod:`rigidfold.exports.mesh3d` does).
* ``NAME_solids.stl`` (binary) and ``NAME_solids.obj`` (one group ``g panel_K`` per panel).
* ``NAME_solids.3dm`` (rhino3dm): layer PANELS with one mesh per panel named ``panel_K``,
  HINGES with each hinge's axis as a line named ``hinge_E`` (E: the crease), CREASES with
  every crease and boundary edge of the design, LABELS with a text dot of each panel's number
  on its surface.
* ``NAME_hinges.csv``: per hinge, see :data:`HINGE_COLUMNS`.
* ``NAME_vertices.csv``: per vertex, its place in the design and on the flat sheet.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.exports.mesh3d import Y_UP, panel_colours, panel_names
from rigidfold.fabricate.build import Fabrication
from rigidfold.io.files import parse_json, text_bytes, write_together
from rigidfold.runtime.interrupts import held_import

HINGE_COLUMNS = (
    "hinge",
    "crease",
    "panel_a",
    "panel_b",
    "vertex_a",
    "vertex_b",
    "ax_m",
    "ay_m",
    "az_m",
    "bx_m",
    "by_m",
    "bz_m",
    "length_m",
    "fold_design_deg",
    "fold_min_deg",
    "fold_max_deg",
    "side",
    "bevel_deg",
    "setback_mm",
    "fold_limit_deg",
)
"""Columns of the hinge schedule: the hinge's number and its crease (edge index of the FOLD
file), the panels on its left and right (of vertex_a -> vertex_b), its axis end points in the
design, its length, its fold angle in the design (valley > 0) and its closing fold range from
flat to the design over the motion (towards the solids' side > 0), ``side``: ``closes`` when
it folds towards the solids, ``opens`` when away, the bevel of both panels' edges (angle
between the bevel face and the surface), how far the far face is set back from the axis, and
the fold up to which the two solids meet only along the axis."""

VERTEX_COLUMNS = ("vertex", "x_m", "y_m", "z_m", "flat_x_m", "flat_y_m", "relief_mm")
"""Columns of the vertex schedule: the vertex, its place in the design (z up), on the flat
sheet (the development diagram), and the relief radius of the solids there (0: none)."""


def _meshes(fab: Fabrication) -> list[tuple[str, np.ndarray, np.ndarray]]:
    names = panel_names(fab.panels.pattern)
    return [(names[k], v, f) for k, (v, f) in enumerate(fab.solids.meshes)]


def glb_bytes(fab: Fabrication) -> bytes:
    """glTF binary of the solids: one node per panel under a y-up node."""
    trimesh = held_import("trimesh")
    scene = trimesh.Scene()
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to="rigidfold", matrix=Y_UP)
    colours = panel_colours(fab.panels.pattern)
    for k, (name, verts, faces) in enumerate(_meshes(fab)):
        if not len(faces):
            continue
        mesh = trimesh.Trimesh(
            vertices=verts,
            faces=faces,
            face_colors=np.repeat(colours[k : k + 1], len(faces), axis=0),
            process=False,
        )
        scene.add_geometry(mesh, node_name=name, geom_name=name, parent_node_name="rigidfold")
    if not scene.geometry:  # every panel trimmed away: a valid file with no mesh
        return _empty_glb()
    return scene.export(file_type="glb")


def _empty_glb() -> bytes:
    """A glTF binary of one scene with the y-up node ``rigidfold`` and no mesh (trimesh
    exports no empty scene)."""
    import struct

    document = {
        "asset": {"version": "2.0", "generator": "rigidfold"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "rigidfold", "matrix": np.asarray(Y_UP).T.ravel().tolist()}],
    }
    body = text_bytes(json.dumps(document))
    body += b" " * (-len(body) % 4)
    chunk = struct.pack("<II", len(body), 0x4E4F534A) + body
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunk)) + chunk


def stl_bytes(fab: Fabrication) -> bytes:
    """Binary STL of all the solids."""
    trimesh = held_import("trimesh")
    export_stl = held_import("trimesh.exchange.stl").export_stl

    parts = [(v, f) for _, v, f in _meshes(fab) if len(f)]
    if not parts:  # every panel trimmed away: a binary STL of no triangle
        return b"rigidfold: no solid".ljust(80, b" ") + b"\x00\x00\x00\x00"
    offsets = np.cumsum([0] + [len(v) for v, _ in parts])
    verts = np.vstack([v for v, _ in parts])
    faces = np.vstack([f + o for (_, f), o in zip(parts, offsets, strict=False)])
    return export_stl(trimesh.Trimesh(vertices=verts, faces=faces, process=False))


def obj_text(fab: Fabrication, *, title: str = "") -> str:
    """OBJ of the solids, one group per panel, metres, z up."""
    lines = ["# rigidfold fabricate: thick panels, metres, z up"]
    if title:
        lines.append(f"# {' '.join(title.split())}")
    base = 1
    for name, verts, faces in _meshes(fab):
        if not len(faces):
            continue
        lines.append(f"o {name}")
        lines.append(f"g {name}")
        lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in verts.tolist()]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in faces.tolist()]
        base += len(verts)
    return "\n".join(lines) + "\n"


def rhino_bytes(fab: Fabrication) -> bytes:
    """The Rhino model (see the module's text) as the bytes of a version 7 file, made in
    memory (``File3dm.Encode``): no file is written, so a full disk or the file size limit
    shows where the files are written, with its cause, not as a refusal of rhino3dm."""
    import base64

    rhino3dm = held_import("rhino3dm")  # typed Any: its stubs do not know the setters

    p = fab.panels
    pattern = p.pattern
    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    layers = {}
    for name, colour in (
        ("PANELS", (200, 170, 120, 255)),
        ("HINGES", (220, 40, 40, 255)),
        ("CREASES", (60, 60, 60, 255)),
        ("LABELS", (30, 30, 200, 255)),
    ):
        layer = rhino3dm.Layer()
        layer.Name = name
        layer.Color = colour
        layers[name] = model.Layers.Add(layer)

    def attributes(layer: str, name: str):
        attr = rhino3dm.ObjectAttributes()
        attr.LayerIndex = layers[layer]
        attr.Name = name
        return attr

    for name, verts, faces in _meshes(fab):
        if not len(faces):
            continue
        mesh = rhino3dm.Mesh()
        for x, y, z in verts.tolist():
            mesh.Vertices.Add(x, y, z)
        for a, b, c in faces.tolist():
            mesh.Faces.AddFace(a, b, c)
        mesh.Normals.ComputeNormals()
        model.Objects.AddMesh(mesh, attributes("PANELS", name))
    coords = pattern.coords
    for h, e in enumerate(p.hinge_edges.tolist()):
        u, v = p.hinge_vertices[h].tolist()
        line = rhino3dm.LineCurve(rhino3dm.Point3d(*coords[u]), rhino3dm.Point3d(*coords[v]))
        model.Objects.AddCurve(line, attributes("HINGES", f"hinge_{e}"))
    for e, (u, v) in enumerate(pattern.edges.tolist()):
        if pattern.fixed[e]:
            continue
        line = rhino3dm.LineCurve(rhino3dm.Point3d(*coords[u]), rhino3dm.Point3d(*coords[v]))
        model.Objects.AddCurve(line, attributes("CREASES", f"edge_{e}"))
    for k, name in enumerate(panel_names(pattern)):
        centre = coords[p.vertices[k]].mean(axis=0)
        point = rhino3dm.Point3d(*centre)
        model.Objects.AddTextDot(str(k), point, attributes("LABELS", name))
    options = rhino3dm.File3dmWriteOptions()
    options.Version = 7
    data = base64.b64decode(model.Encode(options) or "")
    if not data:
        raise RigidfoldError("cannot make the Rhino model (rhino3dm made no file of it)")
    return data


def hinge_rows(fab: Fabrication) -> list[dict]:
    """The rows of the hinge schedule (:data:`HINGE_COLUMNS`)."""
    p, s = fab.panels, fab.solids
    coords = p.pattern.coords
    fold = np.degrees(p.pattern.fold_angles)
    low, high = fab.fold_range
    rows = []
    for h, e in enumerate(p.hinge_edges.tolist()):
        u, v = p.hinge_vertices[h].tolist()
        a, b = p.hinge_panels[h].tolist()
        rows.append(
            {
                "hinge": h,
                "crease": e,
                "panel_a": a,
                "panel_b": b,
                "vertex_a": u,
                "vertex_b": v,
                **{
                    f"{c}{x}_m": f"{coords[w][i]:.6f}"
                    for c, w in (("a", u), ("b", v))
                    for i, x in enumerate("xyz")
                },
                "length_m": f"{np.linalg.norm(coords[v] - coords[u]):.6f}",
                "fold_design_deg": f"{fold[e]:.3f}",
                "fold_min_deg": f"{math.degrees(low[h]):.3f}",
                "fold_max_deg": f"{math.degrees(high[h]):.3f}",
                "side": "closes" if high[h] > 0 else "opens",
                "bevel_deg": f"{math.degrees(s.bevel[h]):.3f}",
                "setback_mm": f"{s.inset[h] * 1e3:.2f}",
                "fold_limit_deg": f"{math.degrees(s.fold_limit[h]):.3f}",
            }
        )
    return rows


def vertex_rows(fab: Fabrication) -> list[dict]:
    """The rows of the vertex schedule (:data:`VERTEX_COLUMNS`)."""
    p = fab.panels
    xyz, xy = p.pattern.coords, p.coords2d
    return [
        {
            "vertex": v,
            "x_m": f"{xyz[v, 0]:.6f}",
            "y_m": f"{xyz[v, 1]:.6f}",
            "z_m": f"{xyz[v, 2]:.6f}",
            "flat_x_m": f"{xy[v, 0]:.6f}",
            "flat_y_m": f"{xy[v, 1]:.6f}",
            "relief_mm": f"{fab.solids.relief[v] * 1e3:.2f}",
        }
        for v in range(p.pattern.n_vertices)
    ]


def csv_text(columns: tuple[str, ...], rows: list[dict]) -> str:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()


def solid_file_data(
    fab: Fabrication, out: Path, name: str, *, title: str = ""
) -> list[tuple[Path, str | bytes]]:
    """The 3D files and the schedules of ``fab`` as (path in ``out``, data):
    ``NAME_solids.glb/.stl/.obj/.3dm``, ``NAME_hinges.csv`` and ``NAME_vertices.csv``."""
    return [
        (out / f"{name}_solids.glb", glb_bytes(fab)),
        (out / f"{name}_solids.stl", stl_bytes(fab)),
        (out / f"{name}_solids.obj", obj_text(fab, title=title)),
        (out / f"{name}_solids.3dm", rhino_bytes(fab)),
        (out / f"{name}_hinges.csv", csv_text(HINGE_COLUMNS, hinge_rows(fab))),
        (out / f"{name}_vertices.csv", csv_text(VERTEX_COLUMNS, vertex_rows(fab))),
    ]


def write_solid_files(fab: Fabrication, out: Path, name: str, *, title: str = "") -> list[Path]:
    """Write the 3D files and the schedules of ``fab`` into ``out`` (which exists), together
    (:func:`rigidfold.io.files.write_together`, :func:`solid_file_data`); returns them."""
    return write_together(solid_file_data(fab, out, name, title=title))


def write_fabrication(
    fab: Fabrication,
    out: Path,
    name: str,
    *,
    source: str,
    title: str = "",
    label: str = "",
    sheet: tuple[float, float],
    gap: float,
    settings: Settings = DEFAULTS,
) -> tuple[list[Path], dict]:
    """Every file of thick panels into ``out`` (which exists): the solids and schedules
    (:func:`solid_file_data`), the cut sheets nested onto ``sheet`` (width, height) mm stock
    ``gap`` mm apart (:func:`rigidfold.fabricate.cutsheets.cut_sheet_data`, titled
    ``label``), and ``NAME_fabricate.json``: ``{"file": source, **fab.to_dict(),
    "cut_sheets": ..., "written": [the other files]}``. Every file is made in memory first
    and all are written together (:func:`rigidfold.io.files.write_together`: on a full disk
    none appears, and the error says so in one line). Returns (the files in the order
    written, the cut sheets' summary)."""
    from rigidfold.fabricate.cutsheets import cut_sheet_data, sheets_summary
    from rigidfold.fabricate.progress import step
    from rigidfold.io.files import jsonable

    width, height = sheet
    step(f"writing the solids of {fab.panels.n} panels", fab.panels.n, settings=settings)
    files = solid_file_data(fab, out, name, title=title)
    more, sheets = cut_sheet_data(
        fab, out, name, width=width, height=height, gap=gap, title=label, settings=settings
    )
    files += more
    summary = sheets_summary(sheets) | {"stock_mm": [width, height]}
    path = out / FABRICATE_JSON.format(name)
    report = {
        "file": source,
        **fab.to_dict(),
        "cut_sheets": summary,
        "written": [str(p) for p, _ in files],
    }
    text = json.dumps(jsonable(report, where=f"the JSON data of '{path}'"), indent=2)
    files.append((path, text + "\n"))
    return write_together(files), summary


FABRICATE_JSON = "{}_fabricate.json"
"""The summary file :func:`write_fabrication` writes, ``{}`` for the design's name."""


def recorded_thickness(path: str | Path, also: Sequence[Path] = ()) -> tuple[float, Path] | None:
    """(the thickness, metres, that ``rigidfold fabricate`` made the panels of the design in
    FOLD file ``path``, the file that records it) or None: fabricate writes it as
    ``thickness_m`` of ``NAME_fabricate.json`` (:data:`FABRICATE_JSON`)
    in its output directory, looked for beside the design (``fabricate DESIGN.fold --out``
    the design's directory), then in the directories ``also`` (for a run's solution, the
    run's thick panels: :func:`rigidfold.pipeline.built.thick_dir_of`)."""
    path = Path(path)
    name = FABRICATE_JSON.format(path.stem)
    places = [path.parent / name, *(where / name for where in also)]
    for place in places:
        try:
            data = parse_json(place.read_bytes())
        except (OSError, ValueError):
            continue
        t = data.get("thickness_m") if isinstance(data, dict) else None
        if isinstance(t, int | float) and not isinstance(t, bool) and 0 < t < float("inf"):
            return float(t), place
    return None


SOLID_FILES = (
    "{}_solids.glb",
    "{}_solids.stl",
    "{}_solids.obj",
    "{}_solids.3dm",
    "{}_hinges.csv",
    "{}_vertices.csv",
)
"""The names :func:`write_solid_files` writes, ``{}`` for the design's name."""


def recorded_files(out: Path, name: str) -> list[str]:
    """The files of design ``name`` that an earlier ``fabricate`` into ``out`` recorded in
    its ``NAME_fabricate.json`` (``"written"``, and the file itself): their names in
    ``out``, only those of a form it writes (:data:`SOLID_FILES`, the cut sheets'
    :data:`rigidfold.fabricate.cutsheets.SHEET_FILE`); ``[]`` when the file cannot be read
    (absent, not JSON, a symbolic link). ``--overwrite`` removes exactly these."""
    from rigidfold.fabricate.cutsheets import SHEET_FILE
    from rigidfold.io.files import parse_json

    own = FABRICATE_JSON.format(name)
    try:
        fd = os.open(out / own, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        with os.fdopen(fd, "rb") as file:
            data = parse_json(file.read())
    except (OSError, ValueError):
        return []
    written = data.get("written") if isinstance(data, dict) else None
    fixed = {t.format(name) for t in SOLID_FILES}
    sheet = re.compile(SHEET_FILE.format(re.escape(name)), re.DOTALL)
    names = [
        Path(w).name
        for w in (written if isinstance(written, list) else [])
        if isinstance(w, str) and (Path(w).name in fixed or sheet.fullmatch(Path(w).name))
    ]
    return list(dict.fromkeys([*names, own]))
