"""The structure check of a design: supports, loads, the shell model's response and the
serviceability verdict, in one result.

:func:`check_structure` checks that the supports make the mechanism first-order rigid
(:mod:`rigidfold.structure.supports`; chosen by ``auto`` when asked), then loads the shell
model (:mod:`rigidfold.structure.model`, :mod:`rigidfold.structure.loads`) and runs it
(:mod:`rigidfold.structure.analysis`). Serviceability: the largest displacement of any node
must be at most span / ``limit`` (``--limit L/250``). The span is the largest plan distance
between two supports; where the supports lie on one line or at one point (a cantilever), it
is twice the largest plan distance from a support to a vertex (the cantilever convention).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.material import Material
from rigidfold.mechanism.second_order import Stability
from rigidfold.mesh import CreasePattern
from rigidfold.outcomes import Outcome
from rigidfold.structure.analysis import ShellResponse, solve_shell
from rigidfold.structure.loads import (
    Load,
    SelfWeight,
    check_loads,
    check_magnitudes,
    nodal_loads,
)
from rigidfold.structure.model import ShellMesh, shell_mesh
from rigidfold.structure.supports import Rigidity, SupportGrowth


class StructureStatus(Outcome):
    """How the structure check ended."""

    PASSED = "passed", "the supports hold the mechanism and the deflection is within the limit"
    DEFLECTION = "deflection", "the largest displacement exceeds the serviceability limit"
    MECHANISM = "mechanism", "the supports leave a mechanism"
    NOT_CONVERGED = "not_converged", "the static analysis did not carry the whole load"


def check_limit(divisor: object) -> float:
    """The deflection limit's divisor (span / ``divisor``: 250.0 for ``L/250``) as a float;
    ValueError naming what was received for one that is not a finite number > 0."""
    value = (
        float(divisor)
        if isinstance(divisor, int | float | np.integer | np.floating)
        and not isinstance(divisor, bool)
        else float("nan")
    )
    if not (np.isfinite(value) and value > 0):
        raise RigidfoldError(
            f"the deflection limit must be L/N with N > 0 (e.g. L/250), got {divisor!r}"
        )
    return value


@dataclass(frozen=True, eq=False)
class StructureCheck:
    """The structure check of one design.

    pattern : the design (actuated creases fixed); material, thickness (m); rigidity : the
    supports' first-order rigidity; loads : the load terms; self_weight : whether included;
    hinge_stiffness : N m/rad per m; nonlinear : geometrically nonlinear analysis; limit :
    the deflection limit's divisor (span / limit); mesh and response : the shell model and
    its response (None when the supports leave a mechanism); growth : how ``--supports
    service`` grew the supports for the deflection (None otherwise); thickness_from : where
    the thickness came from (``""``: given; ``StructureOptions.thickness_from``);
    balance_tol : a static answer whose reactions miss the loads by more than this share of
    them did not carry the load (a singular stiffness: supports that are prestress stable
    only, with free hinges).
    """

    pattern: CreasePattern
    material: Material
    thickness: float
    rigidity: Rigidity
    loads: tuple[Load, ...]
    self_weight: bool
    hinge_stiffness: float
    nonlinear: bool
    limit: float
    mesh: ShellMesh | None
    response: ShellResponse | None
    auto: bool = False
    balance_tol: float = DEFAULTS.structure.balance_tol
    growth: SupportGrowth | None = None
    thickness_from: str = ""

    # ------------------------------------------------------------------ verdict
    @property
    def status(self) -> StructureStatus:
        if not self.rigidity.stable or self.response is None:
            return StructureStatus.MECHANISM
        if (
            not self.response.converged
            or not self.finite
            or not self.balance_error <= self.balance_tol
        ):
            return StructureStatus.NOT_CONVERGED
        if self.max_displacement > self.allowed_displacement:
            return StructureStatus.DEFLECTION
        return StructureStatus.PASSED

    @property
    def passed(self) -> bool:
        return self.status is StructureStatus.PASSED

    @property
    def message(self) -> str:
        """The status's message with this run's detail."""
        status = self.status
        if status is StructureStatus.MECHANISM:
            return status.describe(self.rigidity.detail)
        if status is StructureStatus.NOT_CONVERGED:
            assert self.response is not None
            prestress = (
                "; prestress stable supports carry a load across their flexes only by large "
                "deflection"
                if self.rigidity.stability is Stability.PRESTRESS
                else ""
            )
            why = self.response.message
            if self.response.converged and not self.finite:
                why = "the displacements overflow (the loads or the stiffness are out of range)"
            elif self.response.converged:
                why = (
                    f"the reactions miss the loads by {self.balance_error:.3g} of them: the "
                    "stiffness is singular"
                )
            return status.describe(f"load factor {self.response.load_factor:.3g}; {why}{prestress}")
        prestress = (
            "; the supports are prestress stable, not first-order rigid"
            if self.rigidity.stability is Stability.PRESTRESS
            else ""
        )
        return status.describe(
            f"{self.max_displacement * 1e3:.3g} mm, limit L/{self.limit:g} = "
            f"{self.allowed_displacement * 1e3:.3g} mm on a span of {self.span:.3g} m{prestress}"
            + (self._hint if status is StructureStatus.DEFLECTION else "")
        )

    @property
    def _hint(self) -> str:
        """What may meet a deflection limit that these supports miss."""
        if self.chosen == "auto":
            return "; --supports service pins more vertices where it deflects most"
        if self.growth is not None:
            pinned = len(self.rigidity.supports.pinned)
            alone = (
                f"; pins alone did not meet it ({pinned} pinned of {self.growth.candidates} "
                "candidates)"
            )
            hint = self.growth.hinge_hint
            if hint is not None:
                return (
                    f"{alone}: hinges of {hint[0]:.2g} N m/rad per m would "
                    f"({hint[1] * 1e3:.3g} mm), or thicker panels, or other supports"
                )
            if self.growth.searched_hinges:
                return f"{alone}, nor would stiffer hinges: thicker panels or other supports may"
            return f"{alone}: stiffer hinges, thicker panels or other supports may"
        return ""

    @property
    def chosen(self) -> str:
        """How the supports came: ``"given"``, ``"auto"`` (the fewest pins that make the
        design rigid) or ``"service"`` (those and more for the deflection)."""
        return "service" if self.growth is not None else "auto" if self.auto else "given"

    # ------------------------------------------------------------------ figures
    @cached_property
    def span(self) -> float:
        """The span L of the serviceability limit, m (see the module's text)."""
        xy = self.pattern.coords[self.rigidity.supports.vertices, :2]
        if len(xy) == 0:
            return 0.0
        d = np.linalg.norm(xy[:, None] - xy[None], axis=2)
        longest = float(d.max(initial=0.0))
        centred = xy - xy.mean(axis=0)
        s = np.linalg.svd(centred, compute_uv=False) if len(xy) > 1 else np.zeros(2)
        if len(xy) < 3 or s[-1] <= 1e-6 * max(s[0], 1e-300):  # on one line or one point
            reach = np.linalg.norm(self.pattern.coords[:, None, :2] - xy[None], axis=2)
            return float(2 * reach.min(axis=1).max(initial=0.0))
        return longest

    @property
    def allowed_displacement(self) -> float:
        return self.span / self.limit

    @cached_property
    def magnitudes(self) -> np.ndarray:
        """(N,) float64 displacement magnitude of every shell node, m."""
        assert self.response is not None
        with np.errstate(over="ignore", invalid="ignore"):
            return np.linalg.norm(self.response.displacements[:, :3], axis=1)

    @property
    def finite(self) -> bool:
        """Whether every displacement magnitude is a finite number (True without a
        response)."""
        return self.response is None or bool(np.all(np.isfinite(self.magnitudes)))

    @property
    def max_displacement(self) -> float:
        """Largest displacement magnitude of any node, m (0 without a response)."""
        return float(self.magnitudes.max(initial=0.0)) if self.response is not None else 0.0

    @property
    def total_load(self) -> np.ndarray:
        """(3,) the sum of the loads, N."""
        return self.response.applied.sum(axis=0) if self.response is not None else np.zeros(3)

    @property
    def balance_error(self) -> float:
        """|sum of reactions + sum of loads| / |sum of loads|."""
        if self.response is None:
            return float("nan")
        with np.errstate(over="ignore", invalid="ignore"):
            total = np.linalg.norm(self.total_load)
            residual = np.linalg.norm(self.response.reactions.sum(axis=0) + self.total_load)
            return float(residual / total) if total > 0 else float(residual)

    def hinge_table(self) -> list[dict]:
        """Per free crease: its largest rotation (deg) and its moment (total N m and largest
        N m per metre) from the hinge springs."""
        if self.response is None or self.mesh is None or not len(self.mesh.springs):
            return []
        mesh, rot = self.mesh, self.response.hinge_rotation
        moment = self.hinge_stiffness * mesh.spring_length * rot
        rows = []
        for e in np.unique(mesh.spring_crease):
            sel = mesh.spring_crease == e
            rows.append(
                {
                    "crease": int(e),
                    "vertices": self.pattern.edges[e].tolist(),
                    "max_rotation_deg": float(np.degrees(np.abs(rot[sel]).max())),
                    "moment_Nm": float(moment[sel].sum()),
                    "max_moment_Nm_per_m": float(self.hinge_stiffness * np.abs(rot[sel]).max()),
                }
            )
        return rows

    def to_dict(self) -> dict:
        """What ``DIR/structure.json`` holds."""
        out: dict = {
            "status": self.status.value,
            "message": self.message,
            "material": self.material.to_dict(),
            "thickness_m": self.thickness,
            "thickness_from": self.thickness_from or "given",
            "hinge_stiffness_Nm_per_rad_per_m": self.hinge_stiffness,
            "loads": [load.to_dict() for load in self.loads],
            "self_weight": self.self_weight,
            "analysis": "nonlinear" if self.nonlinear else "linear",
            "supports": {**self.rigidity.to_dict(), "chosen": self.chosen},
            "limit": f"L/{self.limit:g}",
            "span_m": self.span,
        }
        if self.growth is not None:
            out["supports"]["service"] = self.growth.to_dict()
        if self.response is None or self.mesh is None:
            return out
        r, mesh, coords = self.response, self.mesh, self.pattern.coords
        worst = int(np.argmax(self.magnitudes))
        at = mesh.coords[worst]
        nearest = int(np.argmin(np.linalg.norm(coords - at, axis=1)))
        hot = int(np.argmax(r.von_mises)) if len(r.von_mises) else 0
        face = int(mesh.triangle_face[hot])
        hinges = self.hinge_table()
        out.update(
            {
                "shell_elements": mesh.n_elements,
                "nodes": mesh.n_nodes,
                "load_factor": r.load_factor,
                "reactions_N": {
                    str(int(v)): f.tolist()
                    for v, f in zip(self.rigidity.supports.vertices, r.reactions, strict=True)
                },
                "total_load_N": self.total_load.tolist(),
                "reaction_sum_N": r.reactions.sum(axis=0).tolist(),
                "balance_error": self.balance_error,
                "max_displacement_m": self.max_displacement,
                "max_displacement_at": {
                    "position_m": at.tolist(),
                    "displacement_m": r.displacements[worst, :3].tolist(),
                    "nearest_vertex": nearest,
                },
                "max_vertical_displacement_m": float(np.abs(r.displacements[:, 2]).max()),
                "allowed_displacement_m": self.allowed_displacement,
                "serviceability_ok": self.max_displacement <= self.allowed_displacement,
                "frequencies_Hz": r.frequencies.tolist(),
                "max_von_mises_Pa": float(r.von_mises.max(initial=0.0)),
                "max_stress_at": {
                    "triangle": face,
                    "panel": int(self.pattern.facets[face]),
                    "position_m": mesh.coords[mesh.triangles[hot]].mean(axis=0).tolist(),
                },
                "max_hinge_moment_Nm_per_m": max(
                    (h["max_moment_Nm_per_m"] for h in hinges), default=0.0
                ),
                "hinges": hinges,
                "note": r.message,
                "wall_time_s": r.wall_time,
            }
        )
        return out


def check_inputs(
    pattern: CreasePattern,
    *,
    thickness: float,
    hinge_stiffness: float,
    loads: tuple[Load, ...],
    material: Material | None = None,
    settings: Settings = DEFAULTS,
) -> None:
    """ValueError (one line, naming the value) for a thickness that is not a positive number
    of metres, a negative hinge stiffness, a number above
    ``Settings.limits.max_structure_value`` (:func:`check_numbers`), a point load at a
    vertex the design lacks."""
    check_numbers(
        thickness=thickness,
        hinge_stiffness=hinge_stiffness,
        loads=tuple(loads),
        material=material,
        settings=settings,
    )
    check_loads(tuple(loads), pattern.n_vertices)


def check_numbers(
    *,
    thickness: float,
    hinge_stiffness: float,
    loads: tuple[Load, ...] = (),
    material: Material | None = None,
    settings: Settings = DEFAULTS,
) -> None:
    """ValueError (one line, naming the value) for a thickness that is not a positive number
    of metres, a hinge stiffness that is not a number >= 0, and for a thickness, hinge
    stiffness, Young's modulus, density or load above ``Settings.limits.max_structure_value``
    in SI units (beyond it the analysis overflows)."""

    def number(x) -> bool:
        return not isinstance(x, bool) and isinstance(x, int | float | np.number)

    if not (number(thickness) and np.isfinite(thickness) and thickness > 0):
        raise RigidfoldError(f"thickness must be a positive number of metres, got {thickness!r}")
    if not (number(hinge_stiffness) and np.isfinite(hinge_stiffness) and hinge_stiffness >= 0):
        raise RigidfoldError(f"hinge stiffness must be >= 0 N m/rad per m, got {hinge_stiffness!r}")
    largest = settings.limits.max_structure_value
    values = [("thickness", thickness, "m"), ("hinge stiffness", hinge_stiffness, "N m/rad/m")]
    if material is not None:
        values += [("Young's modulus", material.E, "Pa"), ("density", material.density, "kg/m^3")]
    for what, value, unit in values:
        if value > largest:
            raise RigidfoldError(
                f"{what} {value:g} {unit} is above {largest:g} "
                "(Settings.limits.max_structure_value)"
            )
    check_magnitudes(tuple(loads), largest)


@lru_cache(maxsize=2)
def _shell_mesh(pattern: CreasePattern, subdivisions: int) -> ShellMesh:
    """:func:`~rigidfold.structure.model.shell_mesh`, kept for the last designs (the
    analyses of ``--supports service`` share one; a pattern is hashed by identity)."""
    return shell_mesh(pattern, subdivisions)


def check_structure(
    pattern: CreasePattern,
    rigidity: Rigidity,
    *,
    material: Material,
    thickness: float,
    loads: tuple[Load, ...] = (),
    self_weight: bool = True,
    hinge_stiffness: float = 0.0,
    nonlinear: bool = False,
    limit: float = DEFAULTS.structure.limit,
    modes: int = DEFAULTS.structure.modes,
    auto: bool = False,
    settings: Settings = DEFAULTS,
    progress: Callable[[str], None] | None = None,
) -> StructureCheck:
    """Load the design on the supports of ``rigidity`` (from
    :func:`~rigidfold.structure.supports.check_supports` or ``auto_supports``) and check
    it; no analysis when the supports leave a mechanism. ``progress`` is handed a line as
    each analysis starts."""
    check_inputs(
        pattern,
        thickness=thickness,
        hinge_stiffness=hinge_stiffness,
        loads=loads,
        material=material,
        settings=settings,
    )
    if any(isinstance(load, SelfWeight) for load in loads):
        self_weight = True
        loads = tuple(load for load in loads if not isinstance(load, SelfWeight))
    held = rigidity.supports.held(pattern)
    common = dict(
        pattern=held,
        material=material,
        thickness=thickness,
        rigidity=rigidity,
        loads=tuple(loads),
        self_weight=self_weight,
        hinge_stiffness=hinge_stiffness,
        nonlinear=nonlinear,
        limit=limit,
        auto=auto,
        balance_tol=settings.structure.balance_tol,
    )
    if not rigidity.stable:
        return StructureCheck(mesh=None, response=None, **common)  # type: ignore[arg-type]
    mesh = _shell_mesh(held, settings.structure.subdivisions)
    if progress is not None:
        progress(
            f"{'nonlinear' if nonlinear else 'linear'} static analysis of {mesh.n_elements} "
            f"shells in OpenSees"
        )
    weight = material.density * settings.structure.gravity * thickness if self_weight else 0.0
    forces = nodal_loads(mesh, tuple(loads), self_weight=weight)
    response = solve_shell(
        mesh,
        material,
        thickness,
        forces,
        pinned=rigidity.supports.pinned,
        clamped=rigidity.supports.clamped,
        hinge_stiffness=hinge_stiffness,
        nonlinear=nonlinear,
        modes=modes,
        settings=settings,
        progress=progress,
    )
    return StructureCheck(mesh=mesh, response=response, **common)  # type: ignore[arg-type]
