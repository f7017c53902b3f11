"""A FOLD file that Origami Simulator opens: the folded form, y up, in its assignment set.

Origami Simulator (github.com/amandaghassaei/OrigamiSimulator) reads the top-level frame of a
FOLD file and nothing else (``js/importer.js``, ``openFile``; ``js/pattern.js``,
``processFold``). What it takes, from its source:

* ``vertices_coords``, ``edges_vertices``, ``edges_assignment`` and ``faces_vertices``, all
  four (``openFile`` refuses a file without one of them);
* assignments from ``U V M B F C`` only: ``model.js`` (``sync``) files each edge's line under
  its letter and fails on any other, e.g. rigidfold's ``"J"``; ``pattern.js``
  (``getFacesAndVerticesForEdges``) makes creases of ``M``, ``V`` and ``F`` edges, and
  ``model.js`` makes a crease whose target angle is 0 a stiff panel crease, any other a
  folding one; ``C`` edges are cut apart;
* ``edges_foldAngle`` in degrees, valley positive, mountain negative (``openFile`` gives
  ``M`` -180 and ``V`` +180 when the file has no angles): the creases' target angles at 100%
  folding. Its dihedral angle (the ``thetaCalcShader`` of ``index.html``, from the normals
  of the faces in their vertex order) equals FOLD's signed fold angle;
* 3D coordinates with y up: ``processFold`` puts a 2D file's (x, y) at (x, 0, y), and its own
  FOLD export (``js/saveFOLD.js``) is y up; it scales the model to unit size (``model.js``),
  so the unit does not matter;
* faces as vertex triangles indexed with 16 bits (``model.js``: ``Uint16Array``), so at most
  65536 vertices.

:func:`origami_simulator_fold` writes the folded form in the top-level frame, no
``file_frames``: free creases ``M``/``V`` with their fold angles, flat free creases and fixed
creases ``F`` at 0 (fixed creases are rigid panels; one folded more than
``Settings.geometry.flat_angle``, a bent panel read from another tool's file, keeps its angle, which
Origami Simulator folds as a crease), the boundary ``B``. ``edges_rigidfold:fixed`` marks the
fixed creases, so that rigidfold reads the file back (``--up y``) as the same design.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rigidfold.errors import RigidfoldError
from rigidfold.io import write_document
from rigidfold.io.fold import FOLD_SPEC, PREFIX
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import to_y_up

MAX_VERTICES = 2**16
"""Origami Simulator indexes the vertices of its faces with 16-bit integers."""

ASSIGNMENTS = ("M", "V", "F", "B")
"""The assignments of the file: mountain, valley, flat (panel), boundary."""


def origami_simulator_fold(pattern: CreasePattern, *, title: str = "") -> dict:
    """The FOLD document of the folded form ``pattern`` for Origami Simulator (see the module).

    pattern : the design, coordinates (V, 3) in metres, z up, faces (F, 3) counter-clockwise
    from +z. Raises ValueError for more than :data:`MAX_VERTICES` vertices.
    """
    if pattern.n_vertices > MAX_VERTICES:
        raise RigidfoldError(
            f"Origami Simulator reads at most {MAX_VERTICES} vertices (16-bit indices), the "
            f"design has {pattern.n_vertices}"
        )
    rho = pattern.fold_angles
    flat = np.abs(rho) <= pattern.settings.geometry.flat_angle
    letters = np.where(rho > 0, "V", "M")
    letters[flat | pattern.fixed] = "F"
    letters[pattern.is_boundary_edge] = "B"
    angles = np.where(flat | pattern.is_boundary_edge, 0.0, np.degrees(rho))
    return {
        "file_spec": FOLD_SPEC,
        "file_creator": "rigidfold",
        "file_classes": ["singleModel"],
        "frame_title": title,
        "frame_classes": ["foldedForm"],
        "frame_attributes": ["3D"],
        "frame_unit": "m",
        "vertices_coords": to_y_up(pattern.coords).tolist(),
        "faces_vertices": pattern.faces.tolist(),
        "edges_vertices": pattern.edges.tolist(),
        "edges_assignment": letters.tolist(),
        "edges_foldAngle": angles.tolist(),
        f"edges_{PREFIX}fixed": pattern.fixed.tolist(),
    }


def write_origami_simulator_fold(
    path: str | os.PathLike, pattern: CreasePattern, *, title: str = ""
) -> Path:
    """Write :func:`origami_simulator_fold` to ``path`` atomically; returns ``path``."""
    return write_document(path, origami_simulator_fold(pattern, title=title))
