"""Step 9: large-deformation check of a polyhedron with OpenSees (paper Section 6.1).

The frame model of Section 2 is built as 3D elastic beams with corotational transformations
(tubes, 20 mm outside diameter, 1 mm wall, E = 200 GPa, nu = 0.3) and driven to the plane
z = 0 by forced z-displacements of every facet node (barycentre) in load steps, as the paper
does in Abaqus. A rigid-foldable shape follows with tiny member deformation; a locked one
must bend its facets.

Model::

    barycentre node of triangle f ---- member ----> edge node of (f, edge e)

* boundary edge, fixed crease ("J"): one edge node shared by the triangles (rigid joint);
* free crease: one edge node per side, plus one *axis node* per side at the crease's end
  vertex, joined to that side's edge node by a beam along the crease. The two sides are
  pinned together at both points (``equalDOF`` of translations, Penalty handler): two pins
  on the crease line make an exact revolute hinge under any rotation. A rotational spring of
  ``hinge_stiffness`` (1e-3 Nm, the paper's stabiliser) joins the two edge nodes.
* supports: x, y and the rotation about z of the support triangle's barycentre (the plan
  rigid-body motions); z of every barycentre is prescribed.

Reported over the whole analysis (paper Section 6.1): the elongation of every edge, from the
midsegments of each triangle's edge nodes (``l_e = 2 |m_a - m_b|``), and the change of the
dihedral angle of every fixed crease, from the triangles' edge nodes. ``mean_dl_mm`` is the
mean over edges of each edge's largest |Delta l| during the analysis; ``max`` is the largest.

With a ``material`` and ``thickness`` (the panels' own, :mod:`rigidfold.material`),
the members are strips of the panel instead of tubes (:class:`PanelSection`): the triangle's
area is shared equally by its three members, so member k of length l_k in triangle f is a
solid rectangle of width ``b = area_f / (3 l_k)`` and the panel's thickness t, lying in the
panel's plane (A = b t; out-of-plane bending I = b t^3 / 12, in-plane I = t b^3 / 12;
St Venant torsion J = b t^3 / 3 (1 - 0.63 t / b), the sides swapped where t > b; G = E / 2
(1 + nu)). The frame then has the panels' volume, and a member's out-of-plane bending
stiffness per unit width is the plate's E t^3 / 12 without the 1 / (1 - nu^2) of plate
bending. A crease's axis member takes the section of its side's member to that crease.
Without a material, the paper's tubes (``Settings.tube_*``), as before.

OpenSees is imported only when an analysis runs (``openseespy``, free for research,
education and internal use; see its licence).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.frame.model import default_support_face
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import angle_change
from rigidfold.outcomes import Outcome
from rigidfold.runtime.quiet import native_quiet

if TYPE_CHECKING:  # the material is the structure check's; only its fields are read here
    from rigidfold.material import Material


@dataclass(frozen=True)
class TubeSection:
    """Properties of a circular hollow section: A, I (= Iy = Iz), J, G."""

    diameter: float
    wall: float
    E: float
    nu: float

    @classmethod
    def from_settings(cls, settings: Settings) -> TubeSection:
        return cls(
            settings.deformation.tube_diameter,
            settings.deformation.tube_wall,
            settings.deformation.youngs_modulus,
            settings.deformation.poisson_ratio,
        )

    @property
    def A(self) -> float:
        d_in = self.diameter - 2 * self.wall
        return math.pi / 4 * (self.diameter**2 - d_in**2)

    @property
    def I(self) -> float:  # noqa: E743 - the usual symbol
        d_in = self.diameter - 2 * self.wall
        return math.pi / 64 * (self.diameter**4 - d_in**4)

    @property
    def J(self) -> float:
        return 2 * self.I

    @property
    def G(self) -> float:
        return self.E / (2 * (1 + self.nu))


@dataclass(frozen=True, eq=False)
class PanelSection:
    """Per-member sections of the frame as strips of the panel (see the module's text).

    E, nu : the material; thickness : t, m; width : (M,) b of every member, m; normal :
    (M, 3) unit normal of each member's panel (the local x-z plane of its section).
    """

    E: float
    nu: float
    thickness: float
    width: np.ndarray
    normal: np.ndarray

    @property
    def G(self) -> float:
        return self.E / (2 * (1 + self.nu))

    @property
    def A(self) -> np.ndarray:
        """(M,) b t."""
        return self.width * self.thickness

    @property
    def I_out(self) -> np.ndarray:
        """(M,) out-of-plane bending, about the member's in-plane normal: b t^3 / 12."""
        return self.width * self.thickness**3 / 12

    @property
    def I_in(self) -> np.ndarray:
        """(M,) in-plane bending, about the panel's normal: t b^3 / 12."""
        return self.thickness * self.width**3 / 12

    @property
    def J(self) -> np.ndarray:
        """(M,) St Venant torsion of a b x t rectangle, a / 3 c^3 (1 - 0.63 c / a) with
        a the longer side and c the shorter."""
        a = np.maximum(self.width, self.thickness)
        c = np.minimum(self.width, self.thickness)
        return a * c**3 / 3 * (1 - 0.63 * c / a)


def panel_section(pattern: CreasePattern, material: Material, thickness: float) -> PanelSection:
    """The frame's members (:func:`_layout`'s order) as strips of ``thickness`` of
    ``material`` (see the module's text)."""
    lay = _layout(pattern)
    x, faces = pattern.coords, pattern.faces
    normal = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    area = 0.5 * np.linalg.norm(normal, axis=1)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    F = pattern.n_faces
    ends = lay.coords[lay.members[: 3 * F, 1]] - lay.coords[lay.members[: 3 * F, 0]]
    width = np.repeat(area / 3, 3) / np.linalg.norm(ends, axis=1)
    face = np.repeat(np.arange(F), 3)
    # the axis members of each free crease: the left side's, then the right side's
    free = pattern.free_creases
    side_width, side_face = [], []
    for side in (0, 1):
        f = pattern.edge_faces[free, side]
        k = np.argmax(pattern.face_edges[f] == free[:, None], axis=1)
        side_width.append(width[3 * f + k])
        side_face.append(f)
    width = np.concatenate([width, *side_width])
    face = np.concatenate([face, *side_face])
    return PanelSection(
        float(material.E), float(material.nu), float(thickness), width, normal[face]
    )


class DeformStatus(Outcome):
    """How the large-deformation check ended."""

    REACHED_PLANE = "reached_plane", "the frame was driven to the plane"
    FAILED = "failed", "the frame did not reach the plane"


@dataclass
class DeformResult:
    """Outcome of the large-deformation check.

    status : DeformStatus; message (the detail) says why it failed.
    load_factor : fraction of the forced displacements applied when the analysis stopped.
    history : one dict per converged load step (load factor, mean and max |Delta l| in mm,
        max |Delta rho_fix| in degrees).
    dl_max_per_edge : (E,) metres, each edge's largest |Delta l| during the analysis.
    drho_max_per_fixed : (n_fix,) radians, each fixed crease's largest |Delta rho|.
    frames : list of (V, 3) vertex positions, one per converged step, folded -> flat.
    """

    status: DeformStatus
    message: str
    load_factor: float
    steps: int
    history: list[dict]
    dl_max_per_edge: np.ndarray
    drho_max_per_fixed: np.ndarray
    frames: list[np.ndarray] = field(repr=False)
    wall_time: float = 0.0

    @property
    def reached_plane(self) -> bool:
        return self.status is DeformStatus.REACHED_PLANE

    @property
    def mean_dl_mm(self) -> float:
        return float(np.mean(self.dl_max_per_edge) * 1e3) if len(self.dl_max_per_edge) else 0.0

    @property
    def max_dl_mm(self) -> float:
        return float(np.max(self.dl_max_per_edge, initial=0.0) * 1e3)

    @property
    def mean_drho_fix_deg(self) -> float:
        d = self.drho_max_per_fixed
        return float(np.degrees(np.mean(d))) if len(d) else 0.0

    @property
    def max_drho_fix_deg(self) -> float:
        return float(np.degrees(np.max(self.drho_max_per_fixed, initial=0.0)))

    def to_dict(self) -> dict:
        """JSON-serialisable figures of the check (not its history or frames)."""
        return {
            "status": self.status.value,
            "message": self.message,
            "reached_plane": self.reached_plane,
            "load_factor": self.load_factor,
            "steps": self.steps,
            "mean_dl_mm": self.mean_dl_mm,
            "max_dl_mm": self.max_dl_mm,
            "mean_drho_fix_deg": self.mean_drho_fix_deg,
            "max_drho_fix_deg": self.max_drho_fix_deg,
            "wall_time": self.wall_time,
        }


@dataclass(frozen=True)
class _Layout:
    """Node numbering of the OpenSees model (0-based here, tags are index + 1)."""

    coords: np.ndarray  # (N, 3) node coordinates
    bary: np.ndarray  # (F,) barycentre node of each triangle
    face_edge_node: np.ndarray  # (F, 3) edge node of (triangle, its k-th edge)
    members: np.ndarray  # (M, 2) beam node pairs
    pins: np.ndarray  # (P, 2) node pairs with equal translations
    springs: np.ndarray  # (h, 2) node pairs with a rotational spring


def _layout(pattern: CreasePattern) -> _Layout:
    x, E, F = pattern.coords, pattern.n_edges, pattern.n_faces
    edges, ef = pattern.edges, pattern.edge_faces
    free = np.zeros(E, dtype=bool)
    free[pattern.free_creases] = True
    mid = 0.5 * (x[edges[:, 0]] + x[edges[:, 1]])
    # edge node of the left side (or the only one): 0..E-1; right sides of free creases next
    right_node = np.full(E, -1)
    right_node[free] = E + np.arange(free.sum())
    n_right = int(free.sum())
    bary = E + n_right + np.arange(F)
    axis_left = E + n_right + F + np.arange(n_right)
    axis_right = axis_left + n_right
    fe = pattern.face_edges
    face = np.repeat(np.arange(F), 3).reshape(F, 3)
    on_right = (ef[fe, 1] == face) & free[fe]
    face_edge_node = np.where(on_right, right_node[fe], fe)
    free_idx = np.flatnonzero(free)
    end = x[edges[free_idx, 1]]
    coords = np.vstack([mid, mid[free_idx], x[pattern.faces].mean(axis=1), end, end])
    members = np.vstack(
        [
            np.column_stack([np.repeat(bary, 3), face_edge_node.ravel()]),
            np.column_stack([free_idx, axis_left]),
            np.column_stack([right_node[free_idx], axis_right]),
        ]
    )
    pins = np.vstack(
        [
            np.column_stack([free_idx, right_node[free_idx]]),
            np.column_stack([axis_left, axis_right]),
        ]
    )
    springs = np.column_stack([free_idx, right_node[free_idx]])
    return _Layout(coords, bary, face_edge_node, members, pins, springs)


def _face_vertices(nodes: np.ndarray, face_edge_node: np.ndarray) -> np.ndarray:
    """(F, 3, 3) triangle corners from their edge nodes: v_k = m_k + m_(k-1) - m_(k+1)."""
    m = nodes[face_edge_node]
    return m + np.roll(m, 1, axis=1) - np.roll(m, -1, axis=1)


def _edge_lengths(nodes: np.ndarray, face_edge_node: np.ndarray) -> np.ndarray:
    """(F, 3) length of each triangle's k-th edge: 2 |m_(k+1) - m_(k-1)| (midsegment)."""
    m = nodes[face_edge_node]
    return 2 * np.linalg.norm(np.roll(m, -1, axis=1) - np.roll(m, 1, axis=1), axis=2)


def _dihedrals(corners: np.ndarray, pattern: CreasePattern, edges: np.ndarray) -> np.ndarray:
    """Signed fold angle of interior ``edges`` from per-triangle corners (F, 3, 3)."""
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    fa, fb = pattern.edge_faces[edges, 0], pattern.edge_faces[edges, 1]
    k = np.argmax(pattern.face_edges[fa] == edges[:, None], axis=1)
    t = corners[fa, (k + 1) % 3] - corners[fa, k]
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    na, nb = n[fa], n[fb]
    return np.arctan2(-np.einsum("ij,ij->i", np.cross(na, nb), t), np.einsum("ij,ij->i", na, nb))


@native_quiet()
def deform(
    pattern: CreasePattern,
    *,
    support_face: int | None = None,
    plane_z: float = 0.0,
    material: Material | None = None,
    thickness: float | None = None,
    settings: Settings = DEFAULTS,
) -> DeformResult:
    """Drive the frame model of ``pattern`` to the plane z = ``plane_z`` (Step 9).

    With a ``material`` (and ``thickness``, m, default ``Settings.structure.thickness``) the
    members are strips of the panel (:func:`panel_section`); without, the paper's tubes.

    A step that does not converge is retried with half the increment up to
    ``deform_max_halvings`` times; then the analysis stops with status FAILED and the figures
    of the converged steps. The equalDOF pins are enforced with the penalty
    ``deform_penalty * E A / mean edge length``. What OpenSees prints is hidden
    (:func:`rigidfold.runtime.quiet.native_quiet`).
    """
    import openseespy.opensees as ops  # heavy: only when an analysis runs

    t_start = time.perf_counter()
    if support_face is None:
        support_face = default_support_face(pattern)
    lay = _layout(pattern)
    sec = TubeSection.from_settings(settings)
    panel = None
    if material is not None:
        t = settings.structure.thickness if thickness is None else thickness
        panel = panel_section(pattern, material, t)
    tag = lambda i: int(i) + 1  # noqa: E731 - OpenSees tags start at 1

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, c in enumerate(lay.coords):
        ops.node(tag(i), *map(float, c))
    sb = tag(lay.bary[support_face])
    ops.fix(sb, 1, 1, 0, 0, 0, 1)
    ops.uniaxialMaterial("Elastic", 1, float(settings.generation.hinge_stiffness))
    for k, (a, b) in enumerate(lay.members):
        d = lay.coords[b] - lay.coords[a]
        if panel is None:
            # any vector not parallel to the member defines its local x-z plane
            ref = np.eye(3)[int(np.argmin(np.abs(d) / np.linalg.norm(d)))]
            props = (sec.A, sec.E, sec.G, sec.J, sec.I, sec.I)
        else:
            # local z along the panel's normal: Iy bends out of the plane, Iz in it
            ref = panel.normal[k]
            props = (
                float(panel.A[k]),
                panel.E,
                panel.G,
                float(panel.J[k]),
                float(panel.I_out[k]),
                float(panel.I_in[k]),
            )
        ops.geomTransf("Corotational", k + 1, *map(float, ref))
        ops.element("elasticBeamColumn", k + 1, tag(a), tag(b), *props, k + 1)
    n_el = len(lay.members)
    for k, (a, b) in enumerate(lay.springs):
        ops.element("zeroLength", n_el + k + 1, tag(a), tag(b), "-mat", 1, 1, 1, "-dir", 4, 5, 6)
    for a, b in lay.pins:
        ops.equalDOF(tag(a), tag(b), 1, 2, 3)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for node in np.unique(np.concatenate([lay.bary, lay.face_edge_node.ravel()])):
        ops.sp(tag(node), 3, float(plane_z - lay.coords[node, 2]))
    EA = sec.E * sec.A if panel is None else panel.E * float(np.mean(panel.A))
    penalty = settings.deformation.penalty * EA / float(np.mean(pattern.edge_lengths))
    ops.constraints("Penalty", penalty, penalty)
    ops.numberer("RCM")
    ops.system("UmfPack")
    ops.test("NormDispIncr", float(settings.deformation.tol), int(settings.deformation.max_iter), 0)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0 / settings.deformation.steps)
    ops.analysis("Static")

    l0 = _edge_lengths(lay.coords, lay.face_edge_node)
    fixed = pattern.fixed_creases
    rho0 = _dihedrals(_face_vertices(lay.coords, lay.face_edge_node), pattern, fixed)
    dl_max = np.zeros(pattern.n_edges)
    drho_max = np.zeros(len(fixed))
    history: list[dict] = []
    frames = [_vertices(pattern, _face_vertices(lay.coords, lay.face_edge_node))]
    tags = [tag(i) for i in range(len(lay.coords))]

    def nodes_now() -> np.ndarray:
        return lay.coords + np.array([ops.nodeDisp(t)[:3] for t in tags])

    lam, step, halvings = 0.0, 1.0 / settings.deformation.steps, 0
    status, message = DeformStatus.REACHED_PLANE, ""
    while lam < 1.0 - settings.deformation.load_tol:
        inc = min(step, 1.0 - lam)
        ops.integrator("LoadControl", inc)
        if ops.analyze(1) != 0:
            halvings += 1
            if halvings > settings.deformation.max_halvings:
                status = DeformStatus.FAILED
                message = f"no convergence at load factor {lam:.4f} (step {inc:.2e})"
                break
            step = inc / 2
            continue
        lam += inc
        x = nodes_now()
        dl = np.abs(_edge_lengths(x, lay.face_edge_node) - l0)
        per_edge = np.zeros(pattern.n_edges)
        np.maximum.at(per_edge, pattern.face_edges.ravel(), dl.ravel())
        dl_max = np.maximum(dl_max, per_edge)
        corners = _face_vertices(x, lay.face_edge_node)
        drho = np.abs(angle_change(_dihedrals(corners, pattern, fixed), rho0))
        drho_max = np.maximum(drho_max, drho)
        frames.append(_vertices(pattern, corners))
        history.append(
            {
                "load_factor": lam,
                "mean_dl_mm": float(per_edge.mean() * 1e3),
                "max_dl_mm": float(per_edge.max() * 1e3),
                "max_drho_fix_deg": float(np.degrees(drho.max(initial=0.0))),
            }
        )
    if status is DeformStatus.REACHED_PLANE:
        z_off = float(np.max(np.abs(nodes_now()[:, 2] - plane_z)))
        if z_off > settings.deformation.plane_tol:
            status = DeformStatus.FAILED
            message = f"a frame node ends {z_off:.3g} m from the plane"
    ops.wipe()
    return DeformResult(
        status=status,
        message=message,
        load_factor=lam,
        steps=len(history),
        history=history,
        dl_max_per_edge=dl_max,
        drho_max_per_fixed=drho_max,
        frames=frames,
        wall_time=time.perf_counter() - t_start,
    )


def _vertices(pattern: CreasePattern, corners: np.ndarray) -> np.ndarray:
    """(V, 3) vertex positions: the mean of the triangles' corner estimates."""
    total = np.zeros((pattern.n_vertices, 3))
    count = np.zeros(pattern.n_vertices)
    np.add.at(total, pattern.faces.ravel(), corners.reshape(-1, 3))
    np.add.at(count, pattern.faces.ravel(), 1.0)
    return total / count[:, None]
