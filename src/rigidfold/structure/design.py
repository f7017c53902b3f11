"""The structure check of a design from its options, and its files.

:class:`StructureOptions` holds the options of ``rigidfold structure`` (which ``rigidfold
generate --structure`` shares), typed and checked once when made: the supports and indices
:mod:`rigidfold.structure.choices` values, the loads :mod:`rigidfold.structure.loads` values,
the material a :class:`~rigidfold.material.Material`, lengths in metres. The command line's
texts (``--supports auto``, ``--load uniform=0.5kPa``, ``--limit L/250``) are read into them
by :mod:`rigidfold.cli.structure_specs`. :func:`plan_design` reads them against a design:
it chooses or checks the supports (a :class:`DesignPlan`), whose ``check`` runs
:func:`rigidfold.structure.check.check_structure` (:func:`check_design` does both);
:func:`write_structure` writes ``structure.json`` and ``structure.png``
(:data:`STRUCTURE_FILES`). ``rigidfold structure`` and ``rigidfold generate --structure``
both go through them.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.flags import option
from rigidfold.io.files import jsonable, write_together
from rigidfold.material import Material, material_named, presets_help
from rigidfold.mesh import CreasePattern
from rigidfold.structure.check import (
    StructureCheck,
    check_inputs,
    check_limit,
    check_numbers,
    check_structure,
)
from rigidfold.structure.choices import (
    SUPPORT_TYPES,
    Auto,
    Candidates,
    Pins,
    Service,
    SupportSpec,
    check_candidates,
    index_tuple,
    indices_text,
)
from rigidfold.structure.loads import (
    LOAD_TYPES,
    Load,
    Point,
    Pressure,
    SelfWeight,
    Uniform,
    check_loads,
)
from rigidfold.structure.supports import (
    Rigidity,
    Supports,
    auto_supports,
    check_supports,
    index_array,
    support_candidates,
)

STRUCTURE_FILES = ("structure.json", "structure.png")
"""The files :func:`write_structure` writes into its directory."""

Report = Callable[[str], None]
"""Takes a line saying which step of the check starts (progress on stderr)."""


class Steps:
    """Progress of a structure check: :meth:`__call__` hands ``report`` a step's words and
    the seconds since the check began, for designs of more than
    ``Settings.structure.sparse_vertices`` vertices at once, for smaller ones once the check
    has run ``QUIET_FOR`` seconds (a check of a few seconds says nothing)."""

    QUIET_FOR = 2.0

    def __init__(self, report: Report | None, *, large: bool) -> None:
        self.report, self.large, self.t0 = report, large, time.perf_counter()

    def __call__(self, words: str) -> None:
        elapsed = time.perf_counter() - self.t0
        if self.report is not None and (self.large or elapsed >= self.QUIET_FOR):
            self.report(f"{words} ({elapsed:.1f} s)")


def design_supports(
    pattern: CreasePattern,
    supports: SupportSpec = Auto(),  # noqa: B008 (frozen)
    *,
    candidates: Candidates = None,
    clamped: tuple[int, ...] = (),
    actuators: tuple[int, ...] = (),
    settings: Settings = DEFAULTS,
) -> tuple[Rigidity, np.ndarray | None]:
    """(the supports' first-order rigidity, the candidates they were chosen from or None
    where they were given): ``supports`` :class:`Auto` (the fewest pinned ``candidates``:
    :data:`~rigidfold.structure.choices.Candidates`; :class:`Service` starts from the same
    set) or :class:`Pins`, with ``clamped`` vertices and ``actuators`` (free creases held).
    ValueError (one line) for an index the design lacks."""
    V = pattern.n_vertices
    clamp = index_array(clamped, V, "clamped vertices")
    held = index_array(actuators, pattern.n_edges, "actuators")
    if isinstance(supports, Auto | Service):
        pool = support_candidates(pattern, candidates, settings)
        rigidity = auto_supports(pattern, pool, clamped=clamp, actuated=held, settings=settings)
        return rigidity, pool
    if not isinstance(supports, Pins):
        raise RigidfoldError(f"supports must be Auto, Service or Pins, got {supports!r}")
    pins = index_array(supports.vertices, V, "supports")
    if not len(pins) and not len(clamp):
        raise RigidfoldError("give --supports V,V,..., auto or service, or --clamped vertices")
    return check_supports(pattern, Supports(pins, clamp, held), settings), None


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
    steps: Steps | None = None
    """Where the check's steps are reported (:class:`Steps`), or None."""
    thickness_from: str = ""
    """:attr:`StructureOptions.thickness_from`."""

    def check(self) -> StructureCheck:
        """The analysis and its verdict (:func:`rigidfold.structure.check.check_structure`);
        with ``service``, after the supports have been grown for the deflection
        (:func:`rigidfold.structure.service.grow_supports`)."""
        if self.service is None:
            return replace(self._check(self.rigidity), thickness_from=self.thickness_from)
        from rigidfold.structure.service import grow_supports

        count = [0]

        def analyse(rigidity: Rigidity, hinges: float | None) -> StructureCheck:
            count[0] += 1
            self._step(
                f"--supports service: analysis {count[0]}, "
                f"{len(rigidity.supports.pinned)} pins"
                + ("" if hinges is None else f", hinges of {hinges:.3g} N m/rad per m")
            )
            return self._check(rigidity, nonlinear=False, modes=0, hinges=hinges, quiet=True)

        found, growth = grow_supports(
            self.pattern, self.rigidity, self.service, analyse, self.settings
        )
        final = found if not self.nonlinear and not self.modes else self._check(found.rigidity)
        return replace(final, growth=growth, thickness_from=self.thickness_from)

    def _check(
        self,
        rigidity: Rigidity,
        *,
        nonlinear: bool | None = None,
        modes: int | None = None,
        hinges: float | None = None,
        quiet: bool = False,
    ) -> StructureCheck:
        return check_structure(
            self.pattern,
            rigidity,
            material=self.material,
            thickness=self.thickness,
            loads=self.loads,
            self_weight=self.self_weight,
            hinge_stiffness=self.hinge_stiffness if hinges is None else hinges,
            nonlinear=self.nonlinear if nonlinear is None else nonlinear,
            limit=self.limit,
            modes=self.modes if modes is None else modes,
            auto=self.auto,
            settings=self.settings,
            progress=None if quiet else self.steps,
        )

    def _step(self, words: str) -> None:
        if self.steps is not None:
            self.steps(words)


