"""The paper's published results, kept as data for side-by-side reports.

Source: "Form generation of rigid origami for approximation of a curved surface based on
mechanical property of partially rigid frames", Section 6, Tables 5-8. Tables 5 and 6 average
100 random Bezier surfaces per crease pattern; Tables 7 and 8 are single runs (dome, HP) with
the criterion S on the 11 x 11 grid, with and without mirror symmetry. (The paper's Table 8 is
captioned "dome surface"; its text says it is the HP surface.)
"""

from __future__ import annotations

CITATION = (
    '"Form generation of rigid origami for approximation of a curved surface based on '
    'mechanical property of partially rigid frames", Section 6'
)

# (pattern, criterion) -> (N_reduce, N_lock, N_exceed, mean F)
TABLES_5_6 = {
    ("1", "s"): (20.00, 1.13, 0.04, 1.18e-9),
    ("1", "shat"): (20.00, 0.06, 0.01, 1.38e-9),
    ("1", "ss"): (19.97, 24.94, 0.03, 2.19e-9),
    ("1", "random"): (19.99, 7.32, 0.20, 2.44e-9),
    ("2", "s"): (19.96, 2.74, 0.00, 1.17e-9),
    ("2", "shat"): (19.97, 0.92, 0.02, 1.28e-9),
    ("2", "ss"): (19.73, 28.60, 0.14, 1.93e-9),
    ("2", "random"): (19.81, 13.32, 0.19, 4.41e-9),
}

TABLE_7_8_ROWS = (
    "N_lock",
    "N_exceed",
    "min DOF",
    "solves of (6)",
    "mean F",
    "mean D",
    "mean |dl| mm",
    "mean |drho_fix| deg",
)
# (preset, symmetric) -> values in TABLE_7_8_ROWS order
TABLES_7_8 = {
    ("dome", True): (1, 0, 3, 11, 1.42e-9, 1.13e-10, 0.793, 6.59e-2),
    ("dome", False): (1, 0, 1, 38, 2.78e-9, 5.89e-10, 1.09, 9.63e-2),
    ("hp", True): (0, 0, 3, 10, 2.60e-9, 1.08e-10, 0.279, 1.44e-2),
    ("hp", False): (0, 0, 1, 37, 1.72e-9, 9.18e-10, 0.286, 2.19e-2),
}
