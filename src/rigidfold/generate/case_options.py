"""What defines a case, as the user gives it: :class:`CaseOptions` (the target surface and
the crease pattern) and :class:`SettingsOptions` (the settings the command line sets, in its
units). ``rigidfold optimize`` and ``generate`` take both, ``study`` some of the settings.

Each field is made by :func:`rigidfold.flags.option` with what it means, also its flag's help.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass

from rigidfold.config import DEFAULT_SEED, DEFAULTS, DOF_COUNTS, HESSIANS, THETA_WIDEN, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.flags import option
from rigidfold.generate.case import Case
from rigidfold.generate.specs import case_from_specs
from rigidfold.io import UP_AXES
from rigidfold.patterns import DEFAULT_SIZE, DIAGONALS, FORMS
from rigidfold.surfaces import SURFACE_FORMS


@dataclass(frozen=True)
class CaseOptions:
    """The target surface and the crease pattern of a case
    as the command line gives them, texts (:meth:`make` reads them with
    :func:`rigidfold.generate.specs.case_from_specs`, and the case checks them)."""

    surface: str = option(
        MISSING,
        f"target surface: {SURFACE_FORMS}. bezier, dome, hp: the paper's, scaled to the "
        "pattern's plan; expr: z = f(x, y) of --expr in metres; mesh:FILE: an OBJ, STL, PLY or "
        "OFF mesh, fitted by a smooth surface; fold:FILE: the 3D shape of a FOLD file. A mesh "
        "is placed like the pattern, the lower-left corner of its plan at (0, 0)",
        metavar="SURFACE",
    )
    pattern: str = option(
        MISSING,
        f"crease pattern: {FORMS}. 1, 1p, 2, 11: the paper's, on 3 m x 3 m; grid:NXxNY: NX x "
        "NY vertices over --size with --diagonals; mesh:POLYGON: a quality triangulation of "
        "the polygon 'x1,y1;x2,y2;...' in metres, or of a file of 'x,y' lines, with "
        "--edge-length; FILE.fold, FILE.svg: a crease pattern drawn in another tool (SVG in "
        "Origami Simulator's colours: red mountain, blue valley, black boundary, yellow flat), "
        "in its own unit or, drawn without one, fitted into --size. The plan is placed with "
        "the lower-left corner of its bounding box at (0, 0); the built-in surfaces scale to "
        "that box, --expr is in metres as given",
    )
    seed: int = option(
        DEFAULT_SEED,
        "random seed, 0 to 2**63 - 1: of the Bezier surface; generate also draws from it the "
        "fictitious hinge stiffnesses K_j (uniform in "
        f"{DEFAULTS.generation.hinge_stiffness:g} +/- "
        f"{DEFAULTS.generation.hinge_stiffness_spread:g} Nm, Section 6.1) that the s and shat "
        "criteria rank by, and the order of the random criterion",
        parse="seed",
    )
    expr: str | None = option(
        None,
        "z = f(x, y) for --surface expr, e.g. '0.2*sin(x)*y'; the next argument is the "
        "expression even when it starts with '-' (--expr -x*y)",
    )
    size: str | None = option(
        None,
        "plan size in metres of a grid: pattern, or the box a FOLD or SVG file drawn without "
        "units is fitted into, aspect ratio kept (default: {:g}x{:g})".format(*DEFAULT_SIZE),
        metavar="WxH",
    )
    scale: float | None = option(
        None,
        "metres per unit of a FOLD or SVG file drawn without units (instead of --size)",
        parse="positive",
        metavar="M_PER_UNIT",
    )
    rigid_panels: bool = option(
        False,
        "rigid panels: a FOLD or SVG file's polygon faces are rigid flat panels, the "
        "diagonals that triangulate them start as fixed creases (default: free creases)",
    )
    up: str = option(
        UP_AXES[0],
        "the up axis of a FOLD pattern and of a mesh: or fold: surface: y for files drawn "
        "y-up (Blender, Origami Simulator)",
        choices=UP_AXES,
    )
    diagonals: str | None = option(
        None,
        f"how a grid: pattern's cells are cut into triangles (default: {DIAGONALS[0]})",
        choices=DIAGONALS,
    )
    edge_length: float | None = option(
        None,
        "target edge length in metres of a mesh: pattern (default: sqrt(footprint area) / "
        f"{DEFAULTS.inputs.mesh_divisions:g})",
        parse="positive",
        metavar="L",
    )
    symmetric: bool = option(
        False,
        "mirror symmetry: the shape is made mirror-symmetric about the target surface's "
        "mirror planes (dome, hp; refused for a surface without any)",
    )

    def make(self, settings: Settings = DEFAULTS) -> Case:
        """The validated case (RigidfoldError naming what was received)."""
        if self.surface == "expr" and not self.expr:
            raise RigidfoldError(
                "--surface expr needs --expr TEXT, e.g. --expr '0.3*sin(x)*cos(y)'"
            )
        if self.expr and self.surface != "expr":
            raise RigidfoldError(f"--expr is only used with --surface expr, not {self.surface}")
        return case_from_specs(
            self.surface,
            self.pattern,
            seed=self.seed,
            expr=self.expr,
            symmetric=self.symmetric,
            size=self.size,
            diagonals=self.diagonals,
            edge_length=self.edge_length,
            scale=self.scale,
            up=self.up,
            rigid_panels=self.rigid_panels,
            settings=settings,
        )


def _degrees(name: str) -> float:
    return math.degrees(getattr(DEFAULTS.design, name))


@dataclass(frozen=True)
class SettingsOptions:
    """The settings the command line sets, in its units (degrees); :meth:`settings` makes
    the :class:`~rigidfold.config.Settings` (which checks them). None: the default."""

    dz: float = option(
        DEFAULTS.design.dz,
        "bound on |z - f(x, y)|: how far, in metres, each vertex may lie above or below the "
        "target surface",
        parse=float,
    )
    theta_min: float | None = option(
        None,
        "smallest sector angle (corner angle of a triangle at a vertex) allowed, degrees "
        f"(default: {_degrees('theta_min'):g})",
        parse=float,
        metavar="DEG",
    )
    theta_max: float | None = option(
        None,
        "largest sector angle (corner angle of a triangle at a vertex) allowed, degrees "
        f"(default: {_degrees('theta_max'):g})",
        parse=float,
        metavar="DEG",
    )
    theta_widen: str = option(
        DEFAULTS.design.theta_widen,
        "which crease patterns widen the sector-angle bounds to their own plan angles where "
        "the plan breaks them: files (patterns read from FOLD or SVG files: a drawing keeps "
        "its slivers), all, or none (the bounds as given) (Settings.design.theta_widen)",
        choices=THETA_WIDEN,
    )
    rho_max: float | None = option(
        None,
        "bound (12) on the fold angle of every free crease, |rho| <= this, degrees (default: "
        "no bound)",
        parse="positive",
        metavar="DEG",
    )
    fold_limit: tuple[float, ...] | None = option(
        None,
        "with the deployability check: where the chain's candidates do not deploy, it starts "
        "again from the initial shape with bound (12) on the fold angle of every free crease "
        "at the next of these angles, degrees (default: "
        f"{','.join(f'{math.degrees(a):g}' for a in DEFAULTS.generation.fold_limits)}; 0: no "
        "restart)",
        parse="angles",
        metavar="DEG[,DEG...]",
    )
    hessian: str = option(
        DEFAULTS.solver.ipopt_hessian,
        "IPOPT's Hessian of the Lagrangian: closed-form or casadi, the symbolic reference (both "
        "exact; they differ by round-off)",
        choices=HESSIANS,
    )
    svg_tolerance: float = option(
        DEFAULTS.inputs.svg_snap_tol,
        "slips of the pen in an SVG pattern mended, as a fraction of the drawing's diagonal: "
        "a crease overshooting the line it ends on, or ending short of one, by up to this much "
        "is cut or extended to it; 0 mends nothing (Settings.inputs.svg_snap_tol)",
        parse="fraction",
        metavar="FRACTION",
    )
    backtrack: int | None = option(
        None,
        "with the deployability check: how many times a chain (the run's first, and each "
        "restart's under --fold-limit) may retract a solution whose shape had no deployable "
        "candidate and resume at the shape before, with its next candidates (default: "
        f"{DEFAULTS.generation.backtrack_max}; 0: never, as in the paper's Step 7)",
        parse=int,
        metavar="N",
    )
    reseeds: int | None = option(
        None,
        "with the deployability check: how many times the search starts again from the "
        "initial shape, with other fictitious hinge stiffnesses for the ranking, where every "
        "chain of a round (backtracking, --fold-limit) ended short of the target DOF; a later "
        "round is kept where it reaches the target or ends lower than the rounds before with a "
        "design known to deploy (default: "
        f"{DEFAULTS.generation.reseeds_timed} with --time-limit, which ends the last, "
        f"{DEFAULTS.generation.reseeds} without; 0: one round)",
        parse=int,
        metavar="N",
    )
    accept_no_gap: bool = option(
        False,
        "with the deployability check: a design at the target DOF without a clear DOF gap "
        "(near-mechanisms) ends the run; by default the search goes on for one with a clear "
        "gap and delivers such a design only where it finds none, the run falling short "
        "(Settings.generation.clear_gap)",
    )
    dof_count: str = option(
        DEFAULTS.mechanism.dof_count,
        "how the search counts a shape's DOF: threshold (the paper's: the singular values of "
        "the constraints below the rank threshold; a design at the target DOF must still show "
        "a clear gap), gap (also the near-mechanisms, below the threshold times the DOF gap, "
        "at every shape), auto (gap with the deployability check, threshold without) "
        "(Settings.mechanism.dof_count)",
        choices=DOF_COUNTS,
    )
    retry_zero_dof: bool = option(
        False,
        "retries of a 0-DOF solution: treated as a lock, the next crease is tried (the "
        "paper's Step 5 ends generation there; with the deployability check, the default, a "
        "0-DOF solution is always retried, since it cannot deploy)",
    )

    def settings(self) -> Settings:
        """The settings of these options, checked (RigidfoldError naming the setting)."""
        given: dict = {} if self.backtrack is None else {"backtrack_max": self.backtrack}
        if self.reseeds is not None:
            given["reseeds"] = given["reseeds_timed"] = self.reseeds
        if self.fold_limit is not None:  # (): none
            given["fold_limits"] = tuple(math.radians(a) for a in self.fold_limit)
        return Settings.from_degrees(
            dz=self.dz,
            theta_min_deg=self.theta_min,
            theta_max_deg=self.theta_max,
            rho_max_deg=self.rho_max,
            theta_widen=self.theta_widen,
            retry_zero_dof=self.retry_zero_dof,
            clear_gap=not self.accept_no_gap,
            dof_count=self.dof_count,
            ipopt_hessian=self.hessian,
            svg_snap_tol=self.svg_tolerance,
            **given,
        )
