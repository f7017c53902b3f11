"""The drive of a design's deployment (issue 48): analytic cases, the OpenSees check, the
files, bad input."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rigidfold.cli.units import parse_base, parse_cable, parse_point_mass
from rigidfold.config import DEFAULTS
from rigidfold.drive import DEPLOY_FILES, DriveOptions, DriveStatus, deploy_design
from rigidfold.drive import actuators as act
from rigidfold.drive.energy import energy
from rigidfold.drive.equilibria import equilibria, released
from rigidfold.drive.mass import design_masses
from rigidfold.drive.motion import DriveMotion, drive_motion
from rigidfold.errors import RigidfoldError
from rigidfold.exports import read_design
from rigidfold.fabricate.motion import PanelMotion
from rigidfold.fabricate.panels import Panels
from rigidfold.io import write_fold
from rigidfold.mesh import CreasePattern
from rigidfold.mesh.geometry import fold_angles, rigid_motions
from rigidfold.patterns.miura import miura

G = DEFAULTS.drive.gravity
THETA = math.radians(60.0)


def hinge_coords(phi: float, far: float = 1.0) -> np.ndarray:
    """Two triangles on the hinge 0-1 (the x axis): panel A (0, 2, 1) flat, ``far`` across
    the hinge; panel B (0, 1, 3) turned up by ``phi`` (its centroid 1/3 from the hinge)."""
    return np.array(
        [[0, 0, 0], [1, 0, 0], [0.5, -far, 0], [0.5, math.cos(phi), math.sin(phi)]], float
    )


def hinge_pattern(far: float = 1.0) -> CreasePattern:
    return CreasePattern.from_faces(hinge_coords(THETA, far), np.array([[0, 2, 1], [0, 1, 3]]))


def hinge_frames(n: int = 7, far: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The hinge's closed-form motion from flat: ``n`` frames at equal turns."""
    phis = np.linspace(0.0, THETA, n)
    return np.array([hinge_coords(p, far) for p in phis]), phis / THETA


@pytest.fixture
def hinge(tmp_path: Path) -> Path:
    return write_fold(tmp_path / "hinge.fold", hinge_pattern())


def panel_of_face(pattern: CreasePattern, face: int) -> int:
    return int(pattern.facets[face])


def hinge_edge(pattern: CreasePattern) -> int:
    return int(np.flatnonzero((np.sort(pattern.edges, axis=1) == [0, 1]).all(axis=1))[0])


# ------------------------------------------------------------------ one hinge, analytic
@pytest.mark.parametrize("traced", [False, True])
def test_one_hinge_torque_is_m_g_d_cos(hinge: Path, traced: bool) -> None:
    """Panel A clamped, panel B (mass m, centroid d = 1/3 from the hinge) lifted: the
    torque is m g d cos(phi) at every state, from the closed-form frames and from the
    library's own trace; the OpenSees check agrees."""
    pattern = hinge_pattern()
    base = panel_of_face(pattern, 0)
    options = DriveOptions(thickness=0.01, base=base)
    frames = None if traced else hinge_frames()
    r = deploy_design(hinge, options, frames=frames)
    assert r.status is DriveStatus.DRIVEN, r.message
    assert r.drive is not None and r.drive.kind == "crease"
    assert r.drive.ids == (hinge_edge(pattern),)
    m = 0.5 * 0.01 * options.material.density
    phi = r.drive.coordinate
    assert phi[0] == pytest.approx(0.0, abs=1e-9)
    assert phi[-1] == pytest.approx(THETA, abs=1e-6)
    assert np.abs(np.diff(phi)).max() <= DEFAULTS.drive.max_step * (1 + 1e-6)
    expected = m * G / 3 * np.cos(phi)
    np.testing.assert_allclose(r.drive.effort, expected, rtol=1e-3)
    assert r.drive.peak == pytest.approx(m * G / 3, rel=1e-3)
    assert r.drive.peak_s == 0.0
    assert r.check.status.value == "agrees"
    assert len(r.check.states) >= 5
    for c in r.check.states:
        assert c.opensees_Nm == pytest.approx(c.curve_Nm, rel=1e-3)
    assert not r.brake_zones and not r.below
    # released anywhere, the panel falls back to flat
    assert [x.how for x in r.released] == ["flat"]


