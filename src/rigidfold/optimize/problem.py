"""Problem (6): developability (F1) and flatness (F2) with exact derivatives from CasADi.

::

    min_xi   F = F1 + F2
    F1 = sum_{i in V_in} (2 pi - sum_k theta_ik)^2
    F2 = sum_{j in E_fix} |n_j1 x n_j2|^2
    s.t.     |z_i - f(x_i, y_i)| <= dz                  (every vertex that can move)
             theta_min <= theta_ik <= theta_max          (every sector angle)
             |rho_j| <= rho_bar                          (free creases, optional, Eq. 12)
             P = T xi + t                                (Eqs. 7-11, eliminated)

The model is built once per pattern, surface, symmetry and settings as CasADi SX
expressions; the fixed-crease mask is a *parameter* ``w`` (E,), so fixing another crease
needs no rebuild. Angles are ``atan2(|a x b|, a . b)``. Constraint (12) is imposed in the
equivalent smooth form ``n_j1 . n_j2 >= cos(rho_bar)``.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import casadi as ca
import numpy as np
import scipy.sparse as sp

from rigidfold.config import DEFAULTS, Settings, one_blas_thread
from rigidfold.mesh import CreasePattern
from rigidfold.optimize.result import OptimizeResult, Status
from rigidfold.optimize.variables import LinearMap, build_linear_map

SOLVERS = ("ipopt", "slsqp", "slsqp-fd")


def to_casadi(matrix: sp.spmatrix) -> ca.DM:
    """A SciPy sparse matrix as a sparse CasADi DM."""
    csc = sp.csc_matrix(matrix)
    csc.sort_indices()
    sparsity = ca.Sparsity(csc.shape[0], csc.shape[1], csc.indptr.tolist(), csc.indices.tolist())
    return ca.DM(sparsity, csc.data)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


class FormFindingProblem:
    """Problem (6) for one crease pattern, target surface, symmetry and settings.

    Parameters
    ----------
    pattern : CreasePattern
        The initial shape (Step 1); its plan boundary sides and corners define (7) and (8).
    surface : rigidfold.surfaces.Surface
        Target surface z = f(x, y); its ``height`` must accept CasADi symbols (``xp=casadi``).
    planes : sequence of mirror planes
        Vertical planes of symmetry (9); each has ``a, b, c`` and ``reflect``.
    settings : Settings
        Design parameters (dz, theta bounds, rho_bar, F_tol) and tolerances.
    build_ipopt : bool
        Build IPOPT's NLP (exact Hessian of the Lagrangian) now, so that ``build_time`` covers
        it; otherwise it is built on the first IPOPT solve.
    """

    def __init__(
        self,
        pattern: CreasePattern,
        surface,
        *,
        planes: Sequence = (),
        settings: Settings = DEFAULTS,
        build_ipopt: bool = True,
    ) -> None:
        t0 = time.perf_counter()
        self.pattern = pattern
        self.surface = surface
        self.planes = tuple(planes)
        self.settings = settings
        self.map: LinearMap = build_linear_map(pattern, self.planes, settings)
        self._build_model()
        self._ipopt = self._hess_lag = None
        if build_ipopt:
            from rigidfold.optimize.ipopt import ipopt_solver

            ipopt_solver(self)
        self.build_time = time.perf_counter() - t0

    # ------------------------------------------------------------------ model
    def _build_model(self) -> None:
        pat, s = self.pattern, self.settings
        V, E = pat.n_vertices, pat.n_edges
        faces, ef = pat.faces, pat.edge_faces
        interior = pat.interior_edges
        xi = ca.SX.sym("xi", self.map.n_variables)
        w = ca.SX.sym("w", E)
        P = ca.mtimes(to_casadi(self.map.T), xi) + ca.DM(self.map.t)
        x, y, z = P[:V], P[V : 2 * V], P[2 * V :]

        def at(idx: np.ndarray):
            i = idx.tolist()
            return (x[i], y[i], z[i])

        corners = [at(faces[:, k]) for k in range(3)]
        angles = []
        for k in range(3):
            u = _sub(corners[(k + 1) % 3], corners[k])
            v = _sub(corners[(k + 2) % 3], corners[k])
            c = _cross(u, v)
            angles.append(ca.atan2(ca.sqrt(_dot(c, c)), _dot(u, v)))
        theta = ca.vertcat(*angles)  # (3F,), entry k*F + f is the angle at faces[f, k]

        inner = pat.interior_vertices
        row_of = np.full(V, -1)
        row_of[inner] = np.arange(len(inner))
        vert = faces.T.ravel()  # vertex of angle k*F + f
        keep = row_of[vert] >= 0
        A = sp.coo_matrix(
            (np.ones(keep.sum()), (row_of[vert[keep]], np.flatnonzero(keep))),
            shape=(len(inner), 3 * len(faces)),
        )
        defect = 2 * np.pi - ca.mtimes(to_casadi(A), theta)
        F1 = ca.sumsqr(defect)

        nrm = _cross(_sub(corners[1], corners[0]), _sub(corners[2], corners[0]))
        length = ca.sqrt(_dot(nrm, nrm))
        unit = tuple(c / length for c in nrm)
        ia, ib = ef[interior, 0].tolist(), ef[interior, 1].tolist()
        na = tuple(c[ia] for c in unit)
        nb = tuple(c[ib] for c in unit)
        cr = _cross(na, nb)
        flat = _dot(cr, cr)  # |n_a x n_b|^2 per interior edge
        w_int = w[interior.tolist()]
        F2 = ca.dot(w_int, flat)
        F = F1 + F2

        # dz constraint on every vertex that is not completely fixed by (7)-(9)
        T = self.map.T.tocsr()
        moves = np.diff(T.indptr).reshape(3, V).sum(axis=0) > 0
        self._dz_vertices = np.flatnonzero(moves)
        mv = self._dz_vertices.tolist()
        height = self.surface.height(x[mv], y[mv], xp=ca)
        g = [z[mv] - height, theta]
        lbg = [np.full(len(mv), -s.dz), np.full(theta.shape[0], s.theta_min)]
        ubg = [np.full(len(mv), s.dz), np.full(theta.shape[0], s.theta_max)]
        if s.rho_bar is not None:
            g.append((1 - w_int) * (np.cos(s.rho_bar) - _dot(na, nb)))
            lbg.append(np.full(len(interior), -np.inf))
            ubg.append(np.zeros(len(interior)))

        self._xi, self._w = xi, w
        self._F, self._g = F, ca.vertcat(*g)
        self.lbg, self.ubg = np.concatenate(lbg), np.concatenate(ubg)
        self.objective = ca.Function("F", [xi, w], [F, F1, F2], ["xi", "w"], ["F", "F1", "F2"])
        self.constraints = ca.Function("g", [xi, w], [self._g], ["xi", "w"], ["g"])
        self.angles = ca.Function("theta", [xi], [theta], ["xi"], ["theta"])
        self.objective_gradient = ca.Function(
            "dF", [xi, w], [F, ca.gradient(F, xi)], ["xi", "w"], ["F", "dF"]
        )
        self.constraint_jacobian = ca.Function(
            "dg", [xi, w], [self._g, ca.jacobian(self._g, xi)], ["xi", "w"], ["g", "dg"]
        )

    def derivative_functions(self) -> dict[str, ca.Function]:
        """Exact derivatives of each part of (6), for checks and for callers that need them.

        Keys: "F1", "F2" -> Function(xi, w) -> (value, gradient (n,), Hessian (n, n));
        "theta" -> Function(xi, lam) -> (angles (3F,), Jacobian (3F, n), Hessian of lam . theta).
        """
        xi, w = self._xi, self._w
        _, F1, F2 = self.objective(xi, w)
        out = {}
        for name, expr in (("F1", F1), ("F2", F2)):
            hess, grad = ca.hessian(expr, xi)
            out[name] = ca.Function(f"d{name}", [xi, w], [expr, grad, hess])
        theta = self.angles(xi)
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
                raise ValueError(f"fixed mask must have shape ({E},), got {arr.shape}")
            mask = arr.copy()
        else:
            idx = arr.astype(np.int64).ravel()
            bad = idx[(idx < 0) | (idx >= E)]
            if len(bad):
                raise ValueError(f"fixed crease index {int(bad[0])} out of range 0..{E - 1}")
            mask = np.zeros(E, dtype=bool)
            mask[idx] = True
        on_boundary = mask & self.pattern.is_boundary_edge
        if on_boundary.any():
            e = int(np.flatnonzero(on_boundary)[0])
            raise ValueError(f"edge {e} is a boundary edge and cannot be fixed")
        return mask

    def start_point(self, coords: np.ndarray | None = None) -> np.ndarray:
        """Independent variables (n,) of a starting shape (default: the initial pattern)."""
        return self.map.restrict(self.pattern.coords if coords is None else coords)

    def violation(self, coords: np.ndarray, fixed: np.ndarray) -> float:
        """Largest violation of any constraint of (6) at a shape, evaluated with NumPy."""
        s = self.settings
        shape = self.pattern.with_coords(coords)
        dz = coords[:, 2] - np.asarray(self.surface.height(coords[:, 0], coords[:, 1]))
        theta = shape.corner_angles
        parts = [
            np.abs(dz[self._dz_vertices]).max(initial=0.0) - s.dz,
            s.theta_min - theta.min(),
            theta.max() - s.theta_max,
            self.map.residual(coords),
        ]
        if s.rho_bar is not None:
            free = ~fixed & ~shape.is_boundary_edge
            parts.append(np.abs(shape.fold_angles[free]).max(initial=0.0) - s.rho_bar)
        return max(0.0, *parts)

    # ------------------------------------------------------------------ solve
    def solve(
        self, fixed=None, start: np.ndarray | None = None, solver: str = "ipopt"
    ) -> OptimizeResult:
        """Solve (6) from ``start`` coordinates (V, 3) with the creases ``fixed`` fixed."""
        if solver not in SOLVERS:
            raise ValueError(f"unknown solver {solver!r} (choose from {', '.join(SOLVERS)})")
        mask = self.fixed_mask(fixed)
        xi0 = self.start_point(start)
        w = mask.astype(float)
        t0 = time.perf_counter()
        with one_blas_thread():  # which zero of F is reached depends on round-off
            if solver == "ipopt":
                from rigidfold.optimize.ipopt import run_ipopt

                xi, iterations, outcome, message = run_ipopt(self, xi0, w)
            else:
                from rigidfold.optimize.slsqp import run_slsqp

                xi, iterations, outcome, message = run_slsqp(self, xi0, w, exact=solver == "slsqp")
        wall = time.perf_counter() - t0
        coords = self.map.expand(xi)
        F, F1, F2 = (float(v) for v in self.objective(xi, w))
        viol = self.violation(coords, mask)
        status, verdict = classify(outcome, F, viol, self.settings)
        return OptimizeResult(
            pattern=CreasePattern(coords, self.pattern.faces, self.pattern.edges, mask),
            F=F,
            F1=F1,
            F2=F2,
            max_violation=viol,
            status=status,
            message=f"{message}; {verdict}",
            iterations=iterations,
            wall_time=wall,
            solver=solver,
            n_variables=self.n_variables,
        )


def classify(outcome: str, F: float, violation: float, settings: Settings) -> tuple[Status, str]:
    """rigidfold's verdict on a solver run.

    outcome : "solved", "infeasible", "iteration_limit" or "failed" (the solver's own flag).
    A point with F <= F_tol that meets every constraint is accepted whatever the solver said.
    """
    feasible = violation <= settings.constraint_tol
    if feasible and F <= settings.f_tol:
        return Status.CONVERGED, f"accepted: F = {F:.3g} <= F_tol = {settings.f_tol:.3g}"
    if outcome == "infeasible" or (outcome == "solved" and not feasible):
        return Status.INFEASIBLE, f"constraint violation {violation:.3g}"
    if outcome == "iteration_limit":
        return Status.ITERATION_LIMIT, f"stopped at F = {F:.3g}"
    if outcome == "solved":
        return Status.TOLERANCE_NOT_MET, f"F = {F:.3g} > F_tol = {settings.f_tol:.3g}"
    return Status.FAILED, f"F = {F:.3g}, constraint violation {violation:.3g}"