_S = DEFAULTS.structure


@dataclass(frozen=True)
class StructureOptions:
    """The structure check of a design as ``rigidfold structure`` takes it (``rigidfold
    generate --structure`` builds the same), every value typed.

    Each field is made by :func:`rigidfold.flags.option` with what it means, also the help of
    its flag (:func:`rigidfold.cli.parser.add_options`: ``rigidfold structure``'s, and
    ``generate``'s prefixed "--structure: "): a new option is a new field here. ``thickness``
    in metres; ``material`` a :class:`~rigidfold.material.Material`; ``supports`` is
    :class:`Auto`, :class:`Service` or :class:`Pins`; ``candidates`` a
    :data:`~rigidfold.structure.choices.Candidates` (None is ``"boundary"``); ``clamped``
    and ``actuators`` tuples of indices; ``loads`` a tuple of
    :data:`~rigidfold.structure.loads.Load` terms (:class:`Uniform`, :class:`Pressure`,
    :class:`Point`; a :class:`SelfWeight` among them is ``self_weight``); ``limit`` a
    :class:`Limit`; ``candidates`` None is ``"boundary"``; ``material`` a
    :class:`~rigidfold.material.Material` (the command line: a preset of
    :data:`~rigidfold.structure.MATERIALS` or ``"E,nu,density"``).

    The command line's texts are read by :mod:`rigidfold.cli.structure_specs`. Defaults
    from ``Settings.structure``. Every value is checked when the options are made
    (ValueError, one line, naming what was received); the indices against a design by
    :meth:`check_indices` and :func:`plan_design`.
    """

    thickness: float = option(
        _S.thickness,
        "panel thickness in metres, or with a unit: 18mm, 1.8cm",
        parse="thickness",
        metavar="T",
    )
    material: Material = option(  # noqa: RUF009 (frozen)
        material_named(_S.material),
        f"the panels' material: a preset ({presets_help()}) or E,nu,density in SI units (Pa, "
        "-, kg/m^3), e.g. 10e9,0.3,700",
        parse="material",
        metavar="NAME|E,nu,density",
        shown=_S.material,
    )
    supports: SupportSpec = option(  # noqa: RUF009 (frozen)
        Auto(),
        "pinned vertices (indices of the design's vertices); auto: the fewest "
        "--support-candidates that make the mechanism first-order rigid, of the largest "
        "smallest stiffness eigenvalue; service: those, then one more at a time where the "
        "design deflects most until the deflection limit is met (a linear analysis each; "
        "added pins that are not needed are taken away again). A boundary edge whose ends "
        "are both supported is supported along its length",
        metavar="V,V,...|auto|service",
        shown=Auto().text,
    )
    candidates: Candidates = option(  # noqa: RUF009 (a field)
        None,
        "the vertices auto may choose: every boundary vertex, the boundary vertices at the "
        f"lowest height (within {_S.ground_tol:g} m), or a list",
        name="--support-candidates",
        metavar="boundary|ground|V,V,...",
        shown="boundary",
    )
    clamped: tuple[int, ...] = option(
        (),
        "clamped vertices: translations and the rotations of the panels there held",
        metavar="V,V,...",
        shown="none",
    )
    actuators: tuple[int, ...] = option(
        (),
        "free creases (indices into the design's edges_vertices) held at their angle by "
        "actuators: supports of a hinge",
        metavar="I,J,...",
        shown="none",
    )
    hinge_stiffness: float = option(
        _S.hinge_stiffness,
        "rotational stiffness of every free crease, N m/rad per metre of crease",
        parse=float,
        metavar="K",
        shown=f"{_S.hinge_stiffness}, a free hinge" if _S.hinge_stiffness == 0 else None,
    )
    loads: tuple[Load, ...] = option(
        (),
        "a load besides self-weight, repeatable: uniform=Q (per m^2 of plan, downwards: "
        "snow), pressure=Q (normal to the panels, positive pressing on the upper face: wind), "
        "point=V:FX,FY,FZ (a force at vertex V). Q in Pa, kPa, kN/m2 or MPa (uniform=0.5kPa, "
        "500Pa), a bare number in kPa; forces in N, kN or MN (point=12:0,0,-2kN), a bare "
        "number in newtons",
        name="--load",
        metavar="KIND=VALUE",
        repeat=True,
    )
    self_weight: bool = option(
        True, "the panels' weight (density x g x thickness)", switch="leave out"
    )
    limit: float = option(
        _S.limit,
        "serviceability: the largest displacement may be at most the span over N; the span is "
        "the largest plan distance between supports (twice the reach of a cantilever)",
        metavar="L/N",
        shown=f"L/{_S.limit:g}",
    )
    nonlinear: bool = option(
        False,
        f"geometrically nonlinear analysis (corotational shells, {_S.steps} load steps) "
        "instead of a linear one",
        switch="",
    )
    modes: int = option(
        _S.modes, "natural frequencies to compute, 0 for none", parse=int, metavar="N"
    )
    thickness_from: str = option(
        "",
        "where the thickness came from, for the output (structure.json's thickness_from): "
        "empty where it was given, else the command line's words (recorded_thickness)",
        flag=False,
    )

    def __post_init__(self) -> None:
        if not isinstance(self.material, Material):
            raise RigidfoldError(
                f"material must be a Material (rigidfold.material.MATERIALS), got {self.material!r}"
            )
        if not isinstance(self.supports, SUPPORT_TYPES):
            raise RigidfoldError(
                f"supports must be Auto(), Service() or Pins(...), got {self.supports!r}"
            )
        if isinstance(self.loads, str) or not isinstance(self.loads, tuple | list):
            raise RigidfoldError(f"loads must be a tuple of loads, got {self.loads!r}")
        bad = [x for x in self.loads if not isinstance(x, LOAD_TYPES)]
        if bad:
            raise RigidfoldError(
                f"loads must be Uniform, Pressure, Point or SelfWeight, got {bad[0]!r}"
            )
        if any(isinstance(x, SelfWeight) for x in self.loads):
            object.__setattr__(self, "self_weight", True)
        object.__setattr__(
            self, "loads", tuple(x for x in self.loads if not isinstance(x, SelfWeight))
        )
        object.__setattr__(self, "limit", check_limit(self.limit))
        modes = self.modes
        if isinstance(modes, bool) or not isinstance(modes, int) or modes < 0:
            raise RigidfoldError(f"modes must be an integer >= 0, got {modes!r}")
        check_numbers(
            thickness=self.thickness,
            hinge_stiffness=self.hinge_stiffness,
            loads=self.loads,
            material=self.material,
        )
        object.__setattr__(self, "thickness", float(self.thickness))
        object.__setattr__(self, "hinge_stiffness", float(self.hinge_stiffness))
        clamped = index_tuple(self.clamped, "clamped vertices")
        object.__setattr__(self, "clamped", clamped)
        if isinstance(self.supports, Pins) and not self.supports.vertices and not clamped:
            raise RigidfoldError("give --supports V,V,..., auto or service, or --clamped vertices")
        object.__setattr__(self, "candidates", check_candidates(self.candidates))
        object.__setattr__(self, "actuators", index_tuple(self.actuators, "actuators"))
        if not isinstance(self.thickness_from, str):
            raise RigidfoldError(f"thickness_from must be text, got {self.thickness_from!r}")
        for name in ("self_weight", "nonlinear"):
            if not isinstance(getattr(self, name), bool):
                raise RigidfoldError(f"{name} must be true or false, got {getattr(self, name)!r}")

    @property
    def auto(self) -> bool:
        """Whether the supports are chosen (:class:`Auto` or :class:`Service`)."""
        return isinstance(self.supports, Auto | Service)

    @property
    def service(self) -> bool:
        """Whether the chosen supports are grown for the deflection (:class:`Service`)."""
        return isinstance(self.supports, Service)

    def check_indices(self, n_vertices: int, n_edges: int) -> None:
        """ValueError (one line) for a support, candidate, clamped vertex, actuator or point
        load that a design of ``n_vertices`` vertices and ``n_edges`` edges lacks."""
        if isinstance(self.supports, Pins):
            index_array(self.supports.vertices, n_vertices, "supports")
        if isinstance(self.candidates, tuple):
            index_array(self.candidates, n_vertices, "support candidates")
        index_array(self.clamped, n_vertices, "clamped vertices")
        index_array(self.actuators, n_edges, "actuators")
        check_loads(self.loads, n_vertices)

    def replace(self, **changes) -> StructureOptions:
        """These options with ``changes`` (field names, typed values), checked."""
        return replace(self, **changes) if changes else self

    def texts(self) -> dict:
        """``supports``, ``loads``, ``limit``, ``candidates``, ``clamped``, ``actuators`` and
        ``material`` as the options' record holds them: ``"auto"``, ``["uniform=0.5"]``
        (kPa), the divisor, ``"0,6"``, a material's :attr:`~rigidfold.material.Material.key`
        (a preset's name, or ``"E,nu,density"``)."""
        mat = self.material
        candidates = self.candidates
        return {
            "supports": self.supports.text,
            "loads": [load.text for load in self.loads],
            "limit": self.limit,
            "candidates": indices_text(candidates) if isinstance(candidates, tuple) else candidates,
            "clamped": indices_text(self.clamped),
            "actuators": indices_text(self.actuators),
            "material": mat.key,
        }

    def to_dict(self) -> dict:
        """The options as JSON values (the typed ones as :meth:`texts`); :meth:`from_dict`
        reads them."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        return data | self.texts()

    @classmethod
    def from_dict(cls, data: dict) -> StructureOptions:
        """The options of :meth:`to_dict`; unknown keys are ignored, missing ones take their
        defaults. Reads the record's own forms only (those :meth:`texts` writes), not the
        command line's (:mod:`rigidfold.cli.structure_specs`); RigidfoldError naming a value
        it cannot read."""
        names = {f.name for f in fields(cls)}
        given = {k: v for k, v in data.items() if k in names}
        try:
            readers = _RECORD_READERS
            typed = {k: readers[k](v) if k in readers else v for k, v in given.items()}
        except (TypeError, ValueError, KeyError, AttributeError) as exc:
            raise RigidfoldError(f"structure options of a record: cannot read {exc}") from None
        return cls(**typed)


def _record_indices(text: str) -> tuple[int, ...]:
    return tuple(int(t) for t in text.split(",")) if text else ()


def _record_supports(text: str) -> SupportSpec:
    chosen: dict[str, SupportSpec] = {"auto": Auto(), "service": Service()}
    return chosen[text] if text in chosen else Pins(_record_indices(text))


def _record_load(text: str) -> Load:
    kind, _, value = text.partition("=")
    if kind == "point":
        vertex, _, force = value.partition(":")
        fx, fy, fz = (float(f) for f in force.split(","))
        return Point(int(vertex), (fx, fy, fz))
    if kind == "uniform":
        return Uniform(float(value))
    if kind == "pressure":
        return Pressure(float(value))
    if kind == SelfWeight.kind:
        return SelfWeight()
    raise ValueError(f"the load {text!r}")


def _record_material(value: str | dict) -> Material:
    return Material.from_key(value) if isinstance(value, str) else Material.from_dict(value)


_RECORD_READERS: dict[str, Callable] = {
    "supports": _record_supports,
    "loads": lambda texts: tuple(_record_load(t) for t in texts),
    "candidates": lambda v: v if v is None or v in ("boundary", "ground") else _record_indices(v),
    "clamped": _record_indices,
    "actuators": _record_indices,
    "material": _record_material,
}
"""How :meth:`StructureOptions.from_dict` reads each value that :meth:`~StructureOptions.
texts` wrote in the record's own form (the others are JSON values already)."""


