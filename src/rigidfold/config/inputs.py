"""Settings of what rigidfold reads: crease patterns drawn or meshed, target surfaces from
triangle meshes, and the bounds that keep any input's cost in check."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigidfold.config.base import Group, setting
from rigidfold.errors import RigidfoldError


@dataclass(frozen=True)
class InputSettings(Group):
    """Reading crease patterns (SVG drawings, ``mesh:`` footprints, FOLD files) and target
    meshes (``rigidfold.surfaces.MeshSurface``)."""

    svg_merge_tol: float = setting(
        5e-4,
        "Crease patterns drawn in SVG (:func:`rigidfold.io.read_svg`): points closer than "
        "this times the diagonal of the drawing's bounding box are one vertex, a line that "
        "ends within it of another line ends on it, and a line shorter than it is dropped. "
        "Origami Simulator merges within 3 px, 2e-4 to 1e-2 of its example drawings' "
        "diagonals; the default joins the near misses of those drawn in Illustrator (lines "
        "that miss the points they are drawn to by 2.3e-4 to 3.8e-4: whirlpool.svg, "
        "huffmanRectangularWeave.svg, huffmanWaterbomb.svg), which 1e-4 (the default before) "
        "kept as slivers or as faces that cannot be triangulated, and lies far above "
        "round-off of drawing programs (about 1e-3 px). Features of a design closer than it "
        "(2 mm on a 3 m x 3 m sheet) are merged; a carelessly drawn pattern may need 1e-3, "
        "which would also merge real features of some designs.",
    )
    svg_snap_tol: float = setting(
        1e-2,
        "Crease patterns drawn in SVG: slips of the pen up to this times the diagonal of the "
        "drawing's bounding box are mended, where a crease would otherwise end on nothing "
        "(refused): an overshoot that far past the line a crease crosses is cut off, and a "
        "crease that ends that far short of a line is extended to it. Origami Simulator's own "
        "examples have slips of 4e-4 of their diagonals (its 3 px merge tolerance hides "
        "them); 0 mends nothing. The command line's ``--svg-tolerance``.",
    )
    mesh_divisions: float = setting(
        6.0,
        "Default target edge length of a ``mesh:`` pattern: sqrt(footprint area) divided by "
        "this (0.5 m on the paper's 3 m x 3 m square, the spacing of pattern 1).",
    )
    mesh_angle_cap: float = setting(
        math.radians(33.0),
        "A ``mesh:`` triangulation asks for no plan angle below min(theta_min, this), radians "
        "(33 degrees: Triangle's quality refinement usually fails to end above 34 degrees).",
    )
    footprint_min_gap: float = setting(
        1e-9,
        "Smallest distance between two points of a ``mesh:`` footprint, or between a point "
        "and a side it is not on, as a fraction of the larger side of its bounding box (its "
        "minimum clearance): a closer one is refused, since Triangle's refinement toward it "
        "runs away (a gap of 1e-30 of the size crashed it; 1e-15 still ends).",
    )
    theta_far_share: float = setting(
        0.05,
        "A crease pattern whose initial shape (its plan lifted onto the target) has more than "
        "this share of its sector angles far outside [theta_min, theta_max] (below theta_min "
        "/ 2 or above (theta_max + 180 degrees) / 2) is refused before any problem is built: "
        "the solver cannot bring that many slivers inside the bounds, and a solve from there "
        "ends at collapsed triangles (Origami Simulator's hypar.svg: a third of its angles "
        "under 15 degrees). A few are brought inside (huffmanWaterbomb.svg read with "
        "svg_merge_tol 1e-4: 8 of 2418 under 1 degree, converged; with the default none under "
        "21 degrees); 1 checks nothing.",
    )
    unit_warning_size: float = setting(
        1000.0,
        "A plan with a side of at least this many metres (1 km), or a ``dz`` larger than the "
        "plan's larger side, gets a warning that the sizes look like millimetres "
        "(:attr:`rigidfold.generate.case.Case.warnings`: ``--size 3000x3000`` is a 3 km plan).",
    )
    surface_grid_nodes: int = setting(
        65,
        "A target mesh is sampled by vertical ray casting at this many grid nodes along the "
        "longer side of its plan box (along the shorter side at the same spacing, at least "
        "4), and a bicubic spline is fitted to the samples: 65 nodes are 47 mm apart on a 3 m "
        "box. From 4 to 513 (a finer grid costs seconds and gigabytes to fit). A grid finer "
        "than the mesh's triangles makes the spline follow their facets; a coarser one "
        "smooths them.",
    )
    surface_footprint_tol: float = setting(
        1e-5,
        "A plan point within this fraction of the longer side of the mesh's plan box of its "
        "footprint (its triangles seen from above) counts as inside it: pattern vertices "
        "farther out are refused (``MeshSurface.check_finite``).",
    )

    def __post_init__(self) -> None:
        if not (isinstance(self.theta_far_share, float | int) and 0 <= self.theta_far_share <= 1):
            raise RigidfoldError(
                f"theta_far_share must lie in [0, 1], got {self.theta_far_share!r}"
            )
        nodes = self.surface_grid_nodes
        if isinstance(nodes, bool) or not isinstance(nodes, int) or not 4 <= nodes <= 513:
            raise RigidfoldError(
                f"surface_grid_nodes must be an integer from 4 to 513, got {nodes!r}"
            )
        tol = self.surface_footprint_tol
        if not (isinstance(tol, float | int) and math.isfinite(tol) and tol >= 0):
            raise RigidfoldError(f"surface_footprint_tol must be a finite number >= 0, got {tol!r}")
        self._fraction("svg_merge_tol", "svg_snap_tol", "footprint_min_gap", below_one=True)


@dataclass(frozen=True)
class LimitSettings(Group):
    """Bounds on the size of what rigidfold reads or builds: a larger input is refused in one
    line before it costs minutes or gigabytes."""

    max_json_depth: int = setting(
        100,
        "Deepest nesting of lists and objects accepted in a JSON file read (FOLD files, a "
        "run's summary.json) or data written as JSON: a deeper document is refused with a "
        "one-line error instead of exhausting Python's recursion limit (FOLD data nests 4 "
        "levels, rigidfold's own files about 10).",
    )
    max_coordinate: float = setting(
        1e6,
        "Largest |coordinate| in metres accepted in a FOLD file and a target mesh (1000 km), "
        "and largest width or height of a crease pattern's plan: larger values are refused "
        "before any geometry is computed on them, where they would overflow.",
    )
    min_pattern_size: float = setting(
        1e-3,
        "Smallest larger side (metres) of a crease pattern's plan (1 mm): the solvers' "
        "tolerances are absolute (``f_tol``, ``dz``), and on a smaller plan (a file read in "
        "the wrong unit) problem (6) is met trivially or its derivatives underflow to NaN.",
    )
    max_svg_depth: int = setting(
        100,
        "Deepest nesting of elements accepted in an SVG drawing: a deeper file is refused "
        "with a one-line error before svgelements, which reads it recursively, exhausts "
        "Python's recursion limit (near 1,000 levels). Drawing programs nest groups a few "
        "levels deep.",
    )
    max_svg_pairs: int = setting(
        500_000,
        "Largest number of pairs of line pieces of an SVG drawing that meet, cross or come "
        "within the merge distance (``svg_merge_tol``) of each other, each of which is looked "
        "at for a crossing or a T-junction: a drawing with more is refused in one line as "
        "soon as they are counted, before they are examined, instead of spending minutes and "
        "gigabytes (the pairs cost about 1 s and 100 MB a million; their crossings, when they "
        "cross, about ten times that). Pieces of one colour drawn over each other along one "
        "line are made one first and count once. A 110 x 110 grid of lines has 12,100 "
        "crossings, a drawing of ``max_pattern_faces`` triangles some 10^5 pairs.",
    )
    max_svg_size: int = setting(
        8_000_000,
        "Largest size of an SVG drawing, with each ``<use>`` element counted as what it "
        "refers to: the characters of its elements' attributes (path data, points, "
        "coordinates, styles) plus ``rigidfold.io.svg_xml.ELEMENT_SIZE`` (100) per element. "
        "A larger drawing is refused in one line before svgelements, which copies what every "
        "``<use>`` refers to, reads it (about 0.6 s per million: 55,000 lines drawn one by "
        "one are 6.2 million, 3.9 s). A file of 2 kB whose groups each use the one before "
        "twice expands 65,536-fold at 16 groups (49 s and 1.3 GB before); 13 groups are "
        "refused. Origami Simulator's largest example, huffmanWaterbomb.svg, is 32,075.",
    )
    max_pattern_faces: int = setting(
        20000,
        "Largest number of triangles a crease pattern (``--pattern``) may have: a typo such "
        "as ``grid:1500x900`` is refused instead of building a problem that cannot be solved. "
        "A ``mesh:`` pattern's is estimated from its footprint area and edge length and from "
        "the points on its outline before Triangle runs, and counted after; an SVG drawing's "
        "is counted before its faces are triangulated, a FOLD file's once read: each is "
        "refused before any problem is built.",
    )
    max_analysis_bytes: int = setting(
        8 * 2**30,
        "Largest memory (bytes) the mechanism analysis may ask for, estimated from the "
        "pattern's size for the method it runs before any matrix is built "
        "(:func:`rigidfold.mechanism.analysis.analysis_memory`: the dense matrices of the "
        "kinematic or frame method, the subspace and sparse factor of the sparse one); a "
        "larger shape (any FOLD file given to ``analyze``) is refused in one line instead of "
        "running out of memory.",
    )
    max_mesh_triangles: int = setting(
        500_000,
        "Largest number of triangles of a target mesh (``--surface mesh:FILE``): a larger one "
        "is refused in one line (a binary STL file from its header, before it is loaded) "
        "instead of spending minutes and gigabytes. The surface is sampled on at most 513 x "
        "513 grid nodes, about 263,000: a mesh of twice as many triangles is finer than any "
        "fit can use (decimate it). A polygon face of an OBJ file counts as the triangles of "
        "its fan.",
    )
    max_structure_bytes: int = setting(
        2 * 2**30,
        "Largest memory (bytes) the structure check (``rigidfold structure``) may ask for at "
        "once, estimated before it is asked: the shell model (about "
        "``rigidfold.structure.design.SHELL_BYTES`` per shell element) and the dense blocks "
        "of the supports' search (the free motions, 3 V x m, and the m x m stiffness on "
        "them, m growing as they are found: a flat sheet has a free motion per vertex). A "
        "larger design is refused in one line instead of running out of memory.",
    )
    max_structure_value: float = setting(
        1e12,
        "Largest magnitude of a number the structure check (``rigidfold structure``) takes, "
        "in SI units: the panels' thickness (m), Young's modulus (Pa), density (kg/m^3), "
        "the hinge stiffness (N m/rad per m) and each load (Pa of a uniform load or a "
        "pressure, N of a point load's components). A larger one is refused in one line; "
        "beyond it the analysis's products overflow (``--thickness 1e300``, ``--load "
        "uniform=1e300``: OverflowError before) or its figure has no finite axis.",
    )
    max_study_runs: int = setting(
        1_000_000,
        "Largest number of runs (surfaces x patterns x criteria) a Bezier study may plan: a "
        "typo such as ``--surfaces 1000000000`` is refused at once instead of spending "
        "minutes and gigabytes listing runs that could never finish.",
    )

    max_sheet_size: float = setting(
        100_000.0,
        "Largest width or height of a stock sheet for the cut sheets (``fabricate --sheet``), "
        "millimetres (100 m): a larger one is refused in one line before the nesting, whose "
        "coordinates would overflow (``--sheet 1e308x1e308``).",
    )
    max_fabricate_panels: int = setting(
        5000,
        "Largest number of panels ``rigidfold fabricate`` (and ``generate --thickness``) "
        "builds thick: a larger design is refused in one line before its solids are built. "
        "The solids, the check and the nesting grow about linearly with the panels (722 "
        "panels: under a minute, ``benchmarks/bench_fabricate_scale.py``).",
    )

    def __post_init__(self) -> None:
        self._integer(max_svg_depth=1, max_svg_pairs=1, max_svg_size=1, max_mesh_triangles=1)
        self._integer(max_fabricate_panels=1)
        self._positive("max_sheet_size")
        self._integer(max_structure_bytes=1)
        self._positive("max_structure_value")
