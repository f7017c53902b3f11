"""What the steps read from a target surface and from a mirror plane, as typing Protocols.

The concrete classes live in :mod:`rigidfold.surfaces` (``Surface`` and its subclasses,
``MirrorPlane``); these Protocols let the lower packages (``mesh``, ``patterns``, ``optimize``)
name the types they accept without importing that package. Members are read-only properties:
a class attribute, a frozen dataclass field or a property each satisfies one.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any, Protocol

import numpy as np


class SymmetryPlane(Protocol):
    """A vertical plane ``a x + b y + c = 0`` (metres) that mirrors plan points.

    ``str(plane)`` names it in messages and metadata.
    """

    @property
    def a(self) -> float: ...

    @property
    def b(self) -> float: ...

    @property
    def c(self) -> float: ...

    def reflect(self, xy: np.ndarray) -> np.ndarray:
        """Mirror images of plan points.  (N, 2) -> (N, 2)"""
        ...


class TargetSurface(Protocol):
    """A target surface z = f(x, y) (Step 1).

    ``height`` must evaluate NumPy arrays (``xp=numpy``) and build CasADi expressions from
    CasADi symbols (``xp=casadi``) for the exact derivatives of problem (6).
    """

    @property
    def name(self) -> str: ...

    @property
    def mirror_planes(self) -> tuple[SymmetryPlane, ...]:
        """The surface's own vertical planes of symmetry (may be empty)."""
        ...

    def height(self, x: Any, y: Any, xp: ModuleType = ...) -> Any:
        """z at plan points; x, y are arrays of one shape (or CasADi symbols with xp=casadi)."""
        ...

    def gradient(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """(f_x, f_y) at plan points.  arrays of the broadcast shape of x, y"""
        ...

    def hessian(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(f_xx, f_xy, f_yy) at plan points.  arrays of the broadcast shape of x, y"""
        ...

    def metadata(self) -> dict[str, Any]:
        """JSON-serialisable description."""
        ...