def plan_design(
    pattern: CreasePattern,
    options: StructureOptions = StructureOptions(),
    *,
    settings: Settings = DEFAULTS,
    progress: Report | None = None,
) -> DesignPlan:
    """The :class:`DesignPlan` of ``pattern`` with ``options`` (see the module's text and
    :func:`design_supports`); the indices and loads are checked against the design
    (ValueError, one line). ``progress`` is handed a line as each long step starts
    (:class:`Steps`)."""
    check_inputs(
        pattern,
        thickness=options.thickness,
        hinge_stiffness=options.hinge_stiffness,
        loads=options.loads,
        material=options.material,
        settings=settings,
    )
    options.check_indices(pattern.n_vertices, pattern.n_edges)
    steps = Steps(progress, large=pattern.n_vertices > settings.structure.sparse_vertices)
    steps(
        f"supports: the free motions of {pattern.n_vertices} vertices, "
        f"{'the supports chosen' if options.auto else 'the supports checked'}"
    )
    rigidity, pool = design_supports(
        pattern,
        options.supports,
        candidates=options.candidates,
        clamped=options.clamped,
        actuators=options.actuators,
        settings=settings,
    )
    return DesignPlan(
        pattern,
        rigidity,
        pool is not None,
        options.material,
        options.thickness,
        options.loads,
        options.self_weight,
        options.hinge_stiffness,
        options.nonlinear,
        options.limit,
        options.modes,
        settings,
        pool if options.service else None,
        steps,
        options.thickness_from,
    )


