"""The partially rigid frame model (Section 2, Appendix A)."""

from rigidfold.frame.model import FrameModel, default_support_face

__all__ = ["FrameModel", "default_support_face"]
