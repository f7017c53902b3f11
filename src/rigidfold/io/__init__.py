"""File formats: FOLD 1.2 crease patterns and SVG drawings."""

from rigidfold.io.fold import (
    FoldData,
    crease_pattern_frame,
    fold_dict,
    motion_frames,
    pattern_from_fold,
    read_fold,
    write_fold,
)
from rigidfold.io.svg import svg_text, write_svg

__all__ = [
    "FoldData",
    "crease_pattern_frame",
    "fold_dict",
    "motion_frames",
    "pattern_from_fold",
    "read_fold",
    "svg_text",
    "write_fold",
    "write_svg",
]
