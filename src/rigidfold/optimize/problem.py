"""Problem (6) for one crease pattern, target surface, symmetry and settings, and its solvers.

The NLP (``rigidfold.optimize.nlp``) is built once per problem; the solvers are objects
(``rigidfold.optimize.solver``) built from it on first use, named in ``SOLVER_FACTORIES``, and
kept on the problem, so IPOPT is set up once however many solves follow.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Mapping, Sequence
from enum import StrEnum
from functools import partial
from types import MappingProxyType

import casadi as ca
import numpy as np

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.errors import RigidfoldError
from rigidfold.mesh import CreasePattern
from rigidfold.optimize.large import ipopt_solver
from rigidfold.optimize.nlp import NLP, build_nlp
from rigidfold.optimize.projection import Projection
from rigidfold.optimize.result import OptimizeResult, Status
from rigidfold.optimize.slsqp import SlsqpSolver
from rigidfold.optimize.solver import Solver, SolverOutcome, SolverProblem
from rigidfold.optimize.variables import LinearMap, build_linear_map
from rigidfold.protocols import SymmetryPlane, TargetSurface


class SolverName(StrEnum):
    """A solver of problem (6) (``--solver``): IPOPT with the exact Hessian, SLSQP with the
    exact Jacobian or with finite differences. A ``str``: files hold the plain value."""

    IPOPT = "ipopt"
    SLSQP = "slsqp"
    SLSQP_FD = "slsqp-fd"


#: name -> solver factory ``(problem) -> Solver``; the one list of solvers
SOLVER_FACTORIES: Mapping[SolverName, Callable[[SolverProblem], Solver]] = MappingProxyType(
    {
        SolverName.IPOPT: ipopt_solver,
        SolverName.SLSQP: partial(SlsqpSolver, exact=True),
        SolverName.SLSQP_FD: partial(SlsqpSolver, exact=False),
    }
)
SOLVERS = tuple(s.value for s in SOLVER_FACTORIES)
"""The solvers' names, the default first (``--solver``'s choices)."""


class FormFindingProblem:
    """Problem (6) for one crease pattern, target surface, symmetry and settings.

    A ``SolverProblem``: the solvers of ``SOLVER_FACTORIES`` are built from it.

    Parameters
    ----------
    pattern : CreasePattern
        The initial shape (Step 1); its plan boundary sides and corners define (7) and (8).
    surface : TargetSurface (e.g. a rigidfold.surfaces.Surface)
        Target surface z = f(x, y); its ``height`` must accept CasADi symbols (``xp=casadi``).
    planes : sequence of SymmetryPlane
        Vertical planes of symmetry (9); each has ``a, b, c`` and ``reflect``.
    settings : Settings
        Design parameters (dz, theta bounds, rho_max, F_tol) and tolerances.
    build_ipopt : bool
        Build the IPOPT solver (exact Hessian of the Lagrangian) now, so that ``build_time``
        covers it; otherwise it is built on the first IPOPT solve.
    project_first : bool
        The IPOPT solver begins every solve with the projection onto F = 0 from the start
        (:mod:`rigidfold.optimize.large`) whatever the pattern's size; False: only from
        ``settings.solver.projection_vertices`` vertices on (IPOPT alone below, the paper's).

    Attributes
    ----------
    map : LinearMap
        The elimination (7)-(11), ``P = T xi + t``.
    nlp : NLP
        Problem (6) as CasADi symbols, expressions and bounds.
    objective : ca.Function (xi, w) -> (F, F1, F2)
    objective_gradient : ca.Function (xi, w) -> (F, dF (n,))
    constraints : ca.Function (xi, w) -> g (m,)
    constraint_jacobian : ca.Function (xi, w) -> (g (m,), dg (m, n))
        CasADi's symbolic derivatives, each built on first use (IPOPT on paper-size
        patterns, SLSQP; large patterns give IPOPT ``rigidfold.optimize.jacobian``'s).
    build_time : float
        Seconds spent building the model (and IPOPT with ``build_ipopt``).
    """

    def __init__(
        self,
        pattern: CreasePattern,
        surface: TargetSurface,
        *,
        planes: Sequence[SymmetryPlane] = (),
        settings: Settings = DEFAULTS,
        build_ipopt: bool = True,
        project_first: bool = False,
    ) -> None:
        t0 = time.perf_counter()
        self.project_first = project_first
        self.pattern = pattern
        self.surface = surface
        self.planes: tuple[SymmetryPlane, ...] = tuple(planes)
        self.settings = settings
        self.map: LinearMap = build_linear_map(pattern, self.planes, settings)
        self.nlp: NLP = build_nlp(pattern, surface, self.map, settings)
        nlp = self.nlp
        xi, w, names = nlp.x, nlp.p, ["xi", "w"]
        self.objective = ca.Function(
            "F", [xi, w], [nlp.f, nlp.f1, nlp.f2], names, ["F", "F1", "F2"]
        )
        self._solvers: dict[SolverName, Solver] = {}
        self._projection: Projection | None = None
        if build_ipopt:
            self.solver(SolverName.IPOPT)
        self.build_time = time.perf_counter() - t0

    @functools.cached_property
    def objective_gradient(self) -> ca.Function:
        nlp = self.nlp
        return ca.Function(
            "dF", [nlp.x, nlp.p], [nlp.f, ca.gradient(nlp.f, nlp.x)], ["xi", "w"], ["F", "dF"]
        )

    @functools.cached_property
    def constraint_jacobian(self) -> ca.Function:
        nlp = self.nlp
        return ca.Function(
            "dg", [nlp.x, nlp.p], [nlp.g, ca.jacobian(nlp.g, nlp.x)], ["xi", "w"], ["g", "dg"]
        )

    @functools.cached_property
    def constraints(self) -> ca.Function:
        return ca.Function("g", [self.nlp.x, self.nlp.p], [self.nlp.g], ["xi", "w"], ["g"])

    def derivative_functions(self) -> dict[str, ca.Function]:
        """Exact derivatives of each part of (6), for checks and for callers that need them.

        Keys: "F1", "F2" -> Function(xi, w) -> (value, gradient (n,), Hessian (n, n));
        "theta" -> Function(xi, lam) -> (angles (3F,), Jacobian (3F, n), Hessian of lam . theta).
        """
        xi, w, theta = self.nlp.x, self.nlp.p, self.nlp.theta
        out = {}
        for name, expr in (("F1", self.nlp.f1), ("F2", self.nlp.f2)):
            hess, grad = ca.hessian(expr, xi)
            out[name] = ca.Function(f"d{name}", [xi, w], [expr, grad, hess])
        lam = ca.SX.sym("lam", theta.shape[0])
        hess, _ = ca.hessian(ca.dot(lam, theta), xi)
        out["theta"] = ca.Function("dtheta", [xi, lam], [theta, ca.jacobian(theta, xi), hess])
        return out

    @property
    def n_variables(self) -> int:
        return self.map.n_variables

    # ------------------------------------------------------------------ helpers
    def fixed_mask(self, fixed=None) -> np.ndarray:
        """Normalise a fixed-crease selection to an (E,) bool mask.

        fixed : None (the pattern's own mask), an (E,) bool mask, or crease indices.
        """
        E = self.pattern.n_edges
        if fixed is None:
            return self.pattern.fixed.copy()
        arr = np.asarray(fixed)
        if arr.dtype == bool:
            if arr.shape != (E,):
                raise RigidfoldError(f"fixed mask must have shape ({E},), got {arr.shape}")
            mask = arr.copy()
        else:
            idx = arr.astype(np.int64).ravel()
            bad = idx[(idx < 0) | (idx >= E)]
            if len(bad):
                raise RigidfoldError(f"fixed crease index {int(bad[0])} out of range 0..{E - 1}")
            mask = np.zeros(E, dtype=bool)
            mask[idx] = True
        on_boundary = mask & self.pattern.is_boundary_edge
        if on_boundary.any():
            e = int(np.flatnonzero(on_boundary)[0])
            raise RigidfoldError(f"edge {e} is a boundary edge and cannot be fixed")
        return mask

    def start_point(self, coords: np.ndarray | None = None) -> np.ndarray:
        """Independent variables (n,) of a starting shape (default: the initial pattern)."""
        return self.map.restrict(self.pattern.coords if coords is None else coords)

    def violation(self, coords: np.ndarray, fixed: np.ndarray) -> float:
        """Largest violation of any constraint of (6) at a shape, evaluated with NumPy."""
        s = self.settings
        shape = self.pattern.with_coords(coords)
        dz = coords[:, 2] - np.asarray(self.surface.height(coords[:, 0], coords[:, 1]))
        theta = shape.corner_angles.T.ravel()  # the order of g's rows
        lo, hi = self.nlp.theta_bounds
        parts = [
            np.abs(dz[self.nlp.dz_vertices]).max(initial=0.0) - s.design.dz,
            float((lo - theta).max(initial=-np.inf)),
            float((theta - hi).max(initial=-np.inf)),
            self.map.residual(coords),
        ]
        if s.design.rho_max is not None:
            free = ~fixed & ~shape.is_boundary_edge
            parts.append(np.abs(shape.fold_angles[free]).max(initial=0.0) - s.design.rho_max)
        return max(0.0, *parts)

    # ------------------------------------------------------------------ solve
    def solver(self, name: SolverName) -> Solver:
        """The solver ``name`` (one of ``SOLVERS``) of this problem, built on first use and kept."""
        if name not in SOLVER_FACTORIES:
            raise RigidfoldError(f"unknown solver {name!r} (choose from {', '.join(SOLVERS)})")
        if name not in self._solvers:
            self._solvers[name] = SOLVER_FACTORIES[name](self)
        return self._solvers[name]

    def solve(
        self,
        fixed=None,
        start: np.ndarray | None = None,
        solver: SolverName = SolverName.IPOPT,
        deadline: float | None = None,
        max_iter: int | None = None,
        stall: int | None = None,
    ) -> OptimizeResult:
        """Solve (6) from ``start`` coordinates (V, 3) with the creases ``fixed`` fixed.

        ``solver`` is a :class:`SolverName`; the result's ``wall_time`` is that of the solve alone.
        ``deadline``: a time of ``time.monotonic()`` (a run's time limit) at which the solve
        ends at its iterate (judged as any other: accepted only at F <= F_tol); so does
        ``max_iter``, the solver's iterations (None: its limit of the settings), and
        ``stall``: where the least feasible F has not halved in that many iterations above F_tol
        (None: never; ``Status.STALLED``).
        A solver that ends where a triangle has collapsed (or at non-finite coordinates) has
        failed: the result is the start, Status.FAILED, its message saying why.
        """
        backend = self.solver(solver)
        mask = self.fixed_mask(fixed)
        xi0 = self.start_point(start)
        w = mask.astype(float)
        t0 = time.perf_counter()
        with one_blas_thread():  # which zero of F is reached depends on round-off
            run = backend.solve(xi0, w, deadline, max_iter, stall)
        wall = time.perf_counter() - t0
        xi = run.xi
        coords = self.map.expand(xi)
        try:
            viol = self.violation(coords, mask)
            status, verdict = None, ""
        except ValueError as exc:  # the solver's point is no shape: keep the start
            xi, coords = xi0, self.map.expand(xi0)
            viol = self.violation(coords, mask)
            status, verdict = Status.FAILED, f"its point is no shape ({exc}): the start is kept"
        F, F1, F2 = (float(v) for v in self.objective(xi, w))
        # the solver's shape is a state of the pattern, which may fold past vertical
        shape = CreasePattern(
            coords, self.pattern.faces, self.pattern.edges, mask, self.pattern.settings, sheet=False
        )
        if status is None:
            status, verdict = classify(run.outcome, F, viol, self.settings, folded_back(shape))
        return OptimizeResult(
            pattern=shape,
            F=F,
            F1=F1,
            F2=F2,
            max_violation=viol,
            status=status,
            message=f"{run.message}; {verdict}",
            iterations=run.iterations,
            wall_time=wall,
            solver=solver,
            n_variables=self.n_variables,
        )

    # ------------------------------------------------------------------ polish
    def polish(self, result: OptimizeResult, deadline: float | None = None) -> OptimizeResult:
        """An accepted ``result`` projected onto F = 0 to ``Settings.solver.polish_tol``
        (:class:`rigidfold.optimize.projection.Projection`, every constraint of (6) kept).

        F_tol (1e-7) leaves angle defects of up to about 3e-4 rad, and a shape that is not
        developable to round-off cannot reach the flat state along a rigid-folding path: the
        path passes the flat state at a distance of about the square root of the defects. The
        projection moves the vertices by about that defect times the edge length. Returns
        ``result`` itself when it was not accepted, or the projection does not lower F or
        meets a singular factor. ``deadline`` (of ``time.monotonic()``): the projection
        stops there, with what it reached.
        """
        if result.status is not Status.CONVERGED:
            return result
        if self._projection is None:
            self._projection = Projection(self)
        w = result.pattern.fixed.astype(float)
        t0 = time.perf_counter()
        try:
            with one_blas_thread():
                run = self._projection(
                    self.start_point(result.coords),
                    w,
                    tol=self.settings.solver.polish_tol,
                    deadline=deadline,
                    stall=self.settings.solver.polish_stall_steps,
                )
        except RuntimeError:  # a singular factor (redundant rows at F ~ 0): keep the result
            return result
        if not run.feasible or not run.F < result.F:
            return result
        coords = self.map.expand(run.xi)
        F, F1, F2 = (float(v) for v in self.objective(run.xi, w))
        viol = self.violation(coords, result.pattern.fixed)
        shape = result.pattern.with_coords(coords)
        status, _ = classify(SolverOutcome.SOLVED, F, viol, self.settings, folded_back(shape))
        if status is not Status.CONVERGED:
            return result
        return dataclasses.replace(
            result,
            pattern=shape,
            F=F,
            F1=F1,
            F2=F2,
            max_violation=viol,
            message=f"{result.message}; polished ({run.reason})",
            wall_time=result.wall_time + time.perf_counter() - t0,
        )


def folded_back(shape: CreasePattern) -> np.ndarray:
    """(k,) int: the fixed creases of ``shape`` whose fold angle is above 90 degrees in
    magnitude. Problem (6) makes a fixed crease's facets one flat panel through the term
    |n_a x n_b|^2 = sin^2(rho), whose zero nearest such an angle is 180 degrees: the facets
    folded onto each other, not a panel."""
    creases = shape.fixed_creases
    return creases[np.abs(shape.fold_angles[creases]) > np.pi / 2]


def classify(
    outcome: SolverOutcome,
    F: float,
    violation: float,
    settings: Settings,
    folded: np.ndarray | None = None,
) -> tuple[Status, str]:
    """rigidfold's verdict on a solver run.

    outcome : the solver's own flag (a ``SolverOutcome``, or its value).
    folded : (k,) int, the fixed creases folded back (:func:`folded_back`), if any.
    A point with F <= F_tol that meets every constraint is accepted whatever the solver said,
    unless a fixed crease is folded back (``Status.FOLDED_BACK``).
    """
    feasible = violation <= settings.solver.constraint_tol
    if feasible and F <= settings.design.f_tol:
        if folded is not None and len(folded):
            return Status.FOLDED_BACK, (
                f"F = {F:.3g} <= F_tol, but fixed crease{'s' if len(folded) > 1 else ''} "
                f"{', '.join(str(int(c)) for c in folded)} folded back onto "
                f"{'their' if len(folded) > 1 else 'its'} facets (near 180 degrees)"
            )
        return Status.CONVERGED, f"accepted: F = {F:.3g} <= F_tol = {settings.design.f_tol:.3g}"
    if outcome == SolverOutcome.INFEASIBLE or (outcome == SolverOutcome.SOLVED and not feasible):
        return Status.INFEASIBLE, f"constraint violation {violation:.3g}"
    if outcome == SolverOutcome.ITERATION_LIMIT:
        return Status.ITERATION_LIMIT, f"stopped at F = {F:.3g}"
    if outcome == SolverOutcome.STALLED:
        return Status.STALLED, f"F stalled at {F:.3g} > F_tol = {settings.design.f_tol:.3g}"
    if outcome == SolverOutcome.SOLVED:
        return Status.TOLERANCE_NOT_MET, f"F = {F:.3g} > F_tol = {settings.design.f_tol:.3g}"
    return Status.FAILED, f"F = {F:.3g}, constraint violation {violation:.3g}"