def check_design(
    pattern: CreasePattern,
    options: StructureOptions = StructureOptions(),
    *,
    settings: Settings = DEFAULTS,
    progress: Report | None = None,
) -> StructureCheck:
    """The structure check of ``pattern`` with ``options``: every input checked first
    (ValueError, one line), then the analysis (``progress``: :func:`plan_design`)."""
    return plan_design(pattern, options, settings=settings, progress=progress).check()


def write_structure(check: StructureCheck, out: Path, source: str) -> list[Path]:
    """``OUT/structure.json`` (``{"file": source, **check.to_dict()}``) and, when the
    structure was analysed to finite displacements, ``OUT/structure.png`` (the deflected
    shape, :func:`rigidfold.structure.figure.deflection_png`); ``out`` exists. Both are made
    in memory first and written together (:func:`rigidfold.io.files.write_together`): each
    beside its place first, then all renamed into place, so a failed write (a full disk, the
    file size limit) leaves the files there as they were, and the error (RigidfoldError, one
    line) names its cause. Returns them, structure.json first."""
    from rigidfold.structure.figure import deflection_png

    data = jsonable({"file": source, **check.to_dict()}, where="the structure check")
    files: list[tuple[Path, str | bytes]] = []
    png = deflection_png(check)
    if png is not None:
        files.append((out / STRUCTURE_FILES[1], png))
    files.append((out / STRUCTURE_FILES[0], json.dumps(data, indent=2, allow_nan=False) + "\n"))
    written = write_together(files)
    return written[::-1]  # structure.json first, as before
