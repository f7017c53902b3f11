"""The one set of a generation run's options: :class:`GenerateOptions`.

The CLI's ``generate``, :func:`rigidfold.generate.generate`, the run writer
(:class:`rigidfold.pipeline.RunWriter`) and the study (:class:`rigidfold.study.StudyConfig`) share
it. The checks of the final design that have their own commands keep their options in those
commands' records: the thick panels in a :class:`rigidfold.fabricate.FabricateOptions`
(``rigidfold fabricate``), the structure in a :class:`rigidfold.structure.StructureOptions`
(``rigidfold structure``), the deployment drive in a :class:`rigidfold.drive.DriveOptions`
(``rigidfold deploy``); None: the check does not run. summary.json records them under
``fabricate``, ``structure`` and ``drive``.

Each field is made by :func:`rigidfold.flags.option` with what it means, which is also the
help of its command-line flag (``rigidfold generate --target-dof``): a new option is a new
field here, and :mod:`rigidfold.cli.parser` gives it its flag.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from rigidfold.config import CHECKS, DEFAULT_SEED, DEFAULTS, Check, Settings, check_seed
from rigidfold.drive.options import DriveOptions
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.flags import option
from rigidfold.material import Material, Panel, material_named
from rigidfold.optimize import SOLVERS, SolverName
from rigidfold.selection import CRITERIA
from rigidfold.structure.design import StructureOptions

BATCH_CHOICES = ("auto", "on", "off")
"""``GenerateOptions.batch``: several creases per solve (auto: with the deployability check,
until the first chain's first dead end)."""
PROJECTION_CHOICES = ("auto", "always", "large")
"""``GenerateOptions.projection``: the projection onto F = 0 before IPOPT at every size or on
large patterns only (auto: at every size with the deployability check)."""


@dataclass(frozen=True)
class GenerateOptions:
    """How one generation run goes, in one place: Steps 2-7 (:func:`rigidfold.generate.
    generate`) and the checks that follow them (Steps 8-9 and the final design as built, run
    by :class:`rigidfold.pipeline.RunWriter`). Checked when made (:class:`RigidfoldError` naming
    what was received). What each field means: :func:`rigidfold.flags.docs`."""

    criterion: str = option(
        CRITERIA[0],
        "how the next crease line to fix is chosen, lowest score first (Section 5): shat = "
        "S-hat and s = S, the shape score S^S over the mechanism score (from normalised or "
        "plain mechanism modes), ss = S^S alone, random",
        choices=CRITERIA,
    )
    target_dof: int = option(
        1,
        "stop at a shape with this many degrees of freedom (DOF: independent rigid folding "
        "motions; 1 = folds along one path, stabilised by one support or actuator; 0, a "
        "rigid design, only without the deployability check)",
        parse="count",
    )
    seed: int = option(
        DEFAULT_SEED,
        "the stream of the random criterion and of the hinge stiffnesses of S-hat (the "
        "command line's --seed, which also draws the Bezier surface)",
        flag=False,
    )
    solver: SolverName = option(  # noqa: RUF009 (a str)
        SolverName.IPOPT, "solver of problem (6)", choices=SOLVERS
    )
    lookahead: bool = option(
        False,
        "the look-ahead: skip the candidate creases whose fix would lock another crease at "
        "first order, or locked one at an earlier shape (tried only once every other "
        "candidate failed, first together with the nearly flat creases they would lock); the "
        "forecast's cost is part of the selection time",
    )
    deploy_check: bool = option(
        True,
        "the deployability check of Step 5 (each accepted solution of at most DOF max(target, "
        f"{DEFAULTS.generation.deploy_check_max_dof}) is polished to F = 0 and accepted only "
        "if its folding path reaches the flat state, else replaced like a lock and counted in "
        "N_path; a 0-DOF solution, which cannot deploy, is retried like a lock); without it, "
        "the paper's Step 5",
    )
    support_face: int | None = option(
        None,
        "the triangle whose frame node carries the s = 6 supports (None: the one nearest the "
        "centroid); it sets the metric of the mechanism modes and so the S-hat scores",
        flag=False,
    )
    deform: bool = option(
        True,
        "Step 9, the large-deformation check (OpenSees), on the solutions that --check names "
        "(the development diagram, Step 8, and the folding motion run without it)",
    )
    check: Check = option(  # noqa: RUF009 (a str)
        Check.FINAL,
        "which solutions get the folding motion and the large-deformation check: the final "
        "design only, or all (the development diagram is drawn for every solution)",
        choices=CHECKS,
    )
    material: Material | None = option(  # noqa: RUF009 (frozen)
        None,
        "the panels' material: Step 9's frame of strips of the "
        "panels, the structure's material and the thick panels' density unless theirs is "
        "given (None: Step 9 with the paper's steel tubes; the command line's --material)",
        flag=False,
    )
    fabricate: FabricateOptions | None = option(  # noqa: RUF009 (a field, as dataclasses.field)
        None,
        "the final design's thick panels as rigidfold fabricate takes them, made from the "
        "motion the run traced (None: none)",
        flag=False,
    )
    structure: StructureOptions | None = option(  # noqa: RUF009
        None,
        "the final design's structure check as rigidfold structure takes it, of the thick "
        "panels' thickness (None: none)",
        flag=False,
    )
    drive: DriveOptions | None = option(  # noqa: RUF009
        None,
        "the final design's deployment drive as rigidfold deploy takes it (None: none)",
        flag=False,
    )
    batch: str = option(
        "auto",
        "several creases per solve: from the ranked candidates, the largest set whose fixes "
        "are independent and lock no crease at first order (rigidfold.selection.batch), "
        "halved on failure; one crease per solve near the target DOF. auto (the default) = "
        "with the deployability check, until the first dead end of the run's first chain "
        "(then back to the shape before its first set, one crease per solve from there, as "
        "off), off without the check (the paper's Step 5 and the study); off = the paper's "
        "one crease per solve; on = in every chain",
        choices=BATCH_CHOICES,
    )
    projection: str = option(
        "auto",
        "how each solve of problem (6) begins: always = by the projection onto F = 0 from "
        "the start (the parent's shape: the nearest developable shape to it, with one crease "
        "more fixed), IPOPT only where that does not converge (rigidfold.optimize.large); "
        "large = so only on patterns of Settings.solver.projection_vertices or more, IPOPT "
        "alone on smaller ones (the paper's solver, its Tables 5-8); auto (the default) = "
        "always with the deployability check, large without it (the paper's Step 5 and the "
        "study)",
        choices=PROJECTION_CHOICES,
    )
    time_limit: float | None = option(
        None,
        "solve no further candidate after this many seconds (a candidate's path trace under "
        "way ends there too): the run ends with the lowest-DOF design that deploys as its "
        "final design, checked as usual, and exits 1 (None: no limit)",
        parse="positive",
        metavar="SECONDS",
    )

    def __post_init__(self) -> None:
        self._check_run()
        self._check_checks()

    def _check_run(self) -> None:
        """Validate the options of Steps 2-9."""
        for name, choices in (
            ("criterion", CRITERIA),
            ("batch", BATCH_CHOICES),
            ("projection", PROJECTION_CHOICES),
        ):
            value = getattr(self, name)
            if value not in choices:
                raise RigidfoldError(f"unknown {name} {value!r} (choose from {', '.join(choices)})")
        for name, kind, values in (("solver", SolverName, SOLVERS), ("check", Check, CHECKS)):
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise RigidfoldError(
                    f"{name} must be a {kind.__name__} ({', '.join(values)}), got {value!r}"
                )
        target = self.target_dof
        if isinstance(target, bool) or not isinstance(target, int | np.integer) or target < 0:
            raise RigidfoldError(f"target DOF must be an integer >= 0, got {target!r}")
        if target == 0 and self.deploy_check:
            # a DOF-0 design is rigid: it has no folding motion, so it never deploys
            raise RigidfoldError(
                "target DOF 0 asks for a rigid design, which cannot deploy, with the "
                "deployability check, which accepts only designs that deploy: add "
                "--no-deploy-check (deploy_check=False, the paper's Step 5) or aim at DOF 1"
            )
        face = self.support_face
        if face is not None and (isinstance(face, bool) or not isinstance(face, int | np.integer)):
            raise RigidfoldError(f"support face must be a face index, got {face!r}")
        check_seed(self.seed)
        limit = self.time_limit
        if limit is not None and (
            isinstance(limit, bool)
            or not isinstance(limit, int | float | np.integer | np.floating)
            or not 0 < limit < float("inf")
        ):
            raise RigidfoldError(f"time limit must be a number of seconds > 0, got {limit!r}")
        if self.material is not None and not isinstance(self.material, Material):
            raise RigidfoldError(f"material must be a Material or None, got {self.material!r}")

    def _check_checks(self) -> None:
        """The thick panels and the structure: of their types, one material and one
        thickness of the panels."""
        fab, st = self.fabricate, self.structure
        if fab is not None and not isinstance(fab, FabricateOptions):
            raise RigidfoldError(f"fabricate must be FabricateOptions or None, got {fab!r}")
        if st is not None and not isinstance(st, StructureOptions):
            raise RigidfoldError(f"structure must be StructureOptions or None, got {st!r}")
        if self.drive is not None and not isinstance(self.drive, DriveOptions):
            raise RigidfoldError(f"drive must be DriveOptions or None, got {self.drive!r}")
        if st is None:
            return
        if self.material is not None and st.material != self.material:
            raise RigidfoldError(
                f"the structure's material {st.material.key!r} is not the panels' material "
                f"{self.material.key!r}"
            )
        if fab is not None and st.thickness != fab.thickness:
            raise RigidfoldError(
                f"the structure's thickness {st.thickness:g} m is not the thick panels' "
                f"{fab.thickness:g} m"
            )

    @property
    def panel_material(self) -> Material:
        """The material of the structure check and of the thick panels' masses: ``material``,
        else the structure's, else the preset ``Settings.structure.material`` names."""
        if self.material is not None:
            return self.material
        if self.structure is not None:
            return self.structure.material
        return material_named(DEFAULTS.structure.material)

    @property
    def project_first(self) -> bool:
        """Whether every solve of problem (6) begins with the projection onto F = 0
        (:attr:`projection` "always", or "auto" with the deployability check), not only on
        patterns of ``Settings.solver.projection_vertices`` or more."""
        return self.projection == "always" or (self.projection == "auto" and self.deploy_check)

    @property
    def panel_thickness(self) -> float | None:
        """The panels' thickness, metres: the thick panels', else the structure's; None
        where neither runs."""
        if self.fabricate is not None:
            return self.fabricate.thickness
        return None if self.structure is None else self.structure.thickness

    def frame_panel(self, settings: Settings = DEFAULTS) -> Panel | None:
        """The panels whose strips make Step 9's frame: ``material``, of
        :attr:`panel_thickness` (else ``settings.structure.thickness``); None without a
        ``material``: the paper's tubes."""
        if self.material is None:
            return None
        return Panel(self.material, self.panel_thickness or settings.structure.thickness)

    def replace(self, **changes) -> GenerateOptions:
        """These options with ``changes`` (field names), validated; unknown names are a
        RigidfoldError naming them. A new ``material`` is the structure check's too."""
        unknown = sorted(set(changes) - {f.name for f in fields(self)})
        if unknown:
            raise RigidfoldError(f"unknown generate option {', '.join(map(repr, unknown))}")
        material = changes.get("material")
        if material is not None and self.structure is not None and "structure" not in changes:
            changes["structure"] = self.structure.replace(material=material)
        return replace(self, **changes) if changes else self

    def to_dict(self) -> dict:
        """The options as JSON values (summary.json's ``options``): the fields, the checks'
        options as theirs (None: not run)."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        fab, st, dr = data.pop("fabricate"), data.pop("structure"), data.pop("drive")
        data["solver"], data["check"] = self.solver.value, self.check.value
        data["material"] = None if self.material is None else self.material.key
        return data | {
            "fabricate": None if fab is None else fab.to_dict(),
            "structure": None if st is None else st.to_dict(),
            "drive": None if dr is None else dr.to_dict(),
        }

    @classmethod
    def from_dict(cls, data: dict) -> GenerateOptions:
        """The options of :meth:`to_dict`; other keys (``symmetric``, kept in the case) are
        ignored, missing ones take their defaults."""
        given = {f.name: data[f.name] for f in fields(cls) if f.name in data}
        fab, st = given.pop("fabricate", None), given.pop("structure", None)
        dr = given.pop("drive", None)
        if "solver" in given:
            given["solver"] = SolverName(given["solver"])
        if "check" in given:
            given["check"] = Check(given["check"])
        if given.get("material") is not None:
            given["material"] = Material.from_key(given["material"])
        return cls(
            **given,
            fabricate=None if fab is None else FabricateOptions.from_dict(fab),
            structure=None if st is None else StructureOptions.from_dict(st),
            drive=None if dr is None else DriveOptions.from_dict(dr),
        )
