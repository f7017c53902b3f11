"""Tolerances and defaults, in one place.

Every numerical threshold and every default design parameter of rigidfold lives in
:class:`Settings`. Library functions take a ``settings`` argument (default
:data:`DEFAULTS`) instead of scattering literals through the code.
"""

from __future__ import annotations

import contextlib
import functools
import math
import numbers
import threading
from dataclasses import dataclass, replace

from rigidfold.errors import RigidfoldError

HESSIANS = ("closed-form", "casadi")
"""The Hessians of the Lagrangian IPOPT can use (``Settings.ipopt_hessian``)."""

CHECKS = ("final", "all")
"""Which solutions of a generation run get the folding motion and Step 9 (``generate
--check``): the final design only (the default), or every solution."""

SIDES = ("bottom", "top")
"""The sides of the design surface that thick panels can lie on (``fabricate --side``):
below it (against the faces' normals, which point up) or above it."""

SEED_LIMIT = 2**63
"""Seeds (of Bezier surfaces, of generate's random draws) are integers 0 <= seed <
SEED_LIMIT: a study stores them as SQLite's signed 64-bit integers."""

DEFAULT_SEED = 0
"""The seed of a Bezier surface and of generate's random draws (hinge stiffnesses, the
random criterion's order) when none is given."""


def check_seed(seed, what: str = "seed") -> int:
    """``seed`` as an int. Raises ValueError ``"<what> must be a non-negative integer below
    2**63, got <seed>"`` for anything else (a bool, a float, a negative or too large number)."""
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise RigidfoldError(f"{what} must be a non-negative integer below 2**63, got {seed!r}")
    value = int(seed)
    if not 0 <= value < SEED_LIMIT:
        raise RigidfoldError(f"{what} must be a non-negative integer below 2**63, got {value}")
    return value


