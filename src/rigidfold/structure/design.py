"""The structure check of a design from its options, and its files.

:class:`StructureOptions` holds the options of ``rigidfold structure`` (which ``rigidfold
generate --structure`` shares), typed and checked once when made; the command line's texts
(``--supports auto``, ``--load uniform=0.5kPa``, ``--limit L/250``) are read once by
:meth:`StructureOptions.from_strings` into :mod:`rigidfold.structure.choices` and
:mod:`rigidfold.structure.loads` values. :func:`plan_design` reads them against a design:
it chooses or checks the supports (a :class:`DesignPlan`), whose ``check`` runs
:func:`rigidfold.structure.check.check_structure` (:func:`check_design` does both);
:func:`write_structure` writes ``structure.json`` and ``structure.png``
(:data:`STRUCTURE_FILES`). ``rigidfold structure`` and ``rigidfold generate --structure``
both go through them.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.flags import option
from rigidfold.io.files import jsonable, parse_json, write_together
from rigidfold.material import Material, material_named, presets_help
from rigidfold.mesh import CreasePattern
from rigidfold.structure.check import (
    StructureCheck,
    check_inputs,
    check_numbers,
    check_structure,
)
from rigidfold.structure.choices import (
    SUPPORT_TYPES,
    Auto,
    Limit,
    Pins,
    Service,
    SupportSpec,
    parse_supports,
)
from rigidfold.structure.loads import LOAD_TYPES, Load, SelfWeight, check_loads, parse_load
from rigidfold.structure.supports import (
    Rigidity,
    Supports,
    auto_supports,
    check_supports,
    index_list,
    parse_indices,
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
    candidates: str | None = None,
    clamped: str = "",
    actuators: str = "",
    settings: Settings = DEFAULTS,
) -> tuple[Rigidity, np.ndarray | None]:
    """(the supports' first-order rigidity, the candidates they were chosen from or None
    where they were given): ``supports`` :class:`Auto` (the fewest pinned ``candidates``:
    ``"boundary"``, ``"ground"`` or ``"V,V,..."``; :class:`Service` starts from the same
    set) or :class:`Pins`, with ``clamped`` vertices and ``actuators`` (free creases held).
    ValueError (one line) for an index the design lacks."""
    V = pattern.n_vertices
    clamp = parse_indices(clamped, V, "clamped vertices")
    held = parse_indices(actuators, pattern.n_edges, "actuators")
    if isinstance(supports, Auto | Service):
        pool = support_candidates(pattern, candidates, settings)
        rigidity = auto_supports(pattern, pool, clamped=clamp, actuated=held, settings=settings)
        return rigidity, pool
    if not isinstance(supports, Pins):
        raise RigidfoldError(f"supports must be Auto, Service or Pins, got {supports!r}")
    pins = parse_indices(supports.text, V, "supports")
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


def check_options(
    *,
    material: Material = material_named(DEFAULTS.structure.material),  # noqa: B008 (frozen)
    loads: tuple[Load, ...] = (),
    limit: Limit = Limit(DEFAULTS.structure.limit),  # noqa: B008 (frozen)
    modes: int = DEFAULTS.structure.modes,
) -> tuple[Material, tuple[Load, ...], float]:
    """(material, loads, limit divisor) of the options; ValueError (one line) for any that
    is not valid, before the design is read."""
    if not isinstance(material, Material):
        raise RigidfoldError(f"material must be a Material, got {material!r}")
    if not isinstance(limit, Limit):
        raise RigidfoldError(f"limit must be a Limit (Limit.parse('L/250')), got {limit!r}")
    if isinstance(modes, bool) or not isinstance(modes, int) or modes < 0:
        raise RigidfoldError(f"modes must be an integer >= 0, got {modes!r}")
    return material, tuple(loads), limit.divisor


_TEXT_FIELDS = ("supports", "loads", "limit")
"""The fields the command line gives as text (:meth:`StructureOptions.from_strings`)."""


_S = DEFAULTS.structure


@dataclass(frozen=True)
class StructureOptions:
    """The structure check of a design as ``rigidfold structure`` takes it (``rigidfold
    generate --structure`` builds the same), every value typed.

    Each field is made by :func:`rigidfold.flags.option` with what it means, also the help of
    its flag (:func:`rigidfold.cli.parser.add_options`: ``rigidfold structure``'s, and
    ``generate``'s prefixed "--structure: "): a new option is a new field here. ``supports``
    is :class:`Auto`, :class:`Service` or :class:`Pins`; ``loads`` a tuple of
    :data:`~rigidfold.structure.loads.Load` terms (:class:`Uniform`, :class:`Pressure`,
    :class:`Point`; a :class:`SelfWeight` among them is ``self_weight``); ``limit`` a
    :class:`Limit`; ``candidates`` None is ``"boundary"``; ``material`` a
    :class:`~rigidfold.material.Material` (the command line: a preset of
    :data:`~rigidfold.structure.MATERIALS` or ``"E,nu,density"``).

    :meth:`from_strings` reads the command line's texts (``"auto"``, ``"uniform=0.5kPa"``,
    ``"L/250"``). Defaults from ``Settings.structure``. Every value is checked when the
    options are made (ValueError, one line, naming what was received); the indices against
    a design by :meth:`check_indices` and :func:`plan_design`.
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
    candidates: str | None = option(
        None,
        "the vertices auto may choose: every boundary vertex, the boundary vertices at the "
        f"lowest height (within {_S.ground_tol:g} m), or a list",
        name="--support-candidates",
        metavar="boundary|ground|V,V,...",
        shown="boundary",
    )
    clamped: str = option(
        "",
        "clamped vertices: translations and the rotations of the panels there held",
        metavar="V,V,...",
        shown="none",
    )
    actuators: str = option(
        "",
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
    limit: Limit = option(  # noqa: RUF009 (frozen)
        Limit(_S.limit),
        "serviceability: the largest displacement may be at most the span over N; the span is "
        "the largest plan distance between supports (twice the reach of a cantilever)",
        metavar="L/N",
        shown=Limit(_S.limit).text,
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
            raise RigidfoldError(f"material must be a Material, got {self.material!r}")
        if not isinstance(self.supports, SUPPORT_TYPES):
            raise RigidfoldError(
                "supports must be Auto(), Service() or Pins(...) (from_strings reads "
                f"'auto', 'service', 'V,V,...'), got {self.supports!r}"
            )
        if isinstance(self.loads, str) or not isinstance(self.loads, tuple | list):
            raise RigidfoldError(f"loads must be a tuple of loads, got {self.loads!r}")
        bad = [x for x in self.loads if not isinstance(x, LOAD_TYPES)]
        if bad:
            raise RigidfoldError(
                "loads must be Uniform, Pressure, Point or SelfWeight (from_strings reads "
                f"'uniform=0.5kPa'), got {bad[0]!r}"
            )
        if any(isinstance(x, SelfWeight) for x in self.loads):
            object.__setattr__(self, "self_weight", True)
        object.__setattr__(
            self, "loads", tuple(x for x in self.loads if not isinstance(x, SelfWeight))
        )
        mat, parsed, _ = check_options(
            material=self.material, loads=self.loads, limit=self.limit, modes=self.modes
        )
        check_numbers(
            thickness=self.thickness,
            hinge_stiffness=self.hinge_stiffness,
            loads=parsed,
            material=mat,
        )
        object.__setattr__(self, "thickness", float(self.thickness))
        object.__setattr__(self, "hinge_stiffness", float(self.hinge_stiffness))
        clamped = index_list(self.clamped, "clamped vertices")
        if isinstance(self.supports, Pins) and not self.supports.vertices and not clamped:
            raise RigidfoldError("give --supports V,V,..., auto or service, or --clamped vertices")
        candidates = self.candidates
        if candidates is not None and (
            not isinstance(candidates, str)
            or candidates.strip().lower() not in ("boundary", "ground")
        ):
            index_list(candidates, "support candidates")
        index_list(self.actuators, "actuators")
        if not isinstance(self.thickness_from, str):
            raise RigidfoldError(f"thickness_from must be text, got {self.thickness_from!r}")
        for name in ("self_weight", "nonlinear"):
            if not isinstance(getattr(self, name), bool):
                raise RigidfoldError(f"{name} must be true or false, got {getattr(self, name)!r}")

    @classmethod
    def from_strings(
        cls,
        *,
        supports: str = "auto",
        loads: tuple[str, ...] | list[str] = (),
        limit: str | float = DEFAULTS.structure.limit,
        **others,
    ) -> StructureOptions:
        """The options of the command line's texts: ``supports`` ``"auto"``, ``"service"`` or
        ``"V,V,..."``; ``loads`` ``--load`` texts (:func:`~rigidfold.structure.parse_load`:
        ``"uniform=0.5kPa"``, a bare number in kPa; ``"point=12:0,0,-2kN"``, a bare number
        in newtons); ``limit`` ``"L/250"`` or 250; the other fields as typed."""
        if isinstance(loads, str) or not isinstance(loads, tuple | list):
            raise RigidfoldError(f"loads must be a list of load texts, got {loads!r}")
        return cls(
            supports=parse_supports(supports),
            loads=tuple(parse_load(text) for text in loads),
            limit=Limit.parse(limit),
            **others,
        )

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
            parse_indices(self.supports.text, n_vertices, "supports")
        if self.candidates is not None and self.candidates.strip().lower() not in (
            "boundary",
            "ground",
        ):
            parse_indices(self.candidates, n_vertices, "support candidates")
        parse_indices(self.clamped, n_vertices, "clamped vertices")
        parse_indices(self.actuators, n_edges, "actuators")
        check_loads(self.loads, n_vertices)

    def replace(self, **changes) -> StructureOptions:
        """These options with ``changes`` (field names), checked; ``supports``, ``loads`` and
        ``limit`` may also be given as the texts of :meth:`from_strings` (the keywords of
        :class:`~rigidfold.generate.GenerateOptions` of earlier versions)."""
        if not changes:
            return self
        if isinstance(changes.get("supports"), str):
            changes["supports"] = parse_supports(changes["supports"])
        loads = changes.get("loads")
        if isinstance(loads, tuple | list) and any(isinstance(x, str) for x in loads):
            changes["loads"] = tuple(parse_load(x) if isinstance(x, str) else x for x in loads)
        if "limit" in changes and not isinstance(changes["limit"], Limit):
            changes["limit"] = Limit.parse(changes["limit"])
        return replace(self, **changes)

    def texts(self) -> dict:
        """``supports``, ``loads`` and ``limit`` as the command line's texts (and
        :meth:`from_strings`) take them: ``"auto"``, ``["uniform=0.5"]`` (kPa), the divisor."""
        return {
            "supports": self.supports.text,
            "loads": [load.text for load in self.loads],
            "limit": self.limit.divisor,
        }

    def to_dict(self) -> dict:
        """The options as JSON values (``supports``, ``loads``, ``limit`` as their texts:
        :meth:`texts`); :meth:`from_dict` reads them."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        data["material"] = self.material.key
        return data | self.texts()

    @classmethod
    def from_dict(cls, data: dict) -> StructureOptions:
        """The options of :meth:`to_dict` (``loads`` a list of texts); unknown keys are
        ignored, missing ones take their defaults."""
        names = {f.name for f in fields(cls)}
        given = {k: v for k, v in data.items() if k in names}
        texts = {k: given.pop(k) for k in _TEXT_FIELDS if k in given}
        if "material" in given:
            given["material"] = Material.from_key(given["material"])
        return cls.from_strings(**texts, **given)


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
    mat, parsed, _ = check_options(material=options.material, loads=options.loads)
    check_inputs(
        pattern,
        thickness=options.thickness,
        hinge_stiffness=options.hinge_stiffness,
        loads=parsed,
        material=mat,
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
        mat,
        options.thickness,
        parsed,
        options.self_weight,
        options.hinge_stiffness,
        options.nonlinear,
        options.limit.divisor,
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


def recorded_thickness(path: str | Path, also: Sequence[Path] = ()) -> tuple[float, Path] | None:
    """(the thickness, metres, that ``rigidfold fabricate`` made the panels of the design in
    FOLD file ``path``, the file that records it) or None: fabricate writes it as
    ``thickness_m`` of ``NAME_fabricate.json`` (:data:`rigidfold.fabricate.files.FABRICATE_JSON`)
    in its output directory, looked for beside the design (``fabricate DESIGN.fold --out``
    the design's directory), then in the directories ``also`` (for a run's solution, the
    run's thick panels: :func:`rigidfold.pipeline.built.thick_dir_of`)."""
    from rigidfold.fabricate.files import FABRICATE_JSON

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