def test_one_hinge_spring_point_mass_and_friction(hinge: Path) -> None:
    """A spring of k N m/rad per metre at rest flat adds k L phi, a point mass M on the
    far vertex (1 m from the hinge) adds M g cos(phi); friction mu adds mu L deploying and
    takes it away folding back; the OpenSees check (springs as couples, the point mass as a
    load) agrees."""
    pattern = hinge_pattern()
    options = DriveOptions(
        thickness=0.01,
        base=panel_of_face(pattern, 0),
        hinge_stiffness=5.0,
        point_masses=((3, 0.4),),
        friction=0.7,
    )
    r = deploy_design(hinge, options, frames=hinge_frames())
    m = 0.5 * 0.01 * options.material.density
    phi = r.drive.coordinate
    static = (m / 3 + 0.4) * G * np.cos(phi) + 5.0 * phi
    np.testing.assert_allclose(r.drive.effort, static + 0.7, rtol=1e-3)
    # s is phi / THETA: dU/ds = THETA dU/dphi, D = mu L |dphi/ds|
    np.testing.assert_allclose(r.slope, static * THETA, rtol=1e-3)
    np.testing.assert_allclose(r.friction, 0.7 * THETA, rtol=1e-3)
    assert r.check.status.value == "agrees", r.check.message
    for c in r.check.states:  # the check is of the static torque, without friction
        k = int(np.argmin(np.abs(r.s - c.s)))
        assert c.opensees_Nm == pytest.approx(static[k], rel=1e-3)


def test_hardware_of_a_moving_hinge_weighs_on_the_drive(tmp_path: Path) -> None:
    """The hinge's hardware sits on the hinge line: with the panel on one side of it
    clamped it does not move, and adds nothing to the torque; it is counted in the mass,
    and the panels' masses are the faces'."""
    pattern = hinge_pattern()
    path = write_fold(tmp_path / "h.fold", pattern)
    base = panel_of_face(pattern, 0)
    plain = deploy_design(
        path, DriveOptions(thickness=0.01, base=base, check=False), frames=hinge_frames()
    )
    heavy = deploy_design(
        path,
        DriveOptions(thickness=0.01, base=base, hardware=3.0, check=False),
        frames=hinge_frames(),
    )
    np.testing.assert_allclose(heavy.drive.effort, plain.drive.effort, rtol=1e-6)
    assert heavy.masses.hardware_kg == pytest.approx(3.0)
    density = DriveOptions().material.density
    np.testing.assert_allclose(plain.masses.face_kg, [0.5 * 0.01 * density] * 2)


# ------------------------------------------------------------------ Miura-ori, closed form
L_A, L_B, OFFSET, WIDTH, HEIGHT = 1.0, 1.0, 0.4, 1.0, 0.3


def miura_at(h: float) -> CreasePattern:
    """The 3 x 2 Miura-ori folded to height h, in closed form: the zigzags keep their
    segments (length^2 + height^2 and offset^2 + width^2) and the parallelograms their
    angle (length x offset), so every panel is rigid."""
    la = math.hypot(L_A, HEIGHT)
    lb = math.hypot(OFFSET, WIDTH)
    length = math.sqrt(la**2 - h**2)
    offset = L_A * OFFSET / length
    width = math.sqrt(lb**2 - offset**2)
    return miura(3, 2, length=length, width=width, offset=offset, height=h)