@dataclass(frozen=True)
class Settings:
    """Design parameters of problem (6) and the numerical tolerances of rigidfold.

    Design parameters (paper, Section 6.1)
    ---------------------------------------
    dz : float
        Bound on |z_i - f(x_i, y_i)| in metres (paper: 0.30 m).
    theta_min, theta_max : float
        Bounds on every sector angle in radians (paper: pi/6 and 2 pi/3).
    rho_bar : float or None
        Optional bound on |rho_j| of free creases, constraint (12), radians.
    f_tol : float
        A solution of (6) is accepted when F <= f_tol (paper: 1e-7).

    Generation (Steps 5-7)
    ----------------------
    zero_dof_ends : bool
        Step 5 of the paper: a solution of (6) whose mechanism has DOF 0 ends generation (it
        goes to Step 8; not counted in N_reduce, N_lock or N_exceed). ``False``: while the
        target DOF is >= 1, count it as a lock and try the next candidate (Step 7) instead,
        which reaches the target more often at the price of more solves.

    Tolerances
    ----------
    constraint_tol : float
        Largest accepted violation of any constraint of (6) (metres or radians).
    ipopt_tol, ipopt_max_iter, ipopt_mu_strategy : float, int, str
        IPOPT's convergence tolerance, iteration limit and barrier-parameter strategy.
    ipopt_hessian : str
        IPOPT's Hessian of the Lagrangian: "closed-form" (element Hessians assembled with
        NumPy, ``rigidfold.optimize.hessian``) or "casadi" (CasADi's symbolic Hessian, the
        reference it is tested against). Both are exact; they differ by round-off.
    projection_vertices : int
        From this many vertices on, the IPOPT solver of (6) first tries the projection onto
        F = 0 (:mod:`rigidfold.optimize.projection`) from the start; when that does not
        converge, IPOPT runs and stops at the first feasible iterate with F <= ``ipopt_stop_f``,
        which the projection then finishes. Smaller patterns (the paper's, up to 121
        vertices) run IPOPT alone, as before.
    projection_tol, projection_max_iter, projection_damping : float, int, float
        The projection converges at F <= ``projection_tol``, stops after
        ``projection_max_iter`` factorisations, and starts with the damping
        ``projection_damping`` times |r| times the largest diagonal entry of J J^T.
    projection_margin : float
        How far inside its bound the projection holds a constraint of (6) that blocked one of
        its steps (radians for sector angles, metres for dz, the cosine for (12)).
    ipopt_stop_f : float
        F at which IPOPT hands over to the projection on patterns of ``projection_vertices``
        or more (far below ``f_tol``, so that the projection starts near a zero of F); a
        projection that stops at a feasible point this close to F = 0 is taken without IPOPT.
    slsqp_ftol, slsqp_max_iter : float, int
        SciPy SLSQP's stopping tolerance and iteration limit.
    degenerate_area : float
        A triangle whose area is below ``degenerate_area * (longest edge)**2`` is degenerate.
    corner_angle : float
        A boundary vertex is a corner when the boundary turns there by more than this (radians).
    flat_angle : float
        A free crease with |rho| below this (radians) is flat ("F" in FOLD files).
    max_json_depth : int
        Deepest nesting of lists and objects accepted in a JSON file read (FOLD files, a run's
        summary.json) or data written as JSON: a deeper document is refused with a one-line
        error instead of exhausting Python's recursion limit (FOLD data nests 4 levels,
        rigidfold's own files about 10).
    max_coordinate : float
        Largest |coordinate| in metres accepted in a FOLD file and a target mesh (1000 km),
        and largest width or height of a crease pattern's plan: larger values are refused
        before any geometry is computed on them, where they would overflow.
    triangulation_area_tol : float
        Triangulation of the polygon faces of FOLD and SVG files: a polygon is refused as
        degenerate when a triangle of it has a doubled signed area below this times the
        squared size of the polygon (the larger side of its bounding box, in its plane).
    svg_merge_tol : float
        Crease patterns drawn in SVG (:func:`rigidfold.io.read_svg`): points closer than this
        times the diagonal of the drawing's bounding box are one vertex, a line that ends
        within it of another line ends on it, and a line shorter than it is dropped. Round-off
        of drawing programs (about 1e-3 px) lies far below the default; Origami Simulator
        merges within 3 px, 2e-4 to 1e-2 of its example drawings' diagonals, and a carelessly
        drawn pattern may need 1e-3, which would also merge real features of some designs.
    svg_snap_tol : float
        Crease patterns drawn in SVG: slips of the pen up to this times the diagonal of the
        drawing's bounding box are mended, where a crease would otherwise end on nothing
        (refused): an overshoot that far past the line a crease crosses is cut off, and a
        crease that ends that far short of a line is extended to it. Origami Simulator's own
        examples have slips of 4e-4 of their diagonals (its 3 px merge tolerance hides them);
        0 mends nothing. The command line's ``--svg-tolerance``.
    max_svg_depth : int
        Deepest nesting of elements accepted in an SVG drawing: a deeper file is refused with
        a one-line error before svgelements, which reads it recursively, exhausts Python's
        recursion limit (near 1,000 levels). Drawing programs nest groups a few levels deep.
    max_svg_pairs : int
        Largest number of pairs of line pieces of an SVG drawing that meet, cross or come
        within the merge distance (``svg_merge_tol``) of each other, each of which is looked
        at for a crossing or a T-junction: a drawing with more is refused in one line as
        soon as they are counted, before they are examined, instead of spending minutes and
        gigabytes (the pairs cost about 1 s and 100 MB a million; their crossings, when they
        cross, about ten times that). Pieces of one colour drawn over each other along one
        line are made one first and count once. A 110 x 110 grid of lines has 12,100
        crossings, a drawing of ``max_pattern_faces`` triangles some 10^5 pairs.
    max_svg_size : int
        Largest size of an SVG drawing, with each ``<use>`` element counted as what it
        refers to: the characters of its elements' attributes (path data, points,
        coordinates, styles) plus ``rigidfold.io.svg_read.ELEMENT_SIZE`` (100) per element.
        A larger drawing is refused in one line before svgelements, which copies what every
        ``<use>`` refers to, reads it (about 0.6 s per million: 55,000 lines drawn one by one
        are 6.2 million, 3.9 s). A file of 2 kB whose groups each use the one before twice
        expands 65,536-fold at 16 groups (49 s and 1.3 GB before); 13 groups are refused.
        Origami Simulator's largest example, huffmanWaterbomb.svg, is 32,075.
    plan_area_tol : float
        A sheet whose signed area in plan (its faces projected onto the xy plane) is within
        this fraction of its surface area of zero has no plan (a y-up file, a vertical sheet,
        a closed box, a flat-folded state): refused, since rigidfold needs z up. The same
        test refuses the triangle mesh of a target surface (``MeshSurface``).
    linear_rank_tol : float
        Relative threshold of the rank-revealing QR that eliminates constraints (7)-(9).
    map_prune_tol : float
        Entries of the variable map below this magnitude are dropped as round-off.
    symmetry_match_tol : float
        Distance (metres) within which a mirrored vertex must land on another vertex.
    develop_tol : float
        IPOPT tolerance of problem (13); tighter than ``ipopt_tol`` so that a flat pattern
        develops onto itself to about 1e-10.
    overlap_area_tol : float
        Two facets of a development diagram overlap when their intersection is larger than
        this fraction of the smaller one's area.
    mechanism_rank_tol : float
        Singular values below this times the largest one count as zero (rank of S, Eq. 16);
        in the kinematic and sparse analyses, the diagonal of the pivoted QR, and the Ritz
        values, below this times the largest row norm of the constraint matrix (sqrt 2, the
        row of an edge's length).
    sparse_analysis_vertices : int
        ``analyze`` (and so ``generate``) takes the sparse method
        (:mod:`rigidfold.mechanism.sparse`) for patterns with at least this many vertices and
        the dense kinematic one below: the paper's patterns (up to 121 vertices) keep the
        dense reference, and their results to the last digit.
    sparse_shift : float
        delta of the sparse analysis's filter ``(C^T C + delta I)^-1``: directions of
        singular value s with s^2 << delta pass it like the kernel (all those within reach of
        ``mechanism_rank_tol``), the others are damped by about delta / s^2 per solve. Ten
        times the round-off of C^T C (about 1e-15); small enough that two solves damp every
        direction with s > 1000 sqrt(delta) = 1e-4 below 1e-12 (a solved 31 x 31 grid has
        some fifteen singular values between 1e-6 and 3e-4 beside its kernel).
    sparse_oversampling : int
        Columns of the sparse analysis's subspace beyond the expected DOF; the subspace
        doubles while fewer than half of them are damped below 1e-12 of the kernel's share.
    sparse_iterations : int
        Solves with the filter per subspace: each multiplies the share of a direction of
        singular value s by about delta / s^2; two leave the modes less than about 1e-12 of
        every direction with s > 1000 sqrt(delta), far below ``lock_tol``.
    lock_tol : float
        A free crease is locked when the norm of its rotations over all modes is below this
        times the largest such norm (and its triangles are not coplanar).
    lookahead_tol : float
        Look-ahead (``generate(..., lookahead=True)``, :mod:`rigidfold.selection.lookahead`):
        fixing a candidate is predicted to lock a folded free crease when the crease keeps,
        in the first-order mechanisms left after the fix, rotations of norm at most this
        times the largest any free crease keeps: the ``lock_tol`` test applied before the
        solve. At ``lock_tol`` (the default) the forecast is the analysis of the fixed shape
        at the same geometry; a larger value also skips candidates that leave a crease
        nearly still.
    lookahead_carry_angle : float
        Look-ahead, once every candidate not forecast to lock has failed: a candidate whose
        forecast locks only creases that its fix carries to within this angle of flat
        (radians; first order: their fold angles plus their rotations along the smallest
        mechanism motion that flattens the candidate) is fixed together with them, as one
        group (a degree-4 vertex closing flat). Fixed creases are forced flat, so the group
        asks only what fixing the candidate alone would do, less the lock.
    lock_prediction_tol : float
        After multiplying K_j by 1e14, a hinge whose rotations outside the stiffest mode fall
        below this fraction of its rotations before is predicted locked (Section 4.2).
    hinge_stiffness, hinge_stiffness_spread : float
        Fictitious hinge stiffnesses K_j are uniform in this mean +/- spread, Nm (Section 6.1).

    Large-deformation check (Step 9, paper Section 6.1) and folding motion
    ----------------------------------------------------------------------
    tube_diameter, tube_wall : float
        Outside diameter and wall thickness of the frame's tubular beams, metres (20 mm, 1 mm).
    youngs_modulus, poisson_ratio : float
        Beam material, Pa and - (200 GPa, 0.3).
    deform_steps : int
        Load steps from the folded shape to the plane.
    deform_max_halvings : int
        A load step that does not converge is retried with half the increment this many times.
    deform_tol, deform_max_iter : float, int
        Newton convergence: norm of the displacement increment (metres) and iteration limit.
    plane_tol : float
        The plane is reached when every frame node ends within this distance (m) of z = 0.
    motion_frames : int
        Frames of the folding motion from flat to the designed shape.
    motion_length_tol : float
        A shape whose development diagram misses its edge lengths by more than this
        (relative) is not developable for the folding motion's verdict (``deform.compare``).
    deform_penalty : float
        Penalty factor of the pins of the frame model (OpenSees ``Penalty`` handler), times
        E A / (mean edge length).
    deform_load_tol : float
        The analysis has reached the plane when the load factor is within this of 1.

    Structure under load (``rigidfold structure``, ``rigidfold.structure``)
    ---------------------------------------------------------------------
    structure_thickness : float
        Panel thickness, metres (18 mm: a common plywood sheet).
    structure_material : str
        The panels' material preset (``rigidfold.structure.MATERIALS``).
    structure_hinge_stiffness : float
        Rotational stiffness of a free crease's hinge, N m/rad per metre of crease (0: free).
    structure_subdivisions : int
        Each triangle of the pattern is divided into this squared shell elements.
    structure_limit : float
        Serviceability: the largest displacement may be at most span / this (L/250).
    structure_gravity : float
        Acceleration of gravity for the self-weight, m/s^2.
    structure_modes : int
        Natural frequencies computed (0: none).
    structure_steps, structure_max_halvings : int
        Load steps of the geometrically nonlinear analysis, and how often a step that does
        not converge is halved before it stops.
    structure_tol, structure_max_iter : float, int
        Newton convergence of the static analysis: norm of the displacement increment (m)
        and iteration limit.
    structure_soft_modes : float
        Motions of the design whose singular value of the kinematic constraint matrix (rows
        of unit norm) is at most this fraction of the largest are free motions that the
        supports must hold (the rigid-body motions, the mechanisms, and the near-mechanisms
        of nearly flat vertices), ``rigidfold.structure.supports``.
    structure_rigidity_tol : float
        The supports make the design first-order rigid when the smallest eigenvalue of the
        stiffness on those motions (their own, sigma^2, plus the supports', rows of unit
        norm) exceeds this.
    structure_max_support_sets : int
        ``--supports auto`` tries every set of this many candidate sets or fewer of one size
        (the smallest that can be rigid first); more, and it searches greedily.
    structure_ground_tol : float
        ``--support-candidates ground``: boundary vertices within this (m) of the lowest
        boundary vertex's height.
    structure_balance_tol : float
        A static answer whose reactions miss the loads by more than this share of them did
        not carry the load (0.1 %: a singular stiffness).
    structure_prestress_tol : float
        Second order (``rigidfold.structure.stability``): the supports are prestress stable
        when the smallest eigenvalue of the best self-stress's stress matrix on the flexes
        exceeds this fraction of the stress matrices' largest entry; stress matrices below
        this fraction of the largest are dropped.
    structure_prestress_cuts : int
        Cutting planes (linear programs) of the search for that self-stress.
    structure_flex_step, structure_flex_tol : float
        A flex is a finite mechanism when the design moved this many mean edge lengths along
        it is corrected (at right angles, Gauss-Newton, ``structure_max_iter`` iterations)
        to meet every constraint within this fraction of the mean edge length.

    Rigid-folding path (``rigidfold.mechanism.path``, Step 5 beyond the paper)
    -------------------------------------------------------------------------
    path_flat_tol : float
        The path reaches the flat state when every free crease's fold angle is within this
        of 0, radians (0.5 degrees).
    path_fold_limit : float
        The path ends where a crease folds to this, radians (179 degrees): its panels meet.
    path_tol : float
        Corrector tolerance: norm of the constraint residual (edge lengths in mean edge
        lengths, fold angles in radians) at every traced point.
    path_step, path_max_step, path_min_step : float
        First, largest and smallest continuation step: the root-mean-square displacement of
        the vertices, in mean edge lengths.
    path_max_fold_step : float
        Largest change of any fold angle in one continuation step, radians (5 degrees): the
        traced points resolve the motion.
    path_max_steps : int
        Accepted steps of one direction of the trace before it gives up.
    path_corrector_iter, path_contraction : int, float
        Chord iterations of the corrector, and the largest ratio of successive corrections
        it accepts (a step that converges more slowly is halved).
    path_turn_back : float
        A 1-DOF path turns back (the shape does not deploy along it) when its folding
        measure, having fallen, rises this much (a fraction of the design's) above its lowest.
    path_max_turn : float
        Largest angle, radians, between the tangent and the chord of one step (DOF 1).
    path_regularization, path_damping : float
        Diagonal added to the constraint block of the KKT systems (self-stressed rows), and
        to the fold-angle metric of the Gauss-Newton direction (DOF > 1).
    path_stall_steps, path_stall_ratio : int, float
        With DOF > 1 the path stops short when this many steps in a row each lower the
        folding measure by less than this fraction (of its lowest so far).
    path_wander_steps : int
        With DOF 1 the path stops short when this many steps in a row bring the folding
        measure no lower (by ``path_stall_ratio``) than its lowest so far.
    polish_tol : float
        Before the deployability check, an accepted solution is projected onto F = 0 to this
        F (:meth:`rigidfold.optimize.FormFindingProblem.polish`): developable to round-off.
    deploy_max_candidates : int
        Step 7 gives up on a shape once this many of its candidates gave solutions whose
        folding paths do not reach the flat state (``Stop.NO_DEPLOYABLE``; 0: it tries them
        all): every candidate costs a solve and a trace, and a shape whose first candidates
        all fail rarely has a deployable one further down the ranking.
    deploy_check_max_dof : int
        The deployability check runs on accepted solutions of at most this DOF or the target
        DOF, whichever is larger (0: on every solution). A run that does not reach the target
        names the lowest-DOF solution that deploys as its final design.

    Crease patterns (``rigidfold.patterns``)
    ----------------------------------------
    mesh_divisions : float
        Default target edge length of a ``mesh:`` pattern: sqrt(footprint area) divided by
        this (0.5 m on the paper's 3 m x 3 m square, the spacing of pattern 1).
    mesh_angle_cap : float
        A ``mesh:`` triangulation asks for no plan angle below min(theta_min, this), radians
        (33 degrees: Triangle's quality refinement usually fails to end above 34 degrees).
    footprint_min_gap : float
        Smallest distance between two points of a ``mesh:`` footprint, or between a point
        and a side it is not on, as a fraction of the larger side of its bounding box (its
        minimum clearance): a closer one is refused, since Triangle's refinement toward it
        runs away (a gap of 1e-30 of the size crashed it; 1e-15 still ends).
    dz_bound_tol : float
        The report of a run flags a final design whose largest |z - target| is within this
        fraction of ``dz`` of the bound (the constraint is active: the design is as far from
        the target as ``dz`` allows).
    unit_warning_size : float
        A plan with a side of at least this many metres (1 km), or a ``dz`` larger than the
        plan's larger side, gets a warning that the sizes look like millimetres
        (:attr:`rigidfold.case.Case.warnings`: ``--size 3000x3000`` is a 3 km plan).
    theta_far_share : float
        A crease pattern whose initial shape (its plan lifted onto the target) has more than
        this share of its sector angles far outside [theta_min, theta_max] (below
        theta_min / 2 or above (theta_max + 180 degrees) / 2) is refused before any problem is
        built: the solver cannot bring that many slivers inside the bounds, and a solve from
        there ends at collapsed triangles (Origami Simulator's hypar.svg: a third of its
        angles under 15 degrees). A few are brought inside (huffmanWaterbomb.svg: 8 of 2418
        under 1 degree, converged); 1 checks nothing.
    min_pattern_size : float
        Smallest larger side (metres) of a crease pattern's plan (1 mm): the solvers'
        tolerances are absolute (``f_tol``, ``dz``), and on a smaller plan (a file read in the
        wrong unit) problem (6) is met trivially or its derivatives underflow to NaN.
    max_pattern_faces : int
        Largest number of triangles a crease pattern (``--pattern``) may have: a typo such as
        ``grid:1500x900`` is refused instead of building a problem that cannot be solved. A
        ``mesh:`` pattern's is estimated from its footprint area and edge length and from
        the points on its outline before Triangle runs, and counted after; an SVG drawing's
        is counted before its faces are triangulated, a FOLD file's once read: each is
        refused before any problem is built.
    max_analysis_bytes : int
        Largest memory (bytes) the mechanism analysis may ask for, estimated from the
        pattern's size for the method it runs before any matrix is built
        (:func:`rigidfold.mechanism.analysis.analysis_memory`: the dense matrices of the
        kinematic or frame method, the subspace and sparse factor of the sparse one); a
        larger shape (any FOLD file given to ``analyze``) is refused in one line instead of
        running out of memory.

    Studies (``rigidfold.study``)
    -----------------------------
    max_study_runs : int
        Largest number of runs (surfaces x patterns x criteria) a Bezier study may plan: a
        typo such as ``--surfaces 1000000000`` is refused at once instead of spending minutes
        and gigabytes listing runs that could never finish.

    Target surfaces from triangle meshes (``rigidfold.surfaces.MeshSurface``)
    -------------------------------------------------------------------------
    surface_grid_nodes : int
        The mesh is sampled by vertical ray casting at this many grid nodes along the longer
        side of its plan box (along the shorter side at the same spacing, at least 4), and a
        bicubic spline is fitted to the samples: 65 nodes are 47 mm apart on a 3 m box. From
        4 to 513 (a finer grid costs seconds and gigabytes to fit). A grid finer than the
        mesh's triangles makes the spline follow their facets; a coarser one smooths them.
    max_mesh_triangles : int
        Largest number of triangles of a target mesh (``--surface mesh:FILE``): a larger one
        is refused in one line (a binary STL file from its header, before it is loaded)
        instead of spending minutes and gigabytes. The surface is sampled on at most 513 x 513
        grid nodes, about 263,000: a mesh of twice as many triangles is finer than any fit
        can use (decimate it). A polygon face of an OBJ file counts as the triangles of its
        fan.
    surface_footprint_tol : float
        A plan point within this fraction of the longer side of the mesh's plan box of its
        footprint (its triangles seen from above) counts as inside it: pattern vertices
        farther out are refused (``MeshSurface.check_finite``).

    Thick panels (``rigidfold fabricate``, :mod:`rigidfold.fabricate`)
    ----------------------------------------------------------------
    fabricate_side : str
        Which side of the design surface the solids lie on: ``"bottom"`` (below it, against
        the faces' normals, which point up: the surface is the outer skin) or ``"top"``.
    fabricate_clearance_angle : float
        Every solid is bevelled along each hinge so that the two solids stay apart up to the
        crease's largest fold over the motion plus this angle, radians (2 degrees).
    fabricate_clearance : float
        Smallest gap, metres, that solids of panels without a common hinge keep at every
        point of the motion (1 mm).
    fabricate_vertex_relief : float
        Where panels without a common hinge meet at a vertex, every solid's corner there is
        cut off at this many thicknesses from the vertex (a relief; the hinges end there).
    fabricate_relief_rounds : int
        Where two such panels still come closer than ``fabricate_clearance`` near a shared
        vertex, the relief there is doubled and the check run again, this many times at most.
    fabricate_frame_step : float
        Largest change of a hinge's fold angle, radians, between two frames of the motion
        that are checked (2 degrees): the design file's motion frames when they
        are that fine, else the traced folding path sampled that finely.
    fabricate_subdivisions : int
        Between two frames, the motion is halved at most this many times where the bound on
        the gap between two solids does not yet prove the clearance.
    fabricate_min_depth : float
        A panel is too thin when its solid is nowhere this share of the thickness deep (its
        bevels meet above it); ``fabricate --min-thickness`` gives the length itself.
    fabricate_trimmed_away : float
        A panel is trimmed away when its solid keeps less than this share of its area times
        the thickness, or one of its triangles keeps nothing.
    fabricate_density : float
        Density of the panels' material, kg/m^3, for their masses (600: plywood).
    fabricate_sheet_width, fabricate_sheet_height : float
        Stock sheet, millimetres, that the cut sheets are nested onto (2440 x 1220).
    fabricate_sheet_gap : float
        Gap between parts and from the stock sheet's edge, millimetres.
    fabricate_thickness_tries : int
        When a thickness fails, thinner ones (halving, then bisection) are tried this many
        times to name one that passes.
    """

    # design parameters of problem (6)
    dz: float = 0.30
    theta_min: float = math.pi / 6
    theta_max: float = 2 * math.pi / 3
    rho_bar: float | None = None
    f_tol: float = 1e-7
    # generation procedure (Steps 5-7)
    zero_dof_ends: bool = True
    # solver tolerances
    constraint_tol: float = 1e-8
    ipopt_tol: float = 1e-8
    ipopt_max_iter: int = 500
    ipopt_mu_strategy: str = "adaptive"
    ipopt_hessian: str = "closed-form"
    projection_vertices: int = 200
    projection_tol: float = 1e-14
    projection_max_iter: int = 60
    projection_damping: float = 1e-3
    projection_margin: float = 1e-5
    ipopt_stop_f: float = 1e-9
    slsqp_ftol: float = 1e-12
    slsqp_max_iter: int = 1000
    # geometry tolerances
    degenerate_area: float = 1e-10
    corner_angle: float = math.radians(1.0)
    flat_angle: float = 1e-6
    linear_rank_tol: float = 1e-10
    map_prune_tol: float = 1e-13
    symmetry_match_tol: float = 1e-6
    # development diagram (Step 8)
    develop_tol: float = 1e-12
    overlap_area_tol: float = 1e-9
    # mechanism analysis
    mechanism_rank_tol: float = 1e-9
    sparse_analysis_vertices: int = 200
    sparse_shift: float = 1e-14
    sparse_oversampling: int = 12
    sparse_iterations: int = 2
    lock_tol: float = 1e-7
    lookahead_tol: float = 1e-7
    lookahead_carry_angle: float = math.radians(2.0)
    lock_prediction_tol: float = 1e-4
    hinge_stiffness: float = 1e-3
    hinge_stiffness_spread: float = 0.5e-6
    # large-deformation check (Step 9) and folding motion
    tube_diameter: float = 0.020
    tube_wall: float = 0.001
    youngs_modulus: float = 200e9
    poisson_ratio: float = 0.3
    deform_steps: int = 20
    deform_max_halvings: int = 6
    deform_tol: float = 1e-9
    deform_max_iter: int = 30
    plane_tol: float = 1e-6
    motion_frames: int = 11
    motion_length_tol: float = 1e-3
    deform_penalty: float = 1e6
    deform_load_tol: float = 1e-12
    # the structure under load
    structure_thickness: float = 0.018
    structure_material: str = "plywood"
    structure_hinge_stiffness: float = 0.0
    structure_subdivisions: int = 2
    structure_limit: float = 250.0
    structure_gravity: float = 9.81
    structure_modes: int = 3
    structure_steps: int = 10
    structure_max_halvings: int = 4
    structure_tol: float = 1e-8
    structure_max_iter: int = 20
    structure_soft_modes: float = 1e-2
    structure_rigidity_tol: float = 1e-6
    structure_max_support_sets: int = 100_000
    structure_ground_tol: float = 1e-3
    structure_balance_tol: float = 1e-3
    structure_prestress_tol: float = 1e-8
    structure_prestress_cuts: int = 200
    structure_flex_step: float = 0.05
    structure_flex_tol: float = 1e-10
    # rigid-folding path (Step 5, beyond the paper)
    path_flat_tol: float = math.radians(0.5)
    path_fold_limit: float = math.radians(179.0)
    path_tol: float = 1e-10
    path_step: float = 0.05
    path_max_step: float = 0.5
    path_min_step: float = 1e-7
    path_max_fold_step: float = math.radians(5.0)
    path_max_steps: int = 200
    path_corrector_iter: int = 8
    path_contraction: float = 0.5
    path_turn_back: float = 0.05
    path_max_turn: float = math.radians(30.0)
    path_regularization: float = 1e-12
    path_damping: float = 1e-9
    path_stall_steps: int = 5
    path_stall_ratio: float = 1e-4
    path_wander_steps: int = 40
    polish_tol: float = 1e-26
    deploy_check_max_dof: int = 1
    deploy_max_candidates: int = 30
    # reading FOLD files
    max_json_depth: int = 100
    max_coordinate: float = 1e6
    triangulation_area_tol: float = 1e-12
    # reading SVG drawings
    svg_merge_tol: float = 1e-4
    svg_snap_tol: float = 1e-2
    max_svg_depth: int = 100
    max_svg_pairs: int = 500_000
    max_svg_size: int = 8_000_000
    # crease patterns
    mesh_divisions: float = 6.0
    mesh_angle_cap: float = math.radians(33.0)
    footprint_min_gap: float = 1e-9
    theta_far_share: float = 0.05
    unit_warning_size: float = 1000.0
    dz_bound_tol: float = 1e-3
    min_pattern_size: float = 1e-3
    max_pattern_faces: int = 20000
    max_analysis_bytes: int = 8 * 2**30
    # studies
    max_study_runs: int = 1_000_000
    # target surfaces from triangle meshes
    surface_grid_nodes: int = 65
    surface_footprint_tol: float = 1e-5
    max_mesh_triangles: int = 500_000
    # the plan of a crease pattern
    plan_area_tol: float = 1e-6
    # thick panels (rigidfold fabricate)
    fabricate_side: str = "bottom"
    fabricate_clearance_angle: float = math.radians(2.0)
    fabricate_clearance: float = 1e-3
    fabricate_vertex_relief: float = 1.0
    fabricate_relief_rounds: int = 4
    fabricate_frame_step: float = math.radians(2.0)
    fabricate_subdivisions: int = 8
    fabricate_min_depth: float = 1.0
    fabricate_trimmed_away: float = 0.2
    fabricate_density: float = 600.0
    fabricate_sheet_width: float = 2440.0
    fabricate_sheet_height: float = 1220.0
    fabricate_sheet_gap: float = 10.0
    fabricate_thickness_tries: int = 8

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dz) and self.dz > 0):
            raise RigidfoldError(f"dz must be a positive number of metres, got {self.dz!r}")
        if not (0 < self.theta_min < self.theta_max < math.pi):
            raise RigidfoldError(
                "sector-angle bounds must satisfy 0 < theta_min < theta_max < 180 degrees, got "
                f"theta_min={math.degrees(self.theta_min):g}, "
                f"theta_max={math.degrees(self.theta_max):g} degrees"
            )
        if self.rho_bar is not None and not (0 < self.rho_bar < math.pi):
            raise RigidfoldError(
                f"rho_bar must lie in (0, 180) degrees, got {math.degrees(self.rho_bar):g}"
            )
        if not 0 <= self.theta_far_share <= 1:
            raise RigidfoldError(
                f"theta_far_share must lie in [0, 1], got {self.theta_far_share!r}"
            )
        if not self.f_tol > 0:
            raise RigidfoldError(f"f_tol must be positive, got {self.f_tol!r}")
        nodes = self.surface_grid_nodes
        if isinstance(nodes, bool) or not isinstance(nodes, int) or not 4 <= nodes <= 513:
            raise RigidfoldError(
                f"surface_grid_nodes must be an integer from 4 to 513, got {nodes!r}"
            )
        tol = self.surface_footprint_tol
        if not (math.isfinite(tol) and tol >= 0):
            raise RigidfoldError(f"surface_footprint_tol must be a finite number >= 0, got {tol!r}")
        for name in ("projection_tol", "projection_damping", "projection_margin", "ipopt_stop_f"):
            value = getattr(self, name)
            if not (isinstance(value, float | int) and math.isfinite(value) and value > 0):
                raise RigidfoldError(f"{name} must be a positive number, got {value!r}")
        for name in ("svg_merge_tol", "svg_snap_tol", "footprint_min_gap"):
            value = getattr(self, name)
            if not (isinstance(value, float | int) and 0 <= value < 1):
                raise RigidfoldError(f"{name} must be a fraction from 0 to below 1, got {value!r}")
        if not 0 < self.sparse_shift < 1:
            raise RigidfoldError(f"sparse_shift must lie in (0, 1), got {self.sparse_shift!r}")
        least = {
            "sparse_analysis_vertices": 3,
            "sparse_oversampling": 2,
            "sparse_iterations": 1,
            "projection_vertices": 3,
            "projection_max_iter": 1,
            "max_svg_depth": 1,
            "max_svg_pairs": 1,
            "max_svg_size": 1,
            "max_mesh_triangles": 1,
            "fabricate_relief_rounds": 0,
            "fabricate_subdivisions": 0,
            "fabricate_thickness_tries": 0,
        }
        for name, low in least.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise RigidfoldError(f"{name} must be an integer >= {low}, got {value!r}")
        if self.fabricate_side not in SIDES:
            raise RigidfoldError(
                f"fabricate_side must be one of {', '.join(SIDES)}, got {self.fabricate_side!r}"
            )
        if not 0 <= self.fabricate_clearance_angle < math.pi / 2:
            raise RigidfoldError(
                "fabricate_clearance_angle must lie in [0, 90) degrees, got "
                f"{math.degrees(self.fabricate_clearance_angle):g}"
            )
        for name in ("fabricate_clearance", "fabricate_vertex_relief", "fabricate_sheet_gap"):
            value = getattr(self, name)
            if not (isinstance(value, float | int) and math.isfinite(value) and value >= 0):
                raise RigidfoldError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in (
            "fabricate_frame_step",
            "fabricate_density",
            "fabricate_sheet_width",
            "fabricate_sheet_height",
        ):
            value = getattr(self, name)
            if not (isinstance(value, float | int) and math.isfinite(value) and value > 0):
                raise RigidfoldError(f"{name} must be a positive number, got {value!r}")
        for name in ("fabricate_min_depth", "fabricate_trimmed_away"):
            value = getattr(self, name)
            if not (isinstance(value, float | int) and 0 <= value <= 1):
                raise RigidfoldError(f"{name} must be a fraction from 0 to 1, got {value!r}")
        if self.ipopt_hessian not in HESSIANS:
            raise RigidfoldError(
                f"ipopt_hessian must be one of {', '.join(HESSIANS)}, got {self.ipopt_hessian!r}"
            )

    def with_(self, **changes) -> Settings:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    @classmethod
    def from_degrees(
        cls,
        *,
        theta_min_deg: float | None = None,
        theta_max_deg: float | None = None,
        rho_bar_deg: float | None = None,
        **kwargs,
    ) -> Settings:
        """Build settings with angles given in degrees (as on the command line); an angle
        that is None keeps its default (exactly, not through a round trip in degrees)."""
        angles = {"theta_min": theta_min_deg, "theta_max": theta_max_deg}
        for name, degrees in angles.items():
            if degrees is not None:
                kwargs[name] = math.radians(degrees)
        rho_bar = None if rho_bar_deg is None else math.radians(rho_bar_deg)
        return cls(rho_bar=rho_bar, **kwargs)


