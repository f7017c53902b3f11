"""Target surfaces z = f(x, y) over the 3 m x 3 m plan square (Step 1).

``height(x, y, xp=numpy)`` is written with arithmetic and ``xp.<function>`` calls only, so the
same code evaluates NumPy arrays and builds CasADi symbolic expressions (``xp=casadi``) for
the exact derivatives of problem (6). ``gradient`` is analytic.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from math import comb
from types import ModuleType
from typing import Any

import numpy as np


@dataclass(frozen=True)
class MirrorPlane:
    """Vertical plane ``a x + b y + c = 0`` (metres); a ``rigidfold.protocols.SymmetryPlane``."""

    a: float
    b: float
    c: float

    def __post_init__(self) -> None:
        if not np.isfinite([self.a, self.b, self.c]).all() or self.a == self.b == 0:
            raise ValueError(f"not a mirror plane: {self.a} x + {self.b} y + {self.c} = 0")

    def signed_distance(self, xy: np.ndarray) -> np.ndarray:
        """Distance of plan points (N, 2) from the plane, positive where a x + b y + c > 0.  (N,)"""
        xy = np.asarray(xy, dtype=float)
        return (self.a * xy[:, 0] + self.b * xy[:, 1] + self.c) / np.hypot(self.a, self.b)

    def reflect(self, xy: np.ndarray) -> np.ndarray:
        """Mirror images of plan points.  (N, 2) -> (N, 2)"""
        normal = np.array([self.a, self.b]) / np.hypot(self.a, self.b)
        return np.asarray(xy, dtype=float) - 2 * self.signed_distance(xy)[:, None] * normal

    def __str__(self) -> str:
        """E.g. "x = 1.5", "x - y = 0", "x + y = 3", "2x - y = 1"."""
        lhs = ""
        for coef, var in ((self.a, "x"), (self.b, "y")):
            if coef == 0:
                continue
            sign = ("-" if coef < 0 else "") if not lhs else (" - " if coef < 0 else " + ")
            lhs += f"{sign}{'' if abs(coef) == 1 else f'{abs(coef):g}'}{var}"
        return f"{lhs} = {-self.c + 0.0:g}"  # + 0.0 turns -0 into 0


class Surface(ABC):
    """A target surface z = f(x, y); satisfies :class:`rigidfold.protocols.TargetSurface`."""

    name: str = "surface"
    mirror_planes: tuple[MirrorPlane, ...] = ()

    @abstractmethod
    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        """z at plan points; x, y are arrays of one shape (or CasADi symbols with xp=casadi)."""

    @abstractmethod
    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """(dz/dx, dz/dy) at plan points, exact.  arrays of the shape of x."""

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(f_xx, f_xy, f_yy) at plan points, exact.  arrays of the broadcast shape of x, y

        By CasADi's automatic differentiation of ``height`` unless a subclass gives it in
        closed form.
        """
        import casadi as ca

        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        fn = self.__dict__.get("_hessian_function")
        if fn is None:
            sx, sy = ca.SX.sym("x"), ca.SX.sym("y")
            h, _ = ca.hessian(self.height(sx, sy, xp=ca) + 0 * sx, ca.vertcat(sx, sy))
            fn = ca.Function("hessian", [sx, sy], [h[0, 0], h[0, 1], h[1, 1]])
            self._hessian_function = fn
        if x.size == 0:
            return np.zeros(x.shape), np.zeros(x.shape), np.zeros(x.shape)
        # a 1 x n row evaluates the scalar function at n points
        out = fn(x.reshape(1, -1), y.reshape(1, -1))
        fxx, fxy, fyy = (np.asarray(h, dtype=float).reshape(x.shape) for h in out)
        return fxx, fxy, fyy

    @abstractmethod
    def metadata(self) -> dict[str, Any]:
        """JSON-serialisable description."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def _bernstein(i: int, t):
    return comb(3, i) * t**i * (1 - t) ** (3 - i)


def _bernstein_derivative(i: int, t):
    """d/dt of the cubic Bernstein polynomial B_i."""
    lower = 0 if i == 0 else 3 * comb(2, i - 1) * t ** (i - 1) * (1 - t) ** (3 - i)
    upper = 0 if i == 3 else 3 * comb(2, i) * t**i * (1 - t) ** (2 - i)
    return lower - upper


# cubic Bernstein polynomials in the power basis: B_i(t) = sum_k _POWER[k, i] t^k
_POWER = np.array([[1, 0, 0, 0], [-3, 3, 0, 0], [3, -6, 3, 0], [-1, 3, -3, 1]], dtype=float)


class Bezier(Surface):
    """Bicubic Bezier patch over [0, 3]^2 with random control heights.

    Control point (i, j) lies at plan position (x, y) = (i, j), i, j = 0..3, so u = x / 3,
    v = y / 3 and ``z = sum_ij B_i(u) B_j(v) h[i, j]`` with ``B_i(t) = C(3, i) t^i (1-t)^(3-i)``.
    The heights are ``h = numpy.random.default_rng(seed).uniform(0, 3, size=(4, 4))``; h[i, j]
    belongs to the control point at (x = i, y = j). (The paper gives no formula.)
    """

    name = "bezier"

    def __init__(self, seed: int = 0) -> None:
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ValueError(f"the Bezier seed must be a non-negative integer, got {seed!r}")
        self.seed: int | None = int(seed)
        self.heights = np.random.default_rng(self.seed).uniform(0.0, 3.0, size=(4, 4))

    @classmethod
    def from_heights(cls, heights: np.ndarray) -> Bezier:
        """A patch with given control heights h (4, 4)."""
        h = np.asarray(heights, dtype=float)
        if h.shape != (4, 4) or not np.isfinite(h).all():
            raise ValueError(f"Bezier control heights must be a finite (4, 4) array, got {h.shape}")
        surface = cls.__new__(cls)
        surface.seed, surface.heights = None, h
        return surface

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        u, v = x / 3.0, y / 3.0
        bu = [_bernstein(i, u) for i in range(4)]
        bv = [_bernstein(j, v) for j in range(4)]
        return sum(bu[i] * bv[j] * float(self.heights[i, j]) for i in range(4) for j in range(4))

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        u, v = np.asarray(x, dtype=float) / 3.0, np.asarray(y, dtype=float) / 3.0
        bu, bv = [_bernstein(i, u) for i in range(4)], [_bernstein(j, v) for j in range(4)]
        du = [_bernstein_derivative(i, u) for i in range(4)]
        dv = [_bernstein_derivative(j, v) for j in range(4)]
        h = self.heights
        gx = sum(du[i] * bv[j] * h[i, j] for i in range(4) for j in range(4)) / 3.0
        gy = sum(bu[i] * dv[j] * h[i, j] for i in range(4) for j in range(4)) / 3.0
        return gx, gy

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        # in the power basis: z = [1 u u^2 u^3] C [1 v v^2 v^3]^T with C = M h M^T
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        u, v = x.ravel() / 3.0, y.ravel() / 3.0
        C = _POWER @ self.heights @ _POWER.T
        one, zero = np.ones_like(u), np.zeros_like(u)
        pu = np.stack([one, u, u * u, u**3], 1)
        du = np.stack([zero, one, 2 * u, 3 * u * u], 1)
        ddu = np.stack([zero, zero, 2 * one, 6 * u], 1)
        pv = np.stack([one, v, v * v, v**3], 1)
        dv = np.stack([zero, one, 2 * v, 3 * v * v], 1)
        ddv = np.stack([zero, zero, 2 * one, 6 * v], 1)
        fxx = np.einsum("ni,ni->n", ddu @ C, pv) / 9.0
        fxy = np.einsum("ni,ni->n", du @ C, dv) / 9.0
        fyy = np.einsum("ni,ni->n", pu @ C, ddv) / 9.0
        return fxx.reshape(x.shape), fxy.reshape(x.shape), fyy.reshape(x.shape)

    def metadata(self) -> dict[str, Any]:
        return {"name": self.name, "seed": self.seed, "control_heights": self.heights.tolist()}

    def __repr__(self) -> str:
        if self.seed is None:
            return "Bezier.from_heights(<(4, 4) control heights>)"
        return f"Bezier({self.seed})"


class Dome(Surface):
    """Spherical cap through the four corners (z = 0) with its apex 1.5 m high at (1.5, 1.5).

    Radius R = 2.25 m, centre (1.5, 1.5, -0.75): ``z = -0.75 + sqrt(R^2 - (x-1.5)^2 - (y-1.5)^2)``,
    defined within R of the plan centre (the plan square reaches 2.12 m from it).
    """

    name = "dome"
    radius = 2.25
    centre_z = -0.75
    mirror_planes = (MirrorPlane(1.0, 0.0, -1.5), MirrorPlane(0.0, 1.0, -1.5))

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        return self.centre_z + xp.sqrt(self.radius**2 - (x - 1.5) ** 2 - (y - 1.5) ** 2)

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        root = np.sqrt(self.radius**2 - (x - 1.5) ** 2 - (y - 1.5) ** 2)
        return -(x - 1.5) / root, -(y - 1.5) / root

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        dx, dy = x - 1.5, y - 1.5
        root = np.sqrt(self.radius**2 - dx**2 - dy**2)
        cube = root**3
        return -1 / root - dx**2 / cube, -dx * dy / cube, -1 / root - dy**2 / cube

    def metadata(self) -> dict[str, Any]:
        return {"name": self.name, "apex_m": 1.5, "radius_m": self.radius}


class HyperbolicParaboloid(Surface):
    """z = 0.4 (x - 1.5)(y - 1.5): 1.8 m between the lowest and the highest corner.

    Its mirror planes are the diagonals x = y and x + y = 3 (z changes sign across x = 1.5).
    """

    name = "hp"
    k = 0.4
    mirror_planes = (MirrorPlane(1.0, -1.0, 0.0), MirrorPlane(1.0, 1.0, -3.0))

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        return self.k * (x - 1.5) * (y - 1.5)

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.k * (y - 1.5), self.k * (x - 1.5)

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return np.zeros(x.shape), np.full(x.shape, self.k), np.zeros(x.shape)

    def metadata(self) -> dict[str, Any]:
        return {"name": self.name, "k": self.k}
