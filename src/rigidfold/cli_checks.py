"""The command-line options of the thick-panel and structure checks, one function per check,
shared by the standalone commands and by ``generate``.

:func:`fabricate_arguments` adds ``rigidfold fabricate``'s options, :func:`structure_arguments`
``rigidfold structure``'s, to a parser: the command's own, or ``generate``'s, where they mean
the same for its final design. :func:`fabricate_options` and :func:`structure_options` make
the :class:`~rigidfold.fabricate.FabricateOptions` and
:class:`~rigidfold.structure.StructureOptions` of the parsed arguments, which check them.

One flag differs: ``generate --thickness T`` is the thick panels' thickness (it asks for
them) and also the panels' thickness of ``--structure`` and of Step 9's frame with
``--material``; ``rigidfold structure --thickness`` is the structure's alone (generate has no
separate one). ``generate --material`` is the structure's material, Step 9's, and gives the
thick panels' density unless ``--density``; ``generate --density`` sets only the masses.
"""

from __future__ import annotations

import argparse
import sys

from rigidfold.cli_parser import add_options, options_of
from rigidfold.config import DEFAULTS
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.structure import StructureOptions, presets_help

STRUCTURE = StructureOptions()
"""The structure check's defaults (``Settings.structure``)."""


def length(what: str):
    """argparse type: a length in metres, or with a unit (``18mm``)."""

    def parse(text: str) -> float:
        from rigidfold.fabricate.build import parse_length

        try:
            return parse_length(text, what)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    return parse


def fabricate_arguments(p: argparse.ArgumentParser, *, generate: bool) -> None:
    """The thick panels' options (:class:`~rigidfold.fabricate.FabricateOptions`) on ``p``,
    made from its fields (:func:`~rigidfold.cli_parser.add_options`): ``rigidfold
    fabricate``'s, where ``--thickness`` is required, or ``generate``'s, where its own
    ``--thickness`` asks for the final design's thick panels and the others, their help
    prefixed "with --thickness: ", apply to them."""
    if generate:
        p.add_argument(
            "--thickness",
            type=length("thickness"),
            default=None,
            metavar="T",
            help="make the final design's thick panels of this thickness (metres, or 18mm, "
            "1.8cm) as rigidfold fabricate does, from the motion the run traced: "
            "DIR/final/thick/; the run falls short when they collide over the deployment or "
            "are trimmed away. Also the panels' thickness of --structure and of Step 9's "
            "frame with --material (default: no thick panels; --structure and --material "
            f"alone: {STRUCTURE.thickness:g})",
        )
        add_options(
            p,
            FabricateOptions,
            exclude=("thickness",),
            prefix="with --thickness: ",
            shown={
                "density": f"that of --material, or of {STRUCTURE.material}; it does not "
                "change the structure's self-weight"
            },
        )
    else:
        add_options(p, FabricateOptions)


