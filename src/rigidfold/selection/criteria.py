"""Selection criteria of the crease line to fix (Section 5).

For every free crease j (hinge of the frame model):

* S^S_j = |rho_j| / sum |rho|                                  shape score        (32)
* S^F_j = max_i phi_ij^2 / sum_j max_i phi_ij^2                mechanism score    (33-34)
* S^F-hat_j: the same with the column-normalised modes Phi-hat                    (36)
* S_j = S^S_j / S^F_j,  S-hat_j = S^S_j / S^F-hat_j                              (37-38)

The crease with the *lowest* score is fixed first. ``"random"`` ranks the creases randomly,
``"ss"`` by S^S alone. With mirror symmetry, creases are fixed in mirror groups; a group's
score is the mean score of its members.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rigidfold.config import DEFAULTS, Settings
from rigidfold.errors import RigidfoldError
from rigidfold.mechanism import Mechanism
from rigidfold.mechanism.stiffness import PseudoStiffness, hinge_stiffness

CRITERIA = ("shat", "s", "ss", "random")


@dataclass(frozen=True, eq=False)
class Scores:
    """All scores of the free creases of one shape; arrays are (h,), row j = hinges[j]."""

    hinges: np.ndarray
    S_S: np.ndarray
    S_F: np.ndarray
    S_F_hat: np.ndarray
    stiffness: PseudoStiffness

    @property
    def S(self) -> np.ndarray:
        return _ratio(self.S_S, self.S_F)

    @property
    def S_hat(self) -> np.ndarray:
        return _ratio(self.S_S, self.S_F_hat)

    def of(self, criterion: str) -> np.ndarray:
        """The score array used by a criterion ("random" has none: NaN)."""
        if criterion == "shat":
            return self.S_hat
        if criterion == "s":
            return self.S
        if criterion == "ss":
            return self.S_S
        if criterion == "random":
            return np.full(len(self.hinges), np.nan)
        raise RigidfoldError(f"unknown criterion {criterion!r} (choose from {', '.join(CRITERIA)})")


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.inf)


def _share(values: np.ndarray) -> np.ndarray:
    total = values.sum()
    return values / total if total > 0 else np.zeros_like(values)


def score_creases(
    mechanism: Mechanism,
    *,
    K: np.ndarray | None = None,
    seed: int | None = 0,
    settings: Settings = DEFAULTS,
) -> Scores:
    """Scores (32)-(38) of every free crease of an analysed shape."""
    h = mechanism.frame.n_hinges
    if K is None:
        K = hinge_stiffness(h, seed, settings)
    stiff = PseudoStiffness(mechanism.H_phi, np.asarray(K, dtype=float))
    rho = np.abs(mechanism.pattern.fold_angles[mechanism.hinges])
    if mechanism.dof == 0:
        zero = np.zeros(h)
        return Scores(mechanism.hinges, _share(rho), zero, zero, stiff)
    s_f = _share((stiff.Phi**2).max(axis=1))
    s_f_hat = _share((stiff.normalised_modes() ** 2).max(axis=1))
    return Scores(mechanism.hinges, _share(rho), s_f, s_f_hat, stiff)


def predicted_locks(
    stiffness: PseudoStiffness, j: int, *, factor: float = 1e14, settings: Settings = DEFAULTS
) -> np.ndarray:
    """Hinges predicted to lock when hinge j is fixed (Section 4.2, Property 2).

    K_j is multiplied by ``factor``; a hinge p != j whose rotations outside the stiffest mode
    vanish (relative to its own rotations before, below ``lock_prediction_tol``) is predicted
    locked.  returns : (k,) hinge indices (rows of H_phi)
    """
    before = np.linalg.norm(stiffness.Phi, axis=1)
    after = stiffness.stiffened(j, factor).residual_rotations()
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(before > 0, after / before, 0.0)
    rel[j] = np.inf
    return np.flatnonzero(rel < settings.generation.lock_prediction_tol)


def rank_candidates(
    scores: Scores,
    criterion: str,
    *,
    groups: Sequence[Sequence[int]] | None = None,
    rng: np.random.Generator | None = None,
) -> list[tuple[tuple[int, ...], float]]:
    """Candidate crease groups in the order to try them: lowest score first.

    groups : mirror groups of edge indices (default: each free crease alone); groups that
    contain a crease which is not free are skipped.
    returns : [(edge indices, score)], score NaN for "random".
    """
    values = scores.of(criterion)
    ranked: list[tuple[tuple[int, ...], float]]
    if groups is None:
        ranked = [((int(e),), float(v)) for e, v in zip(scores.hinges, values, strict=True)]
    else:
        index_of = {int(e): j for j, e in enumerate(scores.hinges)}
        ranked = []
        for group in groups:
            if all(int(e) in index_of for e in group):
                g = tuple(sorted(int(e) for e in group))
                ranked.append((g, float(np.mean([values[index_of[e]] for e in g]))))
    if criterion == "random":
        rng = rng or np.random.default_rng()
        order = rng.permutation(len(ranked))
        return [ranked[k] for k in order]
    return sorted(ranked, key=lambda item: (item[1], item[0]))
