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

from rigidfold.cli.parser import add_options, argument_type, options_of
from rigidfold.cli.structure_specs import read_structure_options
from rigidfold.cli.units import parse_length, parse_material
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.flags import docs
from rigidfold.structure import StructureOptions

STRUCTURE = StructureOptions()
"""The structure check's defaults (``Settings.structure``)."""

TEXT_DEFAULTS = {"clamped": "", "actuators": ""}
"""The defaults of the structure's flags that are lists of indices, as the command line's
texts (:func:`~rigidfold.cli.structure_specs.read_structure_options` reads them)."""


def length(what: str):
    """argparse type: a length in metres, or with a unit (``18mm``)."""
    return argument_type(lambda text: parse_length(text, what))


def fabricate_arguments(p: argparse.ArgumentParser, *, generate: bool) -> None:
    """The thick panels' options (:class:`~rigidfold.fabricate.FabricateOptions`) on ``p``,
    made from its fields (:func:`~rigidfold.cli.parser.add_options`): ``rigidfold
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
                "density": f"that of --material, or of {STRUCTURE.material.key}; it does not "
                "change the structure's self-weight"
            },
        )
    else:
        add_options(p, FabricateOptions)


def structure_arguments(p: argparse.ArgumentParser, *, generate: bool) -> None:
    """The structure check's options (:class:`~rigidfold.structure.StructureOptions`) on
    ``p``, made from its fields (:func:`~rigidfold.cli.parser.add_options`): ``rigidfold
    structure``'s, where ``--thickness`` left out is the thickness fabricate recorded
    (:func:`structure_options`), or ``generate``'s, their help prefixed "--structure: ",
    where ``--structure`` asks for the check of the final design, ``--material`` is also
    Step 9's and the thick panels', and the thickness is ``--thickness``
    (:func:`fabricate_arguments`)."""
    if not generate:
        # the thickness first, as the record's first field: a length the command line reads
        p.add_argument(
            "--thickness",
            type=length("thickness"),
            default=None,
            metavar="T",
            help=docs(StructureOptions)["thickness"] + " (default: the thickness rigidfold "
            "fabricate made this design's panels, read from NAME_fabricate.json beside the "
            "design or, for a run's solutions/NAME.fold, in the run's final/thick/; else "
            f"{STRUCTURE.thickness:g}; structure.json's thickness_from says which)",
        )
        add_options(p, StructureOptions, exclude=("thickness",), defaults=TEXT_DEFAULTS)
        return
    p.add_argument(
        "--structure",
        action="store_true",
        help="check the final design as a structure as rigidfold structure does "
        "(supports, self-weight and --load in OpenSees, the deflection limit): "
        "DIR/final/structure/; the run falls short when the check fails",
    )
    p.add_argument(
        "--material",
        type=argument_type(parse_material),
        default=None,
        metavar="NAME|E,nu,density",
        help=docs(StructureOptions)["material"] + "; Step 9's frame is then of strips of these "
        f"panels (of --thickness, or {STRUCTURE.thickness * 1e3:g} mm), and --structure and "
        "the thick panels' masses use it (default: the paper's steel tubes for Step 9, "
        f"{STRUCTURE.material.key} for the others)",
    )
    add_options(
        p,
        StructureOptions,
        exclude=("thickness", "material"),
        prefix="--structure: ",
        defaults=TEXT_DEFAULTS,
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
    for the design (:func:`~rigidfold.fabricate.files.recorded_thickness`, said on stderr
    and as ``thickness_from``), else the default."""
    from rigidfold.fabricate.files import recorded_thickness
    from rigidfold.pipeline.built import thick_dir_of

    thickness, source = args.thickness, ""
    design = getattr(args, "file", None)
    if thickness is None and design is not None:
        run = thick_dir_of(design)
        found = recorded_thickness(design, () if run is None else (run,))
        if found is not None:
            thickness, where = found
            source = f"rigidfold fabricate ({where})"
            structure_progress(
                f"the panels are {thickness * 1e3:g} mm thick, as fabricate made them "
                f"({where}); --thickness to check another"
            )
        else:
            source = "default (Settings.structure.thickness)"
    return options_of(
        StructureOptions,
        args,
        make=read_structure_options,
        thickness=STRUCTURE.thickness if thickness is None else thickness,
        thickness_from=source,
        material=args.material,
    )
