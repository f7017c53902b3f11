"""Step 8: development diagrams, problem (13)."""

from rigidfold.develop.diagram import Development, count_flipped, count_overlaps, develop

__all__ = ["Development", "count_flipped", "count_overlaps", "develop"]
