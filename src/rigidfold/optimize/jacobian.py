"""Closed-form first derivatives of (6) for IPOPT: the gradient of F and the constraint Jacobian.

On a large pattern CasADi's symbolic gradient of F and Jacobian of the constraints g cost half
of the model's build (0.4 s and 0.8 s of 2.4 s on a 41 x 41 grid, ``docs/scale.md``), for
derivatives that are short sums of element gradients:

::

    grad F = 2 J_r^T r                       (r, J_r: rigidfold.optimize.residuals)
    d(z_v - f(x_v, y_v))        = (-f_x, -f_y, 1)                  in (x_v, y_v, z_v)
    d theta                     = angle_gradients                  in the triangle's corners
    d((1 - w)(cos rho_max - cos rho)) = (1 - w) sin rho d rho      in the crease's stencil

This module evaluates them with NumPy and hands them to IPOPT as CasADi callbacks, with the
Jacobian's sparsity in the independent variables xi (``P = T xi + t``) fixed per problem:
each element entry is mapped to its nonzeros by one sparse matrix built once, as
``rigidfold.optimize.hessian`` does for the Hessian. The rows and their order are those of
``NLP.g`` (dz, sector angles, then (12) when ``rho_max`` is set); ``tests/test_jacobian.py``
checks both against CasADi's derivatives.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import casadi as ca
import numpy as np
import scipy.sparse as sp

from rigidfold.errors import RigidfoldError
from rigidfold.optimize.hessian import (
    angle_corners,
    coordinate_rows,
    expand_rows,
    unique_inverse,
)
from rigidfold.optimize.residuals import Residuals, angle_gradients, fold_angle_gradients
from rigidfold.optimize.solver import SolverProblem


class ClosedFormJacobian:
    """The constraints g of (6) and their Jacobian in xi, from element gradients.

    ``sparsity`` is a CasADi Sparsity (m, n); ``values(xi, w)`` returns g (m,) and the
    Jacobian's nonzeros (nnz,) in CasADi's (column-major) order.
    """

    def __init__(self, problem: SolverProblem) -> None:
        pat, lin = problem.pattern, problem.map
        V, n = pat.n_vertices, lin.n_variables
        self.V, self.T, self.t = V, lin.T.tocsr(), lin.t
        self.surface = problem.surface
        self.angle_vertices = angle_corners(pat.faces)  # (3F, 3): a, b, c
        self.dz_vertices = problem.nlp.dz_vertices
        self.rho_max = problem.settings.design.rho_max
        self.interior = pat.interior_edges
        self.stencils = pat.crease_stencils(self.interior)  # (Ei, 4): u, v, a, b
        n_dz, n_theta = len(self.dz_vertices), len(self.angle_vertices)
        blocks = [self.dz_vertices[:, None], self.angle_vertices]
        if self.rho_max is not None:
            blocks.append(self.stencils)
        self.m = n_dz + n_theta + (len(self.stencils) if self.rho_max is not None else 0)
        if self.m != problem.nlp.g.shape[0]:
            raise RigidfoldError(f"{self.m} constraint rows, the NLP has {problem.nlp.g.shape[0]}")
        # every element entry: its row of g and its row of P (vertex-major, then x, y, z)
        rows, P_rows, start = [], [], 0
        for vertices in blocks:
            K, L = vertices.shape
            rows.append(np.repeat(np.arange(start, start + K), 3 * L))
            P_rows.append(coordinate_rows(vertices, V).ravel())
            start += K
        row, P_row = np.concatenate(rows), np.concatenate(P_rows)
        entry, col, weight = expand_rows(self.T, P_row)
        keys, slot = unique_inverse(col * self.m + row[entry])  # column-major
        cols, g_rows = keys // self.m, keys % self.m
        self._colptr = np.searchsorted(cols, np.arange(n + 1))
        self._g_rows = g_rows
        self.sparsity = ca.Sparsity(self.m, n, self._colptr.tolist(), g_rows.tolist())
        self.R = sp.csr_matrix((weight, (slot, entry)), shape=(len(keys), len(row)))

    def values(self, xi: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """g (m,) and the Jacobian's nonzeros (nnz,) at xi (n,), fixed-crease weights w (E,)."""
        X = (self.T @ np.asarray(xi, dtype=float) + self.t).reshape(3, self.V).T
        v = self.dz_vertices
        fx, fy = self.surface.gradient(X[v, 0], X[v, 1])
        g_dz = X[v, 2] - np.asarray(self.surface.height(X[v, 0], X[v, 1]), dtype=float)
        e_dz = np.stack([-fx, -fy, np.ones(len(v))], axis=1)
        theta, e_theta = angle_gradients(X[self.angle_vertices])
        g, e = [g_dz, theta], [e_dz.ravel(), e_theta.ravel()]
        if self.rho_max is not None:
            free = 1.0 - np.asarray(w, dtype=float)[self.interior]
            rho, e_rho = fold_angle_gradients(X[self.stencils])
            g.append(free * (np.cos(self.rho_max) - np.cos(rho)))
            e.append(((free * np.sin(rho))[:, None] * e_rho).ravel())
        return np.concatenate(g), self.R @ np.concatenate(e)

    def matrix(self, nonzeros: np.ndarray) -> sp.csr_matrix:
        """The Jacobian (m, n) as a SciPy matrix, from the nonzeros of ``values``."""
        shape = (self.m, len(self._colptr) - 1)
        return sp.csc_matrix((nonzeros, self._g_rows, self._colptr), shape=shape).tocsr()


