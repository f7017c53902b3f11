"""The one set of a generation run's options: :class:`GenerateOptions`.

The CLI's ``generate``, :func:`rigidfold.generate.generate`, the run writer
(:class:`rigidfold.run.RunWriter`) and the study (:class:`rigidfold.study.StudyConfig`) share
it. The checks of the final design that have their own commands keep their options in those
commands' records: the thick panels in a :class:`rigidfold.fabricate.FabricateOptions`
(``rigidfold fabricate``), the structure in a :class:`rigidfold.structure.StructureOptions`
(``rigidfold structure``); None: the check does not run. summary.json records them under
``fabricate_options`` and ``structure_options``, besides the flat keys every earlier version
wrote (``thickness``, ``side``, ``structure``, ``supports``, ``loads``, ``limit``), which
:meth:`GenerateOptions.from_dict` still reads.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from rigidfold.config import CHECKS, DEFAULT_SEED, DEFAULTS, SIDES, check_seed
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.optimize import SOLVERS
from rigidfold.selection import CRITERIA
from rigidfold.structure.design import StructureOptions
from rigidfold.structure.material import parse_material


class _Unset:
    """A keyword not given (None has a meaning: ``thickness=None`` is no thick panels)."""

    def __repr__(self) -> str:
        return "<unset>"


_UNSET = _Unset()

FLAT_KEYS = ("thickness", "side", "structure", "supports", "loads", "limit")
"""The options of the thick panels and the structure as summary.json has held them since
they were added (flat, the structure a bool); still written and read."""


@dataclass(frozen=True, init=False)
class GenerateOptions:
    """How one generation run goes, in one place: Steps 2-7 (:func:`rigidfold.generate.
    generate`) and the checks that follow them (Steps 8-9 and the final design as built, run
    by :class:`rigidfold.run.RunWriter`).

    criterion : one of ``CRITERIA`` (default: the first, S-hat).
    target_dof : int >= 0, the DOF at which generation ends (default 1: stabilised by one
        support or actuator).
    seed : the stream of the random criterion and of the hinge stiffnesses of S^F-hat.
    solver : one of ``SOLVERS`` (default: the first, IPOPT).
    lookahead : skip the candidates predicted to lock (see :mod:`rigidfold.generate`); the
        forecast's cost is part of the selection time.
    deploy_check : polish every accepted solution to F = 0
        (:meth:`rigidfold.optimize.FormFindingProblem.polish`) and accept it only if its
        rigid-folding path reaches the flat state (:func:`rigidfold.mechanism.path.trace_path`,
        on solutions of at most ``Settings.generation.deploy_check_max_dof`` DOF, 0: all); one
        that does not counts in N_path and is replaced like a lock (Step 7), and a DOF-0 shape
        (which cannot deploy) is retried like a lock where the target is >= 1. False is the
        paper's method.
    support_face : the triangle whose frame node carries the s = 6 supports (default: the
        one nearest the centroid); it sets the metric of the mechanism modes and so the
        S^F-hat scores.
    deform : run Step 9 (the large-deformation check) on the checked solutions.
    check : one of ``CHECKS``: the folding motion and Step 9 on the final design only
        ("final") or on every solution ("all").
    material : the panels' material (a preset name or ``"E,nu,density"``): Step 9's frame
        of strips of the panels (:func:`rigidfold.deform.analysis.panel_section`, of
        :attr:`panel_thickness`), the structure's material (``structure.material`` must be
        it) and the thick panels' density unless ``fabricate.density``; None (the default):
        Step 9 with the paper's steel tubes, the structure's own material, and
        :attr:`panel_material` for the masses.
    fabricate : the final design's thick panels (:class:`~rigidfold.fabricate.
        FabricateOptions`, as ``rigidfold fabricate`` takes them), made from the motion the
        run traced and checked over it; None (the default): none.
    structure : the final design's structure check (:class:`~rigidfold.structure.
        StructureOptions`, as ``rigidfold structure`` takes them; with ``fabricate``, of its
        thickness); None (the default): none.

    The keywords of earlier versions are still taken: ``thickness`` (metres, None: no thick
    panels; else the thick panels' and, with a structure check, its thickness), ``side``,
    ``structure=True`` (a structure check of ``material`` or the default, of ``thickness``
    or the default) and ``supports``, ``loads``, ``limit`` (the structure check's); and read
    back as properties (:attr:`thickness`, :attr:`side`, :attr:`supports`, :attr:`loads`,
    :attr:`limit`: a check's value, or its default where the check does not run).

    Studies do not store the options of the thick panels and the structure
    (:meth:`rigidfold.study.StudyConfig.as_dict`): they run neither.
    """

    criterion: str = CRITERIA[0]
    target_dof: int = 1
    seed: int = DEFAULT_SEED
    solver: str = SOLVERS[0]
    lookahead: bool = False
    deploy_check: bool = True
    support_face: int | None = None
    deform: bool = True
    check: str = CHECKS[0]
    material: str | None = None
    fabricate: FabricateOptions | None = None
    structure: StructureOptions | None = None

    def __init__(
        self,
        criterion: str = CRITERIA[0],
        target_dof: int = 1,
        seed: int = DEFAULT_SEED,
        solver: str = SOLVERS[0],
        lookahead: bool = False,
        deploy_check: bool = True,
        support_face: int | None = None,
        deform: bool = True,
        check: str = CHECKS[0],
        material: str | None = None,
        fabricate: FabricateOptions | None = None,
        structure: StructureOptions | bool | None = None,
        *,
        thickness: float | str | _Unset | None = _UNSET,
        side: str | _Unset = _UNSET,
        supports: str | _Unset = _UNSET,
        loads: tuple[str, ...] | list[str] | _Unset = _UNSET,
        limit: float | str | _Unset = _UNSET,
    ) -> None:
        given = dict(locals())
        for f in fields(self):
            object.__setattr__(self, f.name, given[f.name])
        self._check_run()
        keywords = {"supports": supports, "loads": loads, "limit": limit}
        self._legacy(thickness, side, structure, keywords)
        self._check_checks()

    def _check_run(self) -> None:
        """Validate the options of Steps 2-9 (ValueError naming what was received)."""
        if self.criterion not in CRITERIA:
            raise RigidfoldError(
                f"unknown criterion {self.criterion!r} (choose from {', '.join(CRITERIA)})"
            )
        if self.solver not in SOLVERS:
            raise RigidfoldError(
                f"unknown solver {self.solver!r} (choose from {', '.join(SOLVERS)})"
            )
        if self.check not in CHECKS:
            raise RigidfoldError(f"unknown check {self.check!r} (choose from {', '.join(CHECKS)})")
        target = self.target_dof
        if isinstance(target, bool) or not isinstance(target, int | np.integer) or target < 0:
            raise RigidfoldError(f"target DOF must be an integer >= 0, got {target!r}")
        face = self.support_face
        if face is not None and (isinstance(face, bool) or not isinstance(face, int | np.integer)):
            raise RigidfoldError(f"support face must be a face index, got {face!r}")
        check_seed(self.seed)
        if self.material is not None:
            parse_material(self.material)

    def _legacy(self, thickness, side, structure, keywords: dict) -> None:
        """Fold the keywords of earlier versions into ``fabricate`` and ``structure``, on top
        of those given (so that :meth:`replace` takes them too); each is checked even where
        its check does not run."""
        fab = self.fabricate
        if thickness is not _UNSET:
            if thickness is None:
                fab = None
            elif fab is None:
                fab = FabricateOptions(thickness)
            else:
                fab = replace(fab, thickness=thickness)
        if side is not _UNSET:
            if fab is None:
                if side not in SIDES:
                    raise RigidfoldError(f"side must be one of {', '.join(SIDES)}, got {side!r}")
            else:
                fab = replace(fab, side=side)
        changes = {k: v for k, v in keywords.items() if v is not _UNSET}
        if fab is not None and thickness is not _UNSET:
            changes["thickness"] = fab.thickness
        if isinstance(structure, bool):  # structure=True: a check of the keywords
            base = StructureOptions(
                thickness=DEFAULTS.structure.thickness if fab is None else fab.thickness,
                material=DEFAULTS.structure.material if self.material is None else self.material,
            )
            st = base.replace(**changes)
            structure = st if structure else None
        elif structure is not None and changes:
            structure = structure.replace(**changes)
        elif changes:
            StructureOptions().replace(**changes)  # checked, not used
        object.__setattr__(self, "fabricate", fab)
        object.__setattr__(self, "structure", structure)

    def _check_checks(self) -> None:
        """The thick panels and the structure: of their types, one material and one
        thickness of the panels."""
        fab, st = self.fabricate, self.structure
        if fab is not None and not isinstance(fab, FabricateOptions):
            raise RigidfoldError(f"fabricate must be FabricateOptions or None, got {fab!r}")
        if st is not None and not isinstance(st, StructureOptions):
            raise RigidfoldError(f"structure must be StructureOptions or None, got {st!r}")
        if st is None:
            return
        if self.material is not None and st.material != self.material:
            raise RigidfoldError(
                f"the structure's material {st.material!r} is not the panels' material "
                f"{self.material!r}"
            )
        if fab is not None and st.thickness != fab.thickness:
            raise RigidfoldError(
                f"the structure's thickness {st.thickness:g} m is not the thick panels' "
                f"{fab.thickness:g} m"
            )

    @property
    def panel_material(self) -> str:
        """The material of the structure check and of the thick panels' masses."""
        if self.material is not None:
            return self.material
        return DEFAULTS.structure.material if self.structure is None else self.structure.material

    @property
    def panel_thickness(self) -> float | None:
        """The panels' thickness, metres: the thick panels', else the structure's; None
        where neither runs."""
        if self.fabricate is not None:
            return self.fabricate.thickness
        return None if self.structure is None else self.structure.thickness

    @property
    def thickness(self) -> float | None:
        """The thick panels' thickness, metres; None: no thick panels."""
        return None if self.fabricate is None else self.fabricate.thickness

    @property
    def side(self) -> str:
        """The side of the thick panels (the default where there are none)."""
        return DEFAULTS.fabricate.side if self.fabricate is None else self.fabricate.side

    @property
    def supports(self) -> str:
        """The structure check's supports as text (its default where it does not run)."""
        return (self.structure or StructureOptions()).supports.text

    @property
    def loads(self) -> tuple[str, ...]:
        """The structure check's loads as texts (none where it does not run)."""
        return tuple((self.structure or StructureOptions()).texts()["loads"])

    @property
    def limit(self) -> float:
        """The structure check's deflection limit's divisor (its default where it does not
        run)."""
        return (self.structure or StructureOptions()).limit.divisor

    def replace(self, **changes) -> GenerateOptions:
        """These options with ``changes`` (field names, or the keywords of earlier versions),
        validated; unknown names are a ValueError naming them. A new ``material`` is the
        structure check's too."""
        known = {f.name for f in fields(self)} | {"thickness", "side", "supports", "loads", "limit"}
        unknown = sorted(set(changes) - known)
        if unknown:
            raise RigidfoldError(f"unknown generate option {', '.join(map(repr, unknown))}")
        material = changes.get("material")
        if material is not None and self.structure is not None and "structure" not in changes:
            changes["structure"] = self.structure.replace(material=material)
        return replace(self, **changes) if changes else self

    def to_dict(self) -> dict:
        """The options as JSON values (summary.json's ``options``): the fields, the checks'
        options under ``fabricate_options`` and ``structure_options`` (None: not run), and
        the flat keys of earlier versions (:data:`FLAT_KEYS`)."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        fab, st = data.pop("fabricate"), data.pop("structure")
        return data | {
            "thickness": self.thickness,
            "side": self.side,
            "structure": st is not None,
            "supports": self.supports,
            "loads": self.loads,
            "limit": self.limit,
            "fabricate_options": None if fab is None else fab.to_dict(),
            "structure_options": None if st is None else st.to_dict(),
        }

    @classmethod
    def from_dict(cls, data: dict) -> GenerateOptions:
        """The options of :meth:`to_dict`, or of an earlier version's summary.json (the flat
        keys); keys of other versions (``symmetric``, kept in the case) are ignored, missing
        ones take their defaults."""
        names = {f.name for f in fields(cls)} - {"fabricate", "structure"}
        given = {k: v for k, v in data.items() if k in names}
        if "fabricate_options" in data or "structure_options" in data:
            fab, st = data.get("fabricate_options"), data.get("structure_options")
            return cls(
                **given,
                fabricate=None if fab is None else FabricateOptions.from_dict(fab),
                structure=None if st is None else StructureOptions.from_dict(st),
            )
        flat = {k: data[k] for k in FLAT_KEYS if k in data}
        flat["structure"] = bool(flat.get("structure", False))
        return cls(**given, **flat)
