"""The energy of the structure along its motion, U(s), and its derivative.

Quasi-static (slow deployment, no inertia). With panel ``b`` clamped in its built pose (the
base: the motion expressed in its frame), the energy at a state is

* gravity: ``U_g = g sum_i m_i (z_i - z_ground)``, z_i the height of mass i in the base's
  frame (:mod:`rigidfold.drive.mass`): with the base's rotation R_b and translation t_b
  at the state, ``z_i = (R_b e_z) . (x_i - t_b)``, so ``U_g = g (R_b e_z) . (C - M t_b)``
  with C = sum m_i x_i the first moment and M the total mass: one dot product per base and
  state, so every base is cheap;
* the hinges' springs: ``U_k = 1/2 sum_h k L_h (rho_h - rho_rest,h)^2`` (k per metre of
  crease, L_h the hinge's length, rho_rest 0 for a spring at rest flat, the built fold angle
  for one at rest built); the same for every base.

dU/ds is the central difference of second order on the states (``numpy.gradient`` with
their spacing; the states are refined so that no hinge turns more than
``Settings.drive.max_step`` between two), the springs' exactly ``sum k L (rho - rest)
drho/ds``; the hinges' rates ``drho/ds`` the same differences of their continuous fold
angles. Coulomb friction of ``mu`` N m per metre dissipates ``D(s) = sum mu L_h |drho_h/ds|``
per unit of s: it always resists the motion, so the drive's power per unit of s is
``dU/ds + D`` deploying (s rising) and ``dU/ds - D`` folding back (s falling; the torque
that holds it as it goes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidfold.drive.mass import Masses
from rigidfold.drive.motion import DriveMotion


def derivative(values: np.ndarray, s: np.ndarray) -> np.ndarray:
    """d values / ds along the last axis (K states at ``s`` (K,)), central differences of
    second order on the uneven spacing (one-sided of second order at the ends)."""
    values = np.asarray(values, dtype=np.float64)
    if len(s) < 2:
        return np.zeros_like(values)
    spacing = np.asarray(s, dtype=np.float64)
    if len(s) >= 3:
        return np.asarray(np.gradient(values, spacing, axis=-1, edge_order=2))
    return np.asarray(np.gradient(values, spacing, axis=-1, edge_order=1))


@dataclass(frozen=True, eq=False)
class Energy:
    """The energy along the motion, every base at once.

    s : (K,) the states' s.
    gravity : (B, K) U_g with each panel as the base, J (``bases`` the panels of the rows).
    d_gravity : (B, K) its derivative, J per unit of s.
    spring : (K,) U_k, J; d_spring : (K,) its derivative.
    fold : (K, H) the hinges' fold angles, radians; rate : (K, H) their derivative.
    friction : (K,) D(s), the friction's dissipation per unit of s, J.
    length : (H,) the hinges' lengths, m.
    ground : the ground's height, m.
    """

    s: np.ndarray
    gravity: np.ndarray
    d_gravity: np.ndarray
    spring: np.ndarray
    d_spring: np.ndarray
    fold: np.ndarray
    rate: np.ndarray
    friction: np.ndarray
    length: np.ndarray
    ground: float

    def total(self, base: int) -> np.ndarray:
        """(K,) U with ``base`` clamped, J."""
        return self.gravity[base] + self.spring

    def slope(self, base: int) -> np.ndarray:
        """(K,) dU/ds with ``base`` clamped, J."""
        return self.d_gravity[base] + self.d_spring

    def power(self, base: int, *, deploying: bool = True) -> np.ndarray:
        """(K,) the drive's work per unit of s: ``dU/ds + D`` deploying, ``dU/ds - D`` folding
        back (see the module's text), J."""
        return self.slope(base) + (self.friction if deploying else -self.friction)

    def powers(self, *, deploying: bool = True) -> np.ndarray:
        """(B, K): :meth:`power` of every base."""
        sign = 1.0 if deploying else -1.0
        return self.d_gravity + self.d_spring + sign * self.friction


def energy(
    motion: DriveMotion,
    masses: Masses,
    *,
    gravity: float,
    stiffness: float = 0.0,
    friction: float = 0.0,
    rest: str = "flat",
    ground: float | None = None,
) -> Energy:
    """The :class:`Energy` of ``motion`` (see the module's text): ``masses``; ``gravity``
    m/s^2; hinge ``stiffness`` N m/rad per metre, its spring at ``rest`` ``"flat"`` or
    ``"built"``; ``friction`` N m per metre; ``ground`` the ground's height, m (default:
    the lowest vertex of the built design)."""
    pm = motion.motion
    s = motion.s
    pattern = motion.panels.pattern
    if ground is None:
        ground = float(pattern.coords[:, 2].min())
    rotations, translations = pm.rotations, pm.translations
    first = masses.first_moments(rotations, translations)  # (K, 3)
    up = rotations[:, :, :, 2]  # (K, P, 3): each base's z axis in the motion's frame
    m = masses.total
    height = np.einsum("kbi,ki->bk", up, first) - m * np.einsum("kbi,kbi->bk", up, translations)
    u_g = gravity * (height - m * ground)
    fold = motion.fold
    rate = derivative(fold.T, s).T if fold.size else np.zeros_like(fold)
    u, v = motion.panels.hinge_vertices.T
    length = np.linalg.norm(pattern.coords[v] - pattern.coords[u], axis=1)
    rho_rest = fold[-1] if rest == "built" and len(fold) else np.zeros(fold.shape[1])
    k = stiffness * length
    strain = fold - rho_rest
    u_k = 0.5 * (strain**2 @ k)
    du_k = (strain * rate) @ k
    d = np.abs(rate) @ (friction * length)
    return Energy(
        s=s,
        gravity=u_g,
        d_gravity=derivative(u_g, s),
        spring=u_k,
        d_spring=du_k,
        fold=fold,
        rate=rate,
        friction=d,
        length=length,
        ground=float(ground),
    )