def test_miura_strip_closed_form(tmp_path: Path) -> None:
    """A Miura-ori strip whose kinematics are closed form: every refined state is a
    closed-form state (all fold angles within 1e-6 rad of the closed form's at the height
    of its largest fold), and the torque at the frames is dU/drho of the closed form's
    energy (central differences of step 1e-6 on the exact geometry), gravity and hinge
    springs at rest built; the OpenSees check (every hinge's spring) agrees."""
    built = miura_at(HEIGHT)
    path = write_fold(tmp_path / "miura.fold", built)
    heights = np.linspace(0.0, HEIGHT, 7)
    frames = np.array([miura_at(h).coords for h in heights])
    # every panel is tilted when built: clamped there, the flat sheet is tilted too, so the
    # ground is put well below
    options = DriveOptions(thickness=0.012, ground=-5.0, hinge_stiffness=3.0, spring_rest="built")
    r = deploy_design(path, options, frames=(frames, heights / HEIGHT))
    assert r.status is DriveStatus.DRIVEN, r.message
    assert r.motion["source"].startswith("the given 7 frames refined to")
    assert r.check.status.value == "agrees", r.check.message
    panels = Panels(built, miura_at(0.0).coords[:, :2], "top")
    hinges = panels.hinge_edges

    def folds(h: float) -> np.ndarray:
        p = miura_at(h)
        return fold_angles(p.coords, p.faces, p.edges, p.edge_faces)[hinges]

    # the refined states lie on the closed-form motion
    states = r.coords
    major = int(np.argmax(np.abs(folds(HEIGHT))))
    for x in states[1:]:
        f = fold_angles(x, built.faces, built.edges, built.edge_faces)[hinges]
        lo, hi = 0.0, HEIGHT
        for _ in range(60):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if abs(folds(mid)[major]) < abs(f[major]) else (lo, mid)
        np.testing.assert_allclose(f, folds((lo + hi) / 2), atol=1e-6)
    # the torque of the named crease against the closed form's energy
    assert r.drive is not None and r.drive.kind == "crease"
    e = int(np.flatnonzero(hinges == r.drive.ids[0])[0])
    base = r.base
    masses = r.masses

    u, v = built.edges[hinges].T
    length = np.linalg.norm(built.coords[v] - built.coords[u], axis=1)

    def energy_at(h: float) -> float:
        p = miura_at(h)
        rot, tr = rigid_motions(built.coords, p.coords[None], panels.vertices)
        up = rot[0, base][:, 2]
        first = np.einsum("pij,pj->i", rot[0], masses.moment) + masses.kg @ tr[0]
        spring = 0.5 * 3.0 * float(length @ (folds(h) - folds(HEIGHT)) ** 2)
        return G * float(up @ (first - masses.total * tr[0, base])) + spring

    eps = 1e-6
    for h, s in zip(heights[1:-1], (heights / HEIGHT)[1:-1], strict=True):
        du = (energy_at(h + eps) - energy_at(h - eps)) / (2 * eps)
        drho = (folds(h + eps)[e] - folds(h - eps)[e]) / (2 * eps)
        k = int(np.argmin(np.abs(r.s - s)))
        assert r.s[k] == pytest.approx(s, abs=1e-12)
        assert r.drive.effort[k] == pytest.approx(du / drho, abs=2e-3 * r.drive.peak)


# ------------------------------------------------------------------ reversed motion
def test_reversed_motion_gives_the_reversed_curve() -> None:
    """The energy and every crease's torque of a motion run backwards (s -> 1 - s) are
    those of the motion read backwards (without friction: the torque that holds the
    structure does not depend on the direction it moves)."""
    pattern = hinge_pattern(far=2.0)
    panels = Panels(pattern, hinge_coords(0.0, 2.0)[:, :2], "top")
    motion = drive_motion(panels, frames=hinge_frames(13, 2.0))
    pm = motion.motion
    back = DriveMotion(
        panels,
        PanelMotion(
            pm.rotations[::-1],
            pm.translations[::-1],
            1.0 - pm.fraction[::-1],
            pm.closing[::-1],
            "reversed",
        ),
        "reversed",
    )
    masses = design_masses(panels, thickness=0.01, density=700.0)
    forward = energy(motion, masses, gravity=G, stiffness=2.0)
    backward = energy(back, masses, gravity=G, stiffness=2.0)
    for b in range(panels.n):
        np.testing.assert_allclose(backward.total(b), forward.total(b)[::-1], atol=1e-12)
        fwd = act.crease_drives(
            forward.rate, forward.fold, forward.slope(b), forward.s, panels.hinge_edges
        )
        bwd = act.crease_drives(
            backward.rate, backward.fold, backward.slope(b), backward.s, panels.hinge_edges
        )
        np.testing.assert_allclose(bwd[0].effort, fwd[0].effort[::-1], rtol=1e-9)


