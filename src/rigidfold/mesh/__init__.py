"""Crease-pattern data, topology and geometry."""

from rigidfold.mesh.pattern import BoundarySide, CreasePattern

__all__ = ["BoundarySide", "CreasePattern"]
