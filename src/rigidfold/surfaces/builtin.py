"""Target surfaces z = f(x, y) over a plan box [0, W] x [0, H] (Step 1).

The built-in surfaces are defined on the paper's 3 m x 3 m square and scale to the bounding
box of a larger or smaller pattern (``box=(W, H)``, each documented below); on the default
box ``(3, 3)`` they are exactly the paper's.

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

from rigidfold.config import DEFAULT_SEED, check_seed
from rigidfold.errors import RigidfoldError


@dataclass(frozen=True)
class MirrorPlane:
    """Vertical plane ``a x + b y + c = 0`` (metres); a ``rigidfold.protocols.SymmetryPlane``."""

    a: float
    b: float
    c: float

    def __post_init__(self) -> None:
        if not np.isfinite([self.a, self.b, self.c]).all() or self.a == self.b == 0:
            raise RigidfoldError(f"not a mirror plane: {self.a} x + {self.b} y + {self.c} = 0")

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
    """Bicubic Bezier patch over the plan box [0, W] x [0, H] with random control heights.

    Control point (i, j) lies at plan position (x, y) = (i W / 3, j H / 3), i, j = 0..3, so
    u = x / W, v = y / H and ``z = sum_ij B_i(u) B_j(v) h[i, j]`` with
    ``B_i(t) = C(3, i) t^i (1-t)^(3-i)``. The heights (metres, whatever the box) are
    ``h = numpy.random.default_rng(seed).uniform(0, 3, size=(4, 4))``; h[i, j] belongs to the
    control point at (x = i W / 3, y = j H / 3). The paper's box is 3 x 3: control points at
    (i, j). (The paper gives no formula.)
    """

    name = "bezier"

    def __init__(self, seed: int = DEFAULT_SEED, *, box: tuple[float, float] = (3.0, 3.0)) -> None:
        self.seed: int | None = check_seed(seed, "the Bezier seed")
        self.heights = np.random.default_rng(self.seed).uniform(0.0, 3.0, size=(4, 4))
        self.box = _box(box)

    @classmethod
    def from_heights(cls, heights: np.ndarray, *, box: tuple[float, float] = (3.0, 3.0)) -> Bezier:
        """A patch with given control heights h (4, 4) over the plan box (W, H)."""
        h = np.asarray(heights, dtype=float)
        if h.shape != (4, 4) or not np.isfinite(h).all():
            raise RigidfoldError(
                f"Bezier control heights must be a finite (4, 4) array, got {h.shape}"
            )
        surface = cls.__new__(cls)
        surface.seed, surface.heights, surface.box = None, h, _box(box)
        return surface

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        u, v = x / self.box[0], y / self.box[1]
        bu = [_bernstein(i, u) for i in range(4)]
        bv = [_bernstein(j, v) for j in range(4)]
        return sum(bu[i] * bv[j] * float(self.heights[i, j]) for i in range(4) for j in range(4))

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        width, height = self.box
        u, v = np.asarray(x, dtype=float) / width, np.asarray(y, dtype=float) / height
        bu, bv = [_bernstein(i, u) for i in range(4)], [_bernstein(j, v) for j in range(4)]
        du = [_bernstein_derivative(i, u) for i in range(4)]
        dv = [_bernstein_derivative(j, v) for j in range(4)]
        h = self.heights
        gx = sum(du[i] * bv[j] * h[i, j] for i in range(4) for j in range(4)) / width
        gy = sum(bu[i] * dv[j] * h[i, j] for i in range(4) for j in range(4)) / height
        return gx, gy

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        # in the power basis: z = [1 u u^2 u^3] C [1 v v^2 v^3]^T with C = M h M^T
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        width, height = self.box
        u, v = x.ravel() / width, y.ravel() / height
        C = _POWER @ self.heights @ _POWER.T
        one, zero = np.ones_like(u), np.zeros_like(u)
        pu = np.stack([one, u, u * u, u**3], 1)
        du = np.stack([zero, one, 2 * u, 3 * u * u], 1)
        ddu = np.stack([zero, zero, 2 * one, 6 * u], 1)
        pv = np.stack([one, v, v * v, v**3], 1)
        dv = np.stack([zero, one, 2 * v, 3 * v * v], 1)
        ddv = np.stack([zero, zero, 2 * one, 6 * v], 1)
        fxx = np.einsum("ni,ni->n", ddu @ C, pv) / (width * width)
        fxy = np.einsum("ni,ni->n", du @ C, dv) / (width * height)
        fyy = np.einsum("ni,ni->n", pu @ C, ddv) / (height * height)
        return fxx.reshape(x.shape), fxy.reshape(x.shape), fyy.reshape(x.shape)

    def metadata(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "seed": self.seed,
            "control_heights": self.heights.tolist(),
            "plan_box_m": list(self.box),
        }

    def __repr__(self) -> str:
        if self.seed is None:
            args = ", ".join(["<(4, 4) control heights>", *_box_args(self.box)])
            return f"Bezier.from_heights({args})"
        return f"Bezier({', '.join([str(self.seed), *_box_args(self.box)])})"


class Dome(Surface):
    """Spherical cap through the four corners (z = 0) of the plan box, apex over its centre.

    On the paper's 3 m x 3 m box: apex 1.5 m high at (1.5, 1.5), radius R = 2.25 m, centre
    (1.5, 1.5, -0.75): ``z = -0.75 + sqrt(R^2 - (x-1.5)^2 - (y-1.5)^2)``, defined within R of
    the plan centre (the plan square reaches 2.12 m from it). On a box (W, H) this dome is
    scaled by s = (half diagonal of the box) / (half diagonal of the 3 m square) about the
    box's centre (W / 2, H / 2), so that it still passes through the four corners: R = 2.25 s,
    apex 1.5 s. Mirror planes x = W / 2 and y = H / 2.

    A solve may move a vertex past the sphere's rim (r = R from the plan centre), where the
    square root has no real value. Past the circle midway (in R^2 - r^2) between the box's
    corners and the rim, ``u = R^2 - r^2 < u0 = (R^2 - r_corner^2) / 2``, the root
    continues along its tangent in u, ``sqrt(u0) + (u - u0) / (2 sqrt(u0))``: a paraboloid
    joined to the sphere with its height and slope (C1), defined everywhere, unchanged over
    the box, so that neither the solver nor a check meets a NaN outside it.
    """

    name = "dome"

    def __init__(self, *, box: tuple[float, float] = (3.0, 3.0)) -> None:
        self.box = _box(box)
        scale = _scale(self.box)
        self.cx, self.cy = self.box[0] / 2, self.box[1] / 2
        self.radius = 2.25 * scale
        self.centre_z = -0.75 * scale
        self.apex = 1.5 * scale
        self.mirror_planes = (MirrorPlane(1.0, 0.0, -self.cx), MirrorPlane(0.0, 1.0, -self.cy))
        corner_sq = (1.5 * scale) ** 2 * 2  # r^2 of the box's corners
        self.u0 = (self.radius**2 - corner_sq) / 2  # where the root's tangent takes over

    def _u(self, x: Any, y: Any) -> Any:
        return self.radius**2 - (x - self.cx) ** 2 - (y - self.cy) ** 2

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        u, u0 = self._u(x, y), self.u0
        root = xp.sqrt(xp.fmax(u, u0)) + xp.fmin(u - u0, 0.0) / (2 * np.sqrt(u0))
        return self.centre_z + root

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        root = np.sqrt(np.fmax(self._u(x, y), self.u0))  # 2 dz/du, either side of u0
        return -(x - self.cx) / root, -(y - self.cy) / root

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        dx, dy = x - self.cx, y - self.cy
        u = self._u(x, y)
        root = np.sqrt(np.fmax(u, self.u0))
        cube = np.where(u >= self.u0, root**3, np.inf)  # the tangent's d2z/du2 is 0
        return -1 / root - dx**2 / cube, -dx * dy / cube, -1 / root - dy**2 / cube

    def metadata(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "apex_m": self.apex,
            "radius_m": self.radius,
            "plan_box_m": list(self.box),
        }

    def __repr__(self) -> str:
        return f"Dome({', '.join(_box_args(self.box))})"


class HyperbolicParaboloid(Surface):
    """z = 0.4 (x - 1.5)(y - 1.5) on the 3 m square: 1.8 m between its lowest and highest corner.

    On a box (W, H) it is scaled like :class:`Dome`, by s about the box's centre (cx, cy) =
    (W / 2, H / 2): ``z = (0.4 / s) (x - cx)(y - cy)``. Its mirror planes are the lines
    x - y = cx - cy and x + y = cx + cy through the centre (on the 3 m square, the diagonals
    x = y and x + y = 3; z changes sign across x = cx).
    """

    name = "hp"

    def __init__(self, *, box: tuple[float, float] = (3.0, 3.0)) -> None:
        self.box = _box(box)
        self.k = 0.4 / _scale(self.box)
        self.cx, self.cy = self.box[0] / 2, self.box[1] / 2
        self.mirror_planes = (
            MirrorPlane(1.0, -1.0, self.cy - self.cx),
            MirrorPlane(1.0, 1.0, -(self.cx + self.cy)),
        )

    def height(self, x: Any, y: Any, xp: ModuleType = np) -> Any:
        return self.k * (x - self.cx) * (y - self.cy)

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.k * (y - self.cy), self.k * (x - self.cx)

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return np.zeros(x.shape), np.full(x.shape, self.k), np.zeros(x.shape)

    def metadata(self) -> dict[str, Any]:
        return {"name": self.name, "k": self.k, "plan_box_m": list(self.box)}

    def __repr__(self) -> str:
        return f"HyperbolicParaboloid({', '.join(_box_args(self.box))})"


_PAPER_BOX = (3.0, 3.0)


def _box(box: tuple[float, float]) -> tuple[float, float]:
    """(W, H) checked: two positive finite numbers of metres."""
    try:
        width, height = (float(v) for v in box)
    except (TypeError, ValueError):
        raise RigidfoldError(f"a plan box is (W, H) in metres, got {box!r}") from None
    if not (np.isfinite([width, height]).all() and width > 0 and height > 0):
        raise RigidfoldError(f"a plan box needs a positive finite width and height, got {box!r}")
    return width, height


def _scale(box: tuple[float, float]) -> float:
    """Half diagonal of ``box`` over that of the paper's 3 m square (exactly 1 on it)."""
    return float(np.hypot(*box) / np.hypot(*_PAPER_BOX))


def _box_args(box: tuple[float, float]) -> list[str]:
    """["box=(W, H)"] for a ``__repr__``, or [] for the paper's square."""
    return [] if box == _PAPER_BOX else [f"box=({box[0]:g}, {box[1]:g})"]
