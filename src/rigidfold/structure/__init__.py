"""The deployed structure: supports that stabilise the mechanism, and its panels and hinges
under load in OpenSees (``rigidfold structure``).

:mod:`~rigidfold.material` (the panels' material, presets),
:mod:`~rigidfold.structure.supports` (first-order rigidity of a design on its supports, and
the fewest supports that give it), :mod:`~rigidfold.mechanism.second_order` (second order where
first order is not enough: prestress stability, or a finite mechanism),
:mod:`~rigidfold.structure.model` (the shell model: panels as plates, free creases as
hinges), :mod:`~rigidfold.structure.loads` (self-weight, snow, wind, point loads),
:mod:`~rigidfold.structure.analysis` (static and eigen analysis in OpenSees),
:mod:`~rigidfold.structure.check` (the check and its verdict),
:mod:`~rigidfold.structure.choices` (the typed supports and indices of the options),
:mod:`~rigidfold.structure.design` (the options, :class:`StructureOptions`, the check
from them, and its files) and
:mod:`~rigidfold.structure.figure` (the deflected shape). OpenSees and matplotlib are
imported only when an analysis runs or a figure is drawn.
"""

from rigidfold.material import MATERIALS, Material, presets_help
from rigidfold.mechanism.second_order import SecondOrder, Stability, second_order
from rigidfold.structure.check import (
    StructureCheck,
    StructureStatus,
    check_inputs,
    check_limit,
    check_structure,
)
from rigidfold.structure.choices import Auto, Candidates, Pins, Service, SupportSpec
from rigidfold.structure.design import (
    STRUCTURE_FILES,
    StructureOptions,
    check_design,
    design_supports,
    write_structure,
)
from rigidfold.structure.loads import (
    LOAD_KINDS,
    Load,
    Point,
    Pressure,
    SelfWeight,
    Uniform,
)
from rigidfold.structure.supports import (
    CANDIDATE_FORMS,
    Rigidity,
    SupportModes,
    Supports,
    auto_supports,
    check_supports,
    index_array,
    support_candidates,
)

__all__ = [
    "CANDIDATE_FORMS",
    "LOAD_KINDS",
    "MATERIALS",
    "STRUCTURE_FILES",
    "Auto",
    "Candidates",
    "Load",
    "Material",
    "Pins",
    "Point",
    "Pressure",
    "Rigidity",
    "SecondOrder",
    "SelfWeight",
    "Service",
    "Stability",
    "StructureCheck",
    "StructureOptions",
    "StructureStatus",
    "SupportModes",
    "SupportSpec",
    "Supports",
    "Uniform",
    "auto_supports",
    "check_design",
    "check_inputs",
    "check_limit",
    "check_structure",
    "check_supports",
    "design_supports",
    "index_array",
    "presets_help",
    "second_order",
    "support_candidates",
    "write_structure",
]
