"""Mechanism analysis of the frame model and prediction of locked crease lines (Section 4)."""

from rigidfold.mechanism.analysis import METHODS, Mechanism, analyze

__all__ = ["METHODS", "Mechanism", "analyze"]