class ClosedFormGradient:
    """F and its gradient in xi, ``grad F = 2 J_r^T r`` from ``Residuals``."""

    def __init__(self, residuals: Residuals) -> None:
        self.residuals = residuals

    def values(self, xi: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """F (1,) and grad F (n,) at xi (n,), fixed-crease weights w (E,)."""
        r, J = self.residuals(xi, w)
        assert J is not None
        return np.array([r @ r]), 2.0 * (J.T @ r)


class _NumpyCallback(ca.Callback):
    """A CasADi Function (x, p) -> outputs of given sparsities, evaluated by ``fn(x, p)``."""

    def __init__(
        self,
        name: str,
        sizes: tuple[int, int],
        out: Sequence[tuple[str, ca.Sparsity]],
        fn: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]],
    ) -> None:
        ca.Callback.__init__(self)
        self.sizes, self.out, self.fn = sizes, list(out), fn
        self.construct(name, {})

    def get_n_in(self) -> int:
        return 2

    def get_n_out(self) -> int:
        return len(self.out)

    def get_name_in(self, i: int) -> str:
        return ("x", "p")[i]

    def get_name_out(self, i: int) -> str:
        return self.out[i][0]

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self.sizes[i], 1)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return self.out[i][1]

    def has_eval_buffer(self) -> bool:  # NumPy views of CasADi's buffers: no copies
        return True

    def eval_buffer(self, arg, res) -> int:
        x, p = (np.frombuffer(a, dtype=np.float64) for a in arg)
        for buffer, value in zip(res, self.fn(x, p), strict=True):
            if buffer is not None:  # None: an output the caller did not ask for
                np.frombuffer(buffer, dtype=np.float64)[:] = value
        return 0


def closed_form_first_derivatives(
    problem: SolverProblem,
    residuals: Residuals | None = None,
    jacobian: ClosedFormJacobian | None = None,
) -> tuple[ca.Function, ca.Function]:
    """IPOPT's ``grad_f`` (x, p) -> (f, grad_f) and ``jac_g`` (x, p) -> (g, jac_g) Functions.

    ``residuals`` and ``jacobian`` are the problem's, built here unless given. Keep
    references to both Functions: CasADi keeps none to a Python callback.
    """
    n, n_p = problem.map.n_variables, problem.nlp.p.shape[0]
    if residuals is None:
        residuals = Residuals(problem.pattern, problem.map)
    if jacobian is None:
        jacobian = ClosedFormJacobian(problem)
    gradient = ClosedFormGradient(residuals)
    grad_f = _NumpyCallback(
        "nlp_grad_f",
        (n, n_p),
        [("f", ca.Sparsity.dense(1, 1)), ("grad_f_x", ca.Sparsity.dense(n, 1))],
        gradient.values,
    )
    jac_g = _NumpyCallback(
        "nlp_jac_g",
        (n, n_p),
        [("g", ca.Sparsity.dense(jacobian.m, 1)), ("jac_g_x", jacobian.sparsity)],
        jacobian.values,
    )
    return grad_f, jac_g
