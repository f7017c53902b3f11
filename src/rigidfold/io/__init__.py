"""File formats (FOLD 1.2 crease patterns, SVG drawings and crease patterns drawn in SVG) and
atomic output files."""

from rigidfold.io.files import (
    append_json_line,
    atomic_write,
    check_json_depth,
    inside_dir,
    jsonable,
    parse_json,
    prepare_output_dir,
    read_png,
    refuse_replacing_inputs,
    write_json,
)
from rigidfold.io.fold import UNITS, UP_AXES, FoldData, pattern_from_fold, read_fold
from rigidfold.io.fold_frames import (
    FRACTION_KEY,
    DesignFrames,
    crease_pattern_frame,
    crease_pattern_frames,
    motion_fraction,
    motion_frames,
    read_frames,
)
from rigidfold.io.fold_write import fold_dict, round_trip_dict, write_document, write_fold
from rigidfold.io.svg import svg_text, write_svg
from rigidfold.io.svg_read import SvgDrawing, read_svg

__all__ = [
    "FRACTION_KEY",
    "UNITS",
    "UP_AXES",
    "DesignFrames",
    "FoldData",
    "SvgDrawing",
    "append_json_line",
    "atomic_write",
    "check_json_depth",
    "crease_pattern_frame",
    "crease_pattern_frames",
    "fold_dict",
    "inside_dir",
    "jsonable",
    "motion_fraction",
    "motion_frames",
    "parse_json",
    "pattern_from_fold",
    "prepare_output_dir",
    "read_fold",
    "read_frames",
    "read_png",
    "read_svg",
    "refuse_replacing_inputs",
    "round_trip_dict",
    "svg_text",
    "write_document",
    "write_fold",
    "write_json",
    "write_svg",
]