# ------------------------------------------------------------------ the base and the ground
def test_auto_base_keeps_clear_of_the_ground(tmp_path: Path) -> None:
    """Panel B built tilted at 60 degrees: clamped there, the flat sheet (panel A, 2 m
    across the hinge) swings below the ground; auto clamps A, whose motion stays clear."""
    pattern = hinge_pattern(far=2.0)
    path = write_fold(tmp_path / "h.fold", pattern)
    frames = hinge_frames(7, 2.0)
    a, b = panel_of_face(pattern, 0), panel_of_face(pattern, 1)
    auto = deploy_design(path, DriveOptions(thickness=0.01, check=False), frames=frames)
    assert auto.base == a and auto.base_auto
    placed = {p.panel: p for p in auto.bases}
    assert placed[a].clear and not placed[b].clear
    assert auto.bases[0].panel == a
    tilted = deploy_design(path, DriveOptions(thickness=0.01, base=b, check=False), frames=frames)
    assert tilted.status is DriveStatus.BELOW_GROUND
    deepest = tilted.below[0]
    assert deepest.vertex == 2 and deepest.s == 0.0
    assert deepest.depth == pytest.approx(2.0 * math.sin(THETA), rel=1e-6)
    assert "below the ground" in tilted.summary_line()


# ------------------------------------------------------------------ drives on synthetic curves
S = np.linspace(0.0, 1.0, 201)


def test_dead_point_and_the_pair_that_covers_it() -> None:
    """Crease a turns as cos(pi s) (it stops at s = 1/2: a dead point), crease b as
    sin(pi s) (it stops at the ends); together, shared at least norm, they drive it all:
    tau = P (ra, rb) / (ra^2 + rb^2)."""
    rate = np.column_stack([np.cos(np.pi * S), np.sin(np.pi * S), 0.5 + 0 * S])
    fold = np.zeros_like(rate)
    power = np.full(len(S), 2.0)
    edges = np.array([10, 11, 12])
    ranking = act.crease_drives(rate, fold, power, S, edges)
    by = {a.ids[0]: a for a in ranking}
    assert by[10].dead == pytest.approx((0.5,), abs=1e-9)
    assert by[11].dead and by[11].dead[0] == 0.0
    assert by[12].controls and by[12].peak == pytest.approx(4.0)
    assert ranking[0].ids == (12,)  # the smallest peak, away from the dead points
    # away from its dead point crease a's torque 2 / cos(pi s) stays below 2 / dead_fraction
    assert 4.0 < by[10].peak <= 2.0 / DEFAULTS.drive.dead_fraction
    pair = act.best_pair(ranking, rate, fold, edges, power, S)
    assert pair is not None and pair.controls and set(pair.ids) == {10, 11}
    np.testing.assert_allclose(pair.effort[pair.ids.index(10)], 2.0 * np.cos(np.pi * S))
    np.testing.assert_allclose(pair.effort[pair.ids.index(11)], 2.0 * np.sin(np.pi * S))
    assert pair.peak == pytest.approx(2.0)


def test_sign_changes_and_brake_zones() -> None:
    power = np.cos(2 * np.pi * S)
    assert act.zero_crossings(power, S) == pytest.approx([0.25, 0.75], abs=1e-4)
    ((lo, hi),) = act.zones(power, S)
    assert (lo, hi) == pytest.approx((0.25, 0.75), abs=1e-4)
    ranking = act.crease_drives(
        np.ones((len(S), 1)), np.zeros((len(S), 1)), power, S, np.array([3])
    )
    assert ranking[0].sign_changes == pytest.approx((0.25, 0.75), abs=1e-4)


def test_a_cable_only_pulls() -> None:
    """T = -P / (dl/ds): a cable that shortens as the structure rises pulls; one that
    lengthens would have to push, and says where."""
    power = np.ones(len(S))
    lengths = np.column_stack([2.0 - S, 1.0 + S])
    cables = act.cable_drives(lengths, np.array([[0, 1], [2, 3]]), power, S)
    assert cables[0].controls and cables[0].peak == pytest.approx(1.0)
    np.testing.assert_allclose(cables[0].effort, 1.0)
    assert not cables[1].controls
    assert cables[1].push == ((0.0, 1.0),)
    assert cables[0].name == "cable 0-1"


