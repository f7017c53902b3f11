"""The structure check of a design from its options as the user gives them, and its files.

:func:`plan_design` reads the supports (``"auto"``, ``"service"`` or ``"V,V,..."``), the loads
(``--load`` texts) and the material (a preset or ``"E,nu,density"``), chooses or checks the
supports (a :class:`DesignPlan`), whose ``check`` runs
:func:`rigidfold.structure.check.check_structure` (:func:`check_design` does both);
:func:`write_structure` writes ``structure.json`` and ``structure.png``
(:data:`STRUCTURE_FILES`). ``rigidfold structure`` and ``rigidfold generate --structure``
both go through them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.io.files import atomic_write, write_json
from rigidfold.mesh import CreasePattern
from rigidfold.structure.check import StructureCheck, check_inputs, check_structure, parse_limit
from rigidfold.structure.loads import Load, parse_load
from rigidfold.structure.material import Material, parse_material
from rigidfold.structure.supports import (
    Rigidity,
    Supports,
    auto_supports,
    check_supports,
    parse_indices,
    support_candidates,
)

CHOSEN_SUPPORTS = ("auto", "service")
"""The words ``--supports`` takes besides a list of vertices: ``auto``, the fewest pins that
make the design first-order rigid; ``service``, those and more pins until the deflection
limit is met (:mod:`rigidfold.structure.service`)."""

STRUCTURE_FILES = ("structure.json", "structure.png")
"""The files :func:`write_structure` writes into its directory."""


def design_supports(
    pattern: CreasePattern,
    supports: str = "auto",
    *,
    candidates: str | None = None,
    clamped: str = "",
    actuators: str = "",
    settings: Settings = DEFAULTS,
) -> tuple[Rigidity, bool]:
    """(the supports' first-order rigidity, whether they were chosen): ``supports``
    ``"auto"`` (the fewest pinned ``candidates``: ``"boundary"``, ``"ground"`` or
    ``"V,V,..."``; ``"service"`` starts from the same set) or ``"V,V,..."`` pinned
    vertices, with ``clamped`` vertices and ``actuators`` (free creases held). ValueError
    (one line) for an index the design lacks."""
    V = pattern.n_vertices
    clamp = parse_indices(clamped, V, "clamped vertices")
    held = parse_indices(actuators, pattern.n_edges, "actuators")
    if supports.strip().lower() in CHOSEN_SUPPORTS:
        pool = support_candidates(pattern, candidates, settings)
        rigidity = auto_supports(pattern, pool, clamped=clamp, actuated=held, settings=settings)
        return rigidity, True
    pins = parse_indices(supports, V, "supports")
    if not len(pins) and not len(clamp):
        raise RigidfoldError("give --supports V,V,..., auto or service, or --clamped vertices")
    return check_supports(pattern, Supports(pins, clamp, held), settings), False


@dataclass(frozen=True, eq=False)
class DesignPlan:
    """A structure check with every input read and checked and its supports chosen or
    checked (:func:`plan_design`), not yet analysed: :meth:`check` runs it."""

    pattern: CreasePattern
    rigidity: Rigidity
    auto: bool
    material: Material
    thickness: float
    loads: tuple[Load, ...]
    self_weight: bool
    hinge_stiffness: float
    nonlinear: bool
    limit: float
    modes: int
    settings: Settings
    service: np.ndarray | None = None
    """(c,) int64 the candidates ``--supports service`` may pin, None for other supports."""

    def check(self) -> StructureCheck:
        """The analysis and its verdict (:func:`rigidfold.structure.check.check_structure`);
        with ``service``, after the supports have been grown for the deflection
        (:func:`rigidfold.structure.service.grow_supports`)."""
        if self.service is None:
            return self._check(self.rigidity)
        from rigidfold.structure.service import grow_supports

        found, growth = grow_supports(
            self.pattern,
            self.rigidity,
            self.service,
            lambda rigidity: self._check(rigidity, nonlinear=False, modes=0),
            self.settings,
        )
        final = found if not self.nonlinear and not self.modes else self._check(found.rigidity)
        return replace(final, growth=growth)

    def _check(
        self, rigidity: Rigidity, *, nonlinear: bool | None = None, modes: int | None = None
    ) -> StructureCheck:
        return check_structure(
            self.pattern,
            rigidity,
            material=self.material,
            thickness=self.thickness,
            loads=self.loads,
            self_weight=self.self_weight,
            hinge_stiffness=self.hinge_stiffness,
            nonlinear=self.nonlinear if nonlinear is None else nonlinear,
            limit=self.limit,
            modes=self.modes if modes is None else modes,
            auto=self.auto,
            settings=self.settings,
        )


def check_options(
    *,
    material: str | Material = DEFAULTS.structure.material,
    loads: tuple[str, ...] = (),
    limit: str | float = DEFAULTS.structure.limit,
    modes: int = DEFAULTS.structure.modes,
) -> tuple[Material, tuple[Load, ...], float]:
    """(material, loads, limit divisor) read from the options as given; ValueError (one
    line) for any that is not valid, before the design is read."""
    mat = parse_material(material)
    divisor = parse_limit(limit)
    parsed = tuple(parse_load(text) for text in loads)
    if isinstance(modes, bool) or not isinstance(modes, int) or modes < 0:
        raise RigidfoldError(f"modes must be an integer >= 0, got {modes!r}")
    return mat, parsed, divisor


def plan_design(
    pattern: CreasePattern,
    *,
    supports: str = "auto",
    candidates: str | None = None,
    clamped: str = "",
    actuators: str = "",
    thickness: float = DEFAULTS.structure.thickness,
    material: str | Material = DEFAULTS.structure.material,
    hinge_stiffness: float = DEFAULTS.structure.hinge_stiffness,
    loads: tuple[str, ...] = (),
    self_weight: bool = True,
    limit: str | float = DEFAULTS.structure.limit,
    nonlinear: bool = False,
    modes: int = DEFAULTS.structure.modes,
    settings: Settings = DEFAULTS,
) -> DesignPlan:
    """The :class:`DesignPlan` of ``pattern`` (see the module's text and
    :func:`design_supports`); every input is checked (ValueError, one line)."""
    mat, parsed, divisor = check_options(material=material, loads=loads, limit=limit, modes=modes)
    check_inputs(pattern, thickness=thickness, hinge_stiffness=hinge_stiffness, loads=parsed)
    rigidity, auto = design_supports(
        pattern,
        supports,
        candidates=candidates,
        clamped=clamped,
        actuators=actuators,
        settings=settings,
    )
    return DesignPlan(
        pattern,
        rigidity,
        auto,
        mat,
        thickness,
        parsed,
        self_weight,
        hinge_stiffness,
        nonlinear,
        divisor,
        modes,
        settings,
        support_candidates(pattern, candidates, settings)
        if supports.strip().lower() == "service"
        else None,
    )


def check_design(pattern: CreasePattern, **options) -> StructureCheck:
    """The structure check of ``pattern`` with ``options`` (those of :func:`plan_design`):
    every input checked first (ValueError, one line), then the analysis."""
    return plan_design(pattern, **options).check()


def write_structure(check: StructureCheck, out: Path, source: str) -> list[Path]:
    """``OUT/structure.json`` (``{"file": source, **check.to_dict()}``) and, when the
    structure was analysed, ``OUT/structure.png`` (the deflected shape,
    :func:`rigidfold.structure.figure.deflection_png`); ``out`` exists. Returns them."""
    from rigidfold.structure.figure import deflection_png

    written = [write_json(out / STRUCTURE_FILES[0], {"file": source, **check.to_dict()})]
    png = deflection_png(check)
    if png is not None:
        written.append(atomic_write(out / STRUCTURE_FILES[1], png))
    return written
