"""Panel-Pin against the frame model: the smallest stiffness eigenvalue of a DOF-1 design
over its folding motion, in both models (the numbers of docs/structure.md).

Run with ``python benchmarks/panel_pin_trend.py``. For each design (tests/data/
dome_sym_dof1.fold, 11 x 11; tests/data/roof_12x8_dof1.fold, the README's 12 m x 8 m roof),
ten shapes of its traced rigid-folding path (10 % to 100 % folded): the frame model's
pseudo stiffness eigenvalue (rigidfold.mechanism, unit hinge stiffnesses) and Panel-Pin's
(tests/panel_pin.py: rigid panels, pins at the vertices, unit hinge springs, one panel
held), their Spearman rank correlation and the steps where they go different ways.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

TESTS = Path(__file__).resolve().parents[1] / "tests"
sys.path.insert(0, str(TESTS))

from rigidfold.io import read_fold  # noqa: E402
from test_panel_pin import trends  # noqa: E402


def main() -> None:
    for name in ("dome_sym_dof1.fold", "roof_12x8_dof1.fold"):
        pattern = read_fold(TESTS / "data" / name).pattern
        t0 = time.perf_counter()
        fraction, frame, panel = trends(pattern, 11)
        took = time.perf_counter() - t0
        print(f"{name} ({pattern.n_vertices} vertices), {took:.1f} s")
        print("  folded   frame model   Panel-Pin")
        for f, a, b in zip(fraction, frame, panel, strict=True):
            print(f"  {f:5.0%}    {a:.4g}       {b:.4g}")
        swaps = np.flatnonzero(np.sign(np.diff(frame)) != np.sign(np.diff(panel)))
        steps = ", ".join(f"{fraction[i]:.0%}->{fraction[i + 1]:.0%}" for i in swaps)
        print(
            f"  Spearman {spearmanr(frame, panel).statistic:.3f}; largest at "
            f"{fraction[np.argmax(frame)]:.0%} / {fraction[np.argmax(panel)]:.0%}, smallest at "
            f"{fraction[np.argmin(frame)]:.0%} / {fraction[np.argmin(panel)]:.0%}; steps that "
            f"go different ways: {steps or 'none'}"
        )


if __name__ == "__main__":
    main()