def test_equilibria_and_where_it_comes_to_rest() -> None:
    """U = sin(2 pi s): flat holds it (U rises from it), a maximum at 1/4 (unstable), a
    minimum at 3/4 (stable); released below 1/4 it falls back to flat, above it it comes to
    rest at 3/4; friction holds it where |dU/ds| <= D."""
    u = np.sin(2 * np.pi * S)
    slope = 2 * np.pi * np.cos(2 * np.pi * S)
    eq = equilibria(u, slope, S)
    assert [(round(e.s, 3), e.stable, e.end) for e in eq] == [
        (0.0, True, "flat"),
        (0.25, False, ""),
        (0.75, True, ""),
    ]
    rel = released(slope, np.zeros(len(S)), S)
    assert [r.how for r in rel] == ["flat", "rest", "rest"]
    assert rel[1].rest == pytest.approx(0.75, abs=1e-3)
    assert rel[2].rest == pytest.approx(0.75, abs=1e-3)
    assert "falls back to flat" in rel[0].describe()
    held = released(slope, np.full(len(S), 100.0), S)
    assert [r.how for r in held] == ["held"]


# ------------------------------------------------------------------ the files
def test_files_and_the_interface(hinge: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    pattern = hinge_pattern()
    r = deploy_design(
        hinge,
        DriveOptions(thickness=0.01, cables=((2, 3),), cables_auto=True),
        out,
        frames=hinge_frames(),
    )
    assert sorted(p.name for p in out.iterdir()) == sorted(DEPLOY_FILES)
    data = json.loads((out / "deploy.json").read_text())
    for key in (
        "schema_version",
        "base_panel",
        "panel_mass_kg",
        "states",
        "drive",
        "ranking",
        "check",
    ):
        assert key in data
    assert data["base_panel"] == [0] and data["panel_mass_kg"] == pytest.approx(
        list(r.masses.face_kg)
    )
    assert len(data["states"]) == len(r.s)
    for row in data["states"]:
        assert {"s", "U_J", "drive_angle_deg", "drive_torque_Nm"} <= set(row)
    assert data["drive"]["kind"] == "crease" and data["drive"]["edges"] == [hinge_edge(pattern)]
    assert {"peak_Nm", "dead_points", "sign_changes"} <= set(data["drive"])
    peaks = [x["peak_Nm"] for x in data["ranking"]]
    assert peaks == sorted(peaks)
    assert data["check"]["status"] == "agrees" and len(data["check"]["states"]) >= 5
    assert data["cables"][0]["vertices"] == [2, 3]
    assert data["summary"] == r.summary_line()
    assert r.summary_line().startswith(f"drive crease {hinge_edge(pattern)}: peak ")
    # deploy.fold: one frame per state, titled with s, the base where it is built
    fold = json.loads((out / "deploy.fold").read_text())
    frames = fold["file_frames"]
    assert len(frames) == len(r.s)
    assert frames[5]["frame_title"] == f"deploy: s = {r.s[5]:.4f}"
    base_vertices = pattern.faces[0]
    for frame in frames:
        xyz = np.asarray(frame["vertices_coords"])
        np.testing.assert_allclose(xyz[base_vertices], pattern.coords[base_vertices], atol=1e-9)
    back = read_design(out / "deploy.fold")
    assert back.frames is not None and len(back.frames.motion) == len(r.s)
    # and deploy reads its own motion back
    again = deploy_design(out / "deploy.fold", DriveOptions(thickness=0.01, check=False))
    assert again.drive.peak == pytest.approx(r.drive.peak, rel=1e-6)
    rows = (out / "deploy.csv").read_text().splitlines()
    assert rows[0] == "s,angle_deg,torque_Nm,torque_folding_back_Nm,U_J"
    assert len(rows) == len(r.s) + 1
    assert (out / "deploy.png").read_bytes()[:4] == b"\x89PNG"


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "changes",
    [
        {"hinge_stiffness": -1.0},
        {"hinge_stiffness": math.nan},
        {"friction": -0.1},
        {"hardware": math.inf},
        {"density": -700.0},
        {"point_masses": ((3, -1.0),)},
        {"point_masses": ((3, math.nan),)},
        {"thickness": 0.0},
        {"max_torque": 0.0},
        {"base": -1},
        {"cables": ((4, 4),)},
        {"spring_rest": "sideways"},
    ],
)
def test_bad_options_are_one_line_errors(changes: dict) -> None:
    with pytest.raises(RigidfoldError) as info:
        DriveOptions(**changes)
    assert "\n" not in str(info.value)


