"""Selection of the crease lines to fix (Section 5)."""

from rigidfold.selection.criteria import (
    CRITERIA,
    Scores,
    predicted_locks,
    rank_candidates,
    score_creases,
)
from rigidfold.selection.symmetry import crease_groups

__all__ = [
    "CRITERIA",
    "Scores",
    "crease_groups",
    "predicted_locks",
    "rank_candidates",
    "score_creases",
]
