"""Problem (6): form finding of a developable polyhedron near a target surface."""

from rigidfold.optimize.problem import SOLVERS, FormFindingProblem, classify
from rigidfold.optimize.result import OptimizeResult, Status
from rigidfold.optimize.variables import LinearMap, assemble_constraints, build_linear_map

__all__ = [
    "SOLVERS",
    "FormFindingProblem",
    "LinearMap",
    "OptimizeResult",
    "Status",
    "assemble_constraints",
    "build_linear_map",
    "classify",
]
