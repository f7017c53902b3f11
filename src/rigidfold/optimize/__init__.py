"""Problem (6): form finding of a developable polyhedron near a target surface."""

from rigidfold.optimize.ipopt import IpoptSolver
from rigidfold.optimize.nlp import NLP
from rigidfold.optimize.problem import (
    SOLVER_FACTORIES,
    SOLVERS,
    FormFindingProblem,
    SolverName,
    classify,
)
from rigidfold.optimize.result import OptimizeResult, Status
from rigidfold.optimize.slsqp import SlsqpSolver
from rigidfold.optimize.solver import Solver, SolverOutcome, SolverRun
from rigidfold.optimize.variables import LinearMap, assemble_constraints, build_linear_map

__all__ = [
    "NLP",
    "SOLVERS",
    "SOLVER_FACTORIES",
    "FormFindingProblem",
    "IpoptSolver",
    "LinearMap",
    "OptimizeResult",
    "SlsqpSolver",
    "Solver",
    "SolverName",
    "SolverOutcome",
    "SolverRun",
    "Status",
    "assemble_constraints",
    "build_linear_map",
    "classify",
]
