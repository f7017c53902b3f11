"""Step 8: development diagrams, problem (13)."""

from rigidfold.develop.diagram import (
    Development,
    DevelopStatus,
    count_flipped,
    count_overlaps,
    develop,
)

__all__ = ["DevelopStatus", "Development", "count_flipped", "count_overlaps", "develop"]