def test_parsers() -> None:
    assert parse_base("auto") == "auto" and parse_base("panel:3") == 3 and parse_base("7") == 7
    assert parse_cable("4,77") == (4, 77) and parse_cable("4-77") == (4, 77)
    assert parse_point_mass("3:2.5") == (3, 2.5)
    for bad in ("panel:x", "panel:-2"):
        with pytest.raises(RigidfoldError, match="base"):
            parse_base(bad)
    with pytest.raises(RigidfoldError, match="cable"):
        parse_cable("4")
    with pytest.raises(RigidfoldError, match="point mass"):
        parse_point_mass("3")


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (DriveOptions(base=5), "base panel 5 is not in the design"),
        (DriveOptions(cables=((0, 9),)), "vertex 9 is not in the design"),
        (DriveOptions(point_masses=((12, 1.0),)), "point mass at vertex 12"),
    ],
)
def test_indices_the_design_lacks(hinge: Path, tmp_path: Path, options, words: str) -> None:
    out = tmp_path / "out"
    with pytest.raises(RigidfoldError, match=words):
        deploy_design(hinge, options, out, frames=hinge_frames())
    assert not out.exists()


def test_a_design_of_another_dof_is_refused(tmp_path: Path) -> None:
    """Three triangles in a fan: two free creases and no interior vertex, DOF 2."""
    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0.3], [-0.5, 1, 0.6], [-1, 0, 0.2]], float)
    pattern = CreasePattern.from_faces(x, np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4]]))
    path = write_fold(tmp_path / "fan.fold", pattern)
    out = tmp_path / "out"
    with pytest.raises(RigidfoldError, match="the design has DOF 2, not 1") as info:
        deploy_design(path, DriveOptions(), out)
    assert "\n" not in str(info.value)
    assert not out.exists()


def test_a_motion_that_does_not_reach_flat_is_refused(hinge: Path, tmp_path: Path) -> None:
    from rigidfold.mechanism.path import PathStatus, trace_path

    path = replace(
        trace_path(hinge_pattern()), status=PathStatus.TURNED_BACK, message="made up here"
    )
    out = tmp_path / "out"
    with pytest.raises(RigidfoldError, match="does not reach the flat state"):
        deploy_design(hinge, DriveOptions(), out, path=path)
    assert not out.exists()


def test_the_thickness_fabricate_recorded(hinge: Path) -> None:
    """Without --thickness, the thickness ``rigidfold fabricate`` recorded beside the design
    (its NAME_fabricate.json), and deploy.json says where it came from."""
    (hinge.parent / "hinge_fabricate.json").write_text(json.dumps({"thickness_m": 0.025}))
    r = deploy_design(hinge, DriveOptions(check=False), frames=hinge_frames())
    assert r.thickness == 0.025 and "hinge_fabricate.json" in r.thickness_from
    assert r.to_dict()["panels"]["thickness_from"] == r.thickness_from
    given = deploy_design(hinge, DriveOptions(thickness=0.01, check=False), frames=hinge_frames())
    assert given.thickness == 0.01 and given.to_dict()["panels"]["thickness_from"] == "given"


def test_held_conditioning_tells_a_near_mechanism() -> None:
    """One hinge held: rigid, well conditioned. A fan of three triangles (two free creases)
    held at one crease still moves about the other: the check could not decide there."""
    from rigidfold.drive.check import held_conditioning

    pattern = hinge_pattern()
    assert held_conditioning(pattern, pattern.coords, hinge_edge(pattern)) > 1e-3
    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0.3], [-0.5, 1, 0.6], [-1, 0, 0.2]], float)
    fan = CreasePattern.from_faces(x, np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4]]))
    crease = int(fan.free_creases[0])
    assert held_conditioning(fan, fan.coords, crease) < 1e-8


def test_its_own_output_does_not_replace_the_design(tmp_path: Path) -> None:
    """deploy.fold read back and written into its own directory: refused before anything
    is computed."""
    path = write_fold(tmp_path / "deploy.fold", hinge_pattern())
    before = path.read_bytes()
    with pytest.raises(RigidfoldError, match="would replace the input file"):
        deploy_design(path, DriveOptions(), tmp_path)
    assert path.read_bytes() == before