def structure_arguments(p: argparse.ArgumentParser, *, generate: bool) -> None:
    """The structure check's options (:class:`~rigidfold.structure.StructureOptions`) on
    ``p``: ``rigidfold structure``'s, or ``generate``'s, where ``--structure`` asks for the
    check of the final design, ``--material`` is also Step 9's and the thick panels', and
    the thickness is ``--thickness`` (:func:`fabricate_arguments`)."""
    pre = "--structure: " if generate else ""
    if generate:
        p.add_argument(
            "--structure",
            action="store_true",
            help="check the final design as a structure as rigidfold structure does "
            "(supports, self-weight and --load in OpenSees, the deflection limit): "
            "DIR/final/structure/; the run falls short when the check fails",
        )
    else:
        p.add_argument(
            "--thickness",
            type=length("thickness"),
            default=None,
            metavar="T",
            help="panel thickness in metres, or with a unit: 18mm, 1.8cm (default: the "
            "thickness rigidfold fabricate made this design's panels, read from "
            "NAME_fabricate.json beside the design or, for a run's solutions/NAME.fold, in the "
            f"run's final/thick/; else {STRUCTURE.thickness:g}; structure.json's "
            "thickness_from says which)",
        )
    material = (
        f"the panels' material: a preset ({presets_help()}) or E,nu,density in SI units (Pa, "
        "-, kg/m^3), e.g. 10e9,0.3,700"
    )
    p.add_argument(
        "--material",
        default=None if generate else STRUCTURE.material,
        metavar="NAME|E,nu,density",
        help=material
        + (
            "; Step 9's frame is then of strips of these panels (of --thickness, or "
            f"{STRUCTURE.thickness * 1e3:g} mm), and --structure and the thick panels' "
            f"masses use it (default: the paper's steel tubes for Step 9, {STRUCTURE.material} "
            "for the others)"
            if generate
            else " (default: %(default)s)"
        ),
    )
    p.add_argument(
        "--supports",
        default=STRUCTURE.supports.text,
        metavar="V,V,...|auto|service",
        help=f"{pre}pinned vertices (indices of the design's vertices); auto: the fewest "
        "--support-candidates that make the mechanism first-order rigid, of the largest "
        "smallest stiffness eigenvalue; service: those, then one more at a time where the "
        "design deflects most until the deflection limit is met (a linear analysis each; "
        "added pins that are not needed are taken away again). A boundary edge whose ends "
        "are both supported is supported along its length (default: %(default)s)",
    )
    p.add_argument(
        "--support-candidates",
        default=STRUCTURE.candidates,
        metavar="boundary|ground|V,V,...",
        help=f"{pre}the vertices auto may choose: every boundary vertex, the boundary "
        f"vertices at the lowest height (within {DEFAULTS.structure.ground_tol:g} m), or a "
        "list (default: boundary)",
    )
    p.add_argument(
        "--clamped",
        default=STRUCTURE.clamped,
        metavar="V,V,...",
        help=f"{pre}clamped vertices: translations and the rotations of the panels there "
        "held (default: none)",
    )
    p.add_argument(
        "--actuators",
        default=STRUCTURE.actuators,
        metavar="I,J,...",
        help=f"{pre}free creases (indices into the design's edges_vertices) held at their "
        "angle by actuators: supports of a hinge (default: none)",
    )
    p.add_argument(
        "--hinge-stiffness",
        type=float,
        default=STRUCTURE.hinge_stiffness,
        metavar="K",
        help=f"{pre}rotational stiffness of every free crease, N m/rad per metre of crease "
        "(default: %(default)s, a free hinge)",
    )
    p.add_argument(
        "--load",
        action="append",
        default=None,
        metavar="KIND=VALUE",
        help=f"{pre}a load besides self-weight, repeatable: uniform=Q (per m^2 of plan, "
        "downwards: snow), pressure=Q (normal to the panels, positive pressing on the upper "
        "face: wind), point=V:FX,FY,FZ (a force at vertex V). Q in Pa, kPa, kN/m2 or MPa "
        "(uniform=0.5kPa, 500Pa), a bare number in kPa; forces in N, kN or MN "
        "(point=12:0,0,-2kN), a bare number in newtons",
    )
    p.add_argument(
        "--no-self-weight",
        action="store_true",
        help=f"{pre}leave out the panels' weight (density x g x thickness)",
    )
    p.add_argument(
        "--limit",
        default=STRUCTURE.limit.text,
        metavar="L/N",
        help=f"{pre}serviceability: the largest displacement may be at most the span over N; "
        "the span is the largest plan distance between supports (twice the reach of a "
        "cantilever) (default: %(default)s)",
    )
    p.add_argument(
        "--nonlinear",
        action="store_true",
        help=f"{pre}geometrically nonlinear analysis (corotational shells, "
        f"{DEFAULTS.structure.steps} load steps) instead of a linear one",
    )
    p.add_argument(
        "--modes",
        type=int,
        default=STRUCTURE.modes,
        metavar="N",
        help=f"{pre}natural frequencies to compute, 0 for none (default: %(default)s)",
    )


def fabricate_options(args: argparse.Namespace) -> FabricateOptions | None:
    """The thick panels' options of the parsed arguments (checked); None without
    ``--thickness`` (generate)."""
    return None if args.thickness is None else options_of(FabricateOptions, args)


def structure_progress(line: str) -> None:
    """``rigidfold structure``'s progress: each long step of the check on a line of stderr."""
    print(f"rigidfold structure: {line}", file=sys.stderr, flush=True)


def structure_options(args: argparse.Namespace) -> StructureOptions:
    """The structure check's options of the parsed arguments (checked); generate's
    ``--thickness`` and ``--material`` where not given: the check's defaults.
    ``rigidfold structure FILE`` without ``--thickness``: the thickness fabricate recorded
    for the design (:func:`~rigidfold.structure.design.recorded_thickness`, said on stderr
    and as ``thickness_from``), else the default."""
    from rigidfold.structure.design import recorded_thickness

    thickness, source = args.thickness, ""
    design = getattr(args, "file", None)
    if thickness is None and design is not None:
        found = recorded_thickness(design)
        if found is not None:
            thickness, where = found
            source = f"rigidfold fabricate ({where})"
            structure_progress(
                f"the panels are {thickness * 1e3:g} mm thick, as fabricate made them "
                f"({where}); --thickness to check another"
            )
        else:
            source = "default (Settings.structure.thickness)"
    return StructureOptions.from_strings(
        thickness=STRUCTURE.thickness if thickness is None else thickness,
        thickness_from=source,
        material=STRUCTURE.material if args.material is None else args.material,
        supports=args.supports,
        candidates=args.support_candidates,
        clamped=args.clamped,
        actuators=args.actuators,
        hinge_stiffness=args.hinge_stiffness,
        loads=tuple(args.load or ()),
        self_weight=not args.no_self_weight,
        limit=args.limit,
        nonlinear=args.nonlinear,
        modes=args.modes,
    )