DEFAULTS = Settings()
"""The paper's parameters (Section 6.1) and rigidfold's default tolerances."""


_BLAS = threading.local()  # depth of one_blas_thread in this thread


@functools.cache
def _blas_limits():
    """threadpoolctl's ``threadpool_limits``, taught CasADi's own copy of OpenBLAS.

    IPOPT's MUMPS calls the OpenBLAS that CasADi ships as ``libcasadi-tp-openblas``, a name
    threadpoolctl does not know; registered here, ``one_blas_thread`` limits it too.
    """
    from threadpoolctl import OpenBLASController, register, threadpool_limits

    class CasadiOpenBLAS(OpenBLASController):
        filename_prefixes = ("libcasadi-tp-openblas",)

    register(CasadiOpenBLAS)
    return threadpool_limits


@contextlib.contextmanager
def one_blas_thread():
    """Context manager that runs the BLAS and LAPACK of NumPy, SciPy and IPOPT (MUMPS) on one
    thread.

    Problem (6) has no unique minimiser: F is zero on a family of developable shapes (as
    many directions as the mechanism has DOF), and round-off decides which one IPOPT
    reaches. A multi-threaded BLAS rounds differently for each thread count, so without
    this the same case could take another path on a machine with more cores, or in a shell
    rather than in a study worker (Dask starts workers with one thread); MUMPS inside IPOPT
    does too, from a 21 x 21 grid on. The matrices of the paper's patterns are small, so one
    thread costs no measurable time. Nested uses cost nothing: only the outermost one sets
    the limit (about 1 ms with threadpoolctl). Also a decorator, ``@one_blas_thread()``.
    ``benchmarks/blas_threads.py`` measures all of this.
    """
    depth = getattr(_BLAS, "depth", 0)
    _BLAS.depth = depth + 1
    try:
        if depth:
            yield
        else:
            with _blas_limits()(limits=1, user_api="blas"):
                yield
    finally:
        _BLAS.depth = depth
