"""Selection of the crease lines to fix (Section 5)."""

from rigidfold.selection.criteria import (
    CRITERIA,
    Scores,
    predicted_locks,
    rank_candidates,
    score_creases,
)
from rigidfold.selection.lookahead import (
    Choice,
    LockForecast,
    carried_angles,
    exact_residuals,
    flat_groups,
    group_bases,
    lock_forecast,
    lookahead_order,
    squared_residuals,
)
from rigidfold.selection.symmetry import crease_groups

__all__ = [
    "CRITERIA",
    "Choice",
    "LockForecast",
    "Scores",
    "carried_angles",
    "crease_groups",
    "exact_residuals",
    "flat_groups",
    "group_bases",
    "lock_forecast",
    "lookahead_order",
    "predicted_locks",
    "rank_candidates",
    "score_creases",
    "squared_residuals",
]
