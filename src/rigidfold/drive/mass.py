"""The masses that the drive lifts: the panels, the hinge hardware and point masses, each
moving with one panel.

* a panel: its area x thickness x density, at its centroid (the area-weighted centroid of
  its triangles on the design surface: the panels are modelled by their mid-surface, as
  the shell model of ``structure`` is);
* the hardware of a hinge: its length x kg per metre, at the hinge's midpoint (the centroid
  of a uniform line), moving with the panel on its left;
* a point mass: at its vertex, moving with a panel the vertex belongs to.

Gravity acts along -z of the built design's frame. With the masses' positions in the
design ``x_i`` on panels ``p_i``, a state of panel rotations ``R`` and translations ``t``
(:class:`rigidfold.fabricate.motion.PanelMotion`) puts them at ``R[p_i] x_i + t[p_i]``;
their first moment ``sum m_i x_i`` per panel is all the gravitational energy needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.fabricate.panels import Panels
from rigidfold.mesh.geometry import face_areas


@dataclass(frozen=True, eq=False)
class Masses:
    """The masses of a design (see the module's text).

    panel_kg : (P,) float64, each panel's own mass.
    kg : (P,) float64, all the mass each panel carries (its own, hardware, point masses).
    moment : (P, 3) float64, ``sum m x`` of that mass at its place in the design, kg m.
    face_kg : (F,) float64, the mass of each face of the design's file (``faces_vertices``:
        a polygon face is the sum of its triangles).
    hardware_kg, point_kg : the hardware's and the point masses' total, kg.
    """

    panel_kg: np.ndarray
    kg: np.ndarray
    moment: np.ndarray
    face_kg: np.ndarray
    hardware_kg: float
    point_kg: float

    @property
    def total(self) -> float:
        """Total mass, kg."""
        return float(self.kg.sum())

    def first_moments(self, rotations: np.ndarray, translations: np.ndarray) -> np.ndarray:
        """(K, 3) float64: ``sum m x`` of every mass at each state of panel ``rotations``
        (K, P, 3, 3) and ``translations`` (K, P, 3), kg m."""
        return np.einsum("kpij,pj->ki", rotations, self.moment) + np.einsum(
            "p,kpi->ki", self.kg, translations
        )

    def to_dict(self) -> dict:
        return {
            "total_kg": self.total,
            "panels_kg": float(self.panel_kg.sum()),
            "hardware_kg": self.hardware_kg,
            "point_masses_kg": self.point_kg,
        }


def file_faces(n_triangles: int, polygon_sizes: list[int] | None) -> np.ndarray:
    """(T,) int: the face of the file each triangle comes from, for polygons of
    ``polygon_sizes`` vertices triangulated in order (n - 2 triangles each, as
    :func:`rigidfold.mesh.triangulate.triangulate_polygons` makes them); each triangle its
    own face where the sizes do not add up (or are not known)."""
    if polygon_sizes is None or sum(max(n - 2, 0) for n in polygon_sizes) != n_triangles:
        return np.arange(n_triangles)
    return np.repeat(np.arange(len(polygon_sizes)), [max(n - 2, 0) for n in polygon_sizes])


def polygon_sizes(raw: dict | None) -> list[int] | None:
    """The vertex counts of a FOLD document's ``faces_vertices`` (frame 0), or None."""
    faces = raw.get("faces_vertices") if isinstance(raw, dict) else None
    if not isinstance(faces, list) or not all(isinstance(f, list) for f in faces):
        return None
    return [len(f) for f in faces]


def design_masses(
    panels: Panels,
    *,
    thickness: float,
    density: float,
    hardware: float = 0.0,
    point_masses: tuple[tuple[int, float], ...] = (),
    owner: np.ndarray | None = None,
    face_of: np.ndarray | None = None,
) -> Masses:
    """The :class:`Masses` of ``panels``' design: panels ``thickness`` m of ``density``
    kg/m^3, hinge ``hardware`` kg per metre, ``point_masses`` (vertex, kg); ``owner`` (V,):
    the panel each vertex moves with (default: the first it belongs to); ``face_of`` (T,):
    the file face of each triangle (:func:`file_faces`; default: each its own)."""
    pattern = panels.pattern
    x = pattern.coords
    tri_area = face_areas(x, pattern.faces)
    tri_kg = tri_area * thickness * density
    tri_centre = x[pattern.faces].mean(axis=1)
    label = panels.label
    n = panels.n
    panel_kg = np.bincount(label, weights=tri_kg, minlength=n)
    moment = np.zeros((n, 3))
    np.add.at(moment, label, tri_kg[:, None] * tri_centre)
    kg = panel_kg.copy()
    hardware_kg = 0.0
    if hardware > 0 and panels.n_hinges:
        u, v = panels.hinge_vertices.T
        length = np.linalg.norm(x[v] - x[u], axis=1)
        m = hardware * length
        left = panels.hinge_panels[:, 0]
        np.add.at(kg, left, m)
        np.add.at(moment, left, m[:, None] * (x[u] + x[v]) / 2)
        hardware_kg = float(m.sum())
    if owner is None:
        owner = np.full(pattern.n_vertices, -1, dtype=np.int64)
        for k, verts in reversed(list(enumerate(panels.vertices))):
            owner[verts] = k
    point_kg = 0.0
    for vertex, mass in point_masses:
        p = int(owner[vertex])
        kg[p] += mass
        moment[p] += mass * x[vertex]
        point_kg += mass
    if face_of is None:
        face_of = np.arange(pattern.n_faces)
    face_kg = np.bincount(face_of, weights=tri_kg, minlength=int(face_of.max(initial=-1)) + 1)
    return Masses(panel_kg, kg, moment, face_kg, hardware_kg, point_kg)
