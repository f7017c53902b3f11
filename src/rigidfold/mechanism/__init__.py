"""Mechanism analysis of the frame model and prediction of locked crease lines (Section 4)."""

from rigidfold.mechanism.analysis import (
    METHODS,
    Mechanism,
    analysis_bytes,
    analysis_memory,
    analyze,
    check_analysis_size,
    chosen_method,
)

__all__ = [
    "METHODS",
    "Mechanism",
    "analysis_bytes",
    "analysis_memory",
    "analyze",
    "check_analysis_size",
    "chosen_method",
]
