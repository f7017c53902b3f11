"""Benchmark of thick panels (issue 31): ``rigidfold fabricate`` of an 11 x 11 design and of
the README's 12 m x 8 m roof.

Run with ``python benchmarks/bench_fabricate.py [--repeat 3] [--thickness 0.02 0.05]
[--design 11 roof] [--fold FILE ...]`` (``--fold``: also these FOLD designs, read as
``rigidfold fabricate`` reads them; ``--design`` with no name: only those).

Each design is generated first (not timed): ``11`` is the paper's pattern 11 (11 x 11
vertices, 3 m x 3 m) on the Bezier surface of seed 1 down to DOF 1 (S-hat, look-ahead, the
deployability check); ``roof`` is the README's barrel roof (``generate --pattern grid:9x6
--size 12x8 --surface expr --expr "0.06*x*(12-x)/6 + 0.05*y*(8-y)"``, S-hat, no
look-ahead). Then, per thickness, median over ``--repeat`` runs in this process: the folding
motion of the design (:func:`rigidfold.fabricate.design_motion`: the traced path sampled so
that no hinge turns more than ``fabricate_frame_step`` between frames), and the thick panels
with the check of every pair of solids over the whole motion
(:func:`rigidfold.fabricate.fabricate_panels`, no thinner tries: ``search=False``), then the
nesting of its cut sheets on the default stock (2440 x 1220 mm, 10 mm gap) by boxes
(:func:`rigidfold.fabricate.cutsheets.nest_boxes`, rectpack) and by true outlines
(:func:`rigidfold.fabricate.cutsheets.nest_by_outlines`) timed apart, and the sheets
:func:`rigidfold.fabricate.cutsheets.nest` keeps (not timed: it runs both). Target for the
11 x 11 design: motion and solids together under 10 s.
"""

from __future__ import annotations

import argparse

from bench_scale import timed  # this folder is on sys.path (a script)
from rigidfold.config import DEFAULTS
from rigidfold.develop import develop
from rigidfold.exports.design import read_design
from rigidfold.fabricate import Panels, design_motion, fabricate_panels
from rigidfold.fabricate.cutsheets import (
    Stock,
    nest,
    nest_boxes,
    nest_by_outlines,
    parts,
    sheets_summary,
)
from rigidfold.generate import generate
from rigidfold.generate.specs import case_from_specs

ROOF_EXPR = "0.06*x*(12-x)/6 + 0.05*y*(8-y)"
"""The README's 12 m x 8 m barrel roof."""

SHEET = (DEFAULTS.fabricate.sheet_width, DEFAULTS.fabricate.sheet_height)
GAP = DEFAULTS.fabricate.sheet_gap
"""The default stock sheet (mm) and gap (mm) the cut sheets are nested with."""


def design(name: str):
    """The final pattern of design ``name`` (see the module's text)."""
    if name == "11":
        run = generate(
            case_from_specs("bezier", "11", seed=1), criterion="shat", seed=1, lookahead=True
        )
    else:
        case = case_from_specs("expr", "grid:9x6", size="12x8", expr=ROOF_EXPR)
        run = generate(case, criterion="shat", lookahead=False)
    assert run.final is not None, name
    return run.final.result.pattern


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--thickness", type=float, nargs="+", default=[0.02])
    parser.add_argument("--design", nargs="*", choices=("11", "roof"), default=["11", "roof"])
    parser.add_argument(
        "--fold", nargs="+", default=[], metavar="FILE", help="also these FOLD designs"
    )
    args = parser.parse_args()
    for name in [*args.design, *args.fold]:
        if name in args.fold:
            read = read_design(name)
            pattern = read.pattern
            panels = Panels(pattern, read.coords2d, "bottom")
            t_motion, (motion, source) = timed(
                lambda p=panels, r=read: design_motion(p, r), args.repeat
            )
        else:
            pattern = design(name)
            panels = Panels(pattern, develop(pattern).coords2d, "bottom")
            t_motion, (motion, source) = timed(lambda p=panels: design_motion(p), args.repeat)
        assert motion is not None, source
        print(
            f"design {name} (V {pattern.n_vertices}, {panels.n} panels, {panels.n_hinges} "
            f"hinges), median of {args.repeat}:"
        )
        print(f"  motion          {t_motion:7.2f} s  ({motion.n_frames} frames: {source})")
        for t in args.thickness:
            t_fab, fab = timed(
                lambda p=panels, m=motion, t=t: fabricate_panels(p, m, t, search=False),
                args.repeat,
            )
            c = fab.clearance
            total = t_motion + t_fab
            print(
                f"  fabricate {t * 1e3:3g} mm {t_fab:7.2f} s  ({fab.status.value}; smallest gap "
                f"{c.min_gap * 1e3:.1f} mm, trimming loss {100 * fab.solids.trimming_loss:.2f}%, "
                f"{c.distance_queries} distance queries, {c.midpoints} midpoints, "
                f"{fab.relief_rounds} relief rounds)"
            )
            items = parts(fab)
            t_boxes, boxes = timed(lambda i=items: nest_boxes(i, Stock(*SHEET, GAP)), args.repeat)
            on_stock = {p.part.panel for s in boxes if not s.oversize for p in s.parts}
            fitting = [p for p in items if p.panel in on_stock]
            t_outlines, outlines = timed(
                lambda i=fitting: nest_by_outlines(i, Stock(*SHEET, GAP)), args.repeat
            )
            kept = sheets_summary(nest(items, Stock(*SHEET, GAP)))
            print(
                f"  nest      {t * 1e3:3g} mm boxes {t_boxes:5.2f} s ({len(on_stock)} parts on "
                f"{sum(not s.oversize for s in boxes)} sheets), outlines {t_outlines:5.2f} s "
                f"({len(outlines or ())} sheets); kept {kept['nested_by']}: "
                f"{kept['sheets']} sheets (+ {len(kept['oversize_panels'])} oversize)"
            )
            verdict = "met" if total < 10 else "NOT met"
            print(
                f"  total     {t * 1e3:3g} mm {total:7.2f} s"
                + (f"  (target < 10 s: {verdict})" if name == "11" else "")
            )


if __name__ == "__main__":
    main()
