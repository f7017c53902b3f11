"""Settings of the checks of a design: its rigid-folding path, the large-deformation check
(Step 9) and folding motion, the structure under load and the thick panels."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigidfold.config.base import Group, setting
from rigidfold.errors import RigidfoldError

SIDES = ("bottom", "top")
"""The sides of the design surface that thick panels can lie on (``fabricate --side``):
below it (against the faces' normals, which point up) or above it."""


@dataclass(frozen=True)
class PathSettings(Group):
    """The rigid-folding path of a design (``rigidfold.mechanism.path``, Step 5 beyond the
    paper): a continuation from the design to the flat state."""

    PREFIX = "path_"

    flat_tol: float = setting(
        math.radians(0.5),
        "The path reaches the flat state when every free crease's fold angle is within this "
        "of 0, radians (0.5 degrees).",
    )
    collision_angle: float = setting(
        math.radians(179.0),
        "The path ends where a crease folds to this, radians (179 degrees): its panels meet.",
    )
    tol: float = setting(
        1e-10,
        "Corrector tolerance: norm of the constraint residual (edge lengths in mean edge "
        "lengths, fold angles in radians) at every traced point.",
    )
    step: float = setting(
        0.05,
        "First continuation step: the root-mean-square displacement of the vertices, in mean "
        "edge lengths.",
    )
    max_step: float = setting(0.5, "Largest continuation step (as ``path_step``).")
    min_step: float = setting(1e-7, "Smallest continuation step (as ``path_step``).")
    max_fold_step: float = setting(
        math.radians(5.0),
        "Largest change of any fold angle in one continuation step, radians (5 degrees): the "
        "traced points resolve the motion.",
    )
    max_steps: int = setting(
        1000,
        "Accepted steps of one direction of the trace before it gives up. A path along "
        "which the constraints keep a second near flex (a singular value near the rank "
        "threshold) is corrected by Newton's method at its linear rate, so its steps stay "
        "small: such paths of the paper's patterns reach the flat state in 200 to 800 steps "
        "(docs/deployability.md); a path that makes no progress ends sooner "
        "(``path_wander_steps``).",
    )
    corrector_iter: int = setting(8, "Chord iterations of the corrector.")
    contraction: float = setting(
        0.5,
        "Largest ratio of successive corrections the corrector accepts (a step that converges "
        "more slowly is halved).",
    )
    corrector_factorizations: int = setting(
        3,
        "A trace's corrector (all constraint rows) that would factorise its system more than "
        "this many times for one step gives the step up, and the trace halves it: from a "
        "prediction within Newton's reach the corrector converges after 1 or 2 (all but one "
        "of the 273 corrections that converged on four turned-back paths of "
        "``dome:polygamiCross``, which took 3), and the 223 that failed took 1205 of those "
        "traces' 1495 factorisations, most of them 5 to 9 each (docs/deployability.md, "
        "session 40). 0: no bound.",
    )
    turn_back: float = setting(
        1.0,
        "A 1-DOF path turns back (the shape does not deploy along it) when its folding "
        "measure, having fallen, rises this much (a fraction of the design's) above its "
        "lowest: by 1, it has gone further from the flat state than the design is. Below "
        "that, the trace goes on while it finds new lows (``path_wander_steps``): a 1-DOF "
        "path may fold some creases further before it unfolds (0.05 until session 37 "
        "rejected such a design of Origami Simulator's sharp-angled Miura-ori on the dome, "
        "whose measure rose 0.13 above its low on the way to the flat state; "
        "docs/broad_set.md).",
    )
    max_turn: float = setting(
        math.radians(30.0),
        "Largest angle, radians, between the tangent and the chord of one step (DOF 1).",
    )
    regularization: float = setting(
        1e-12,
        "Diagonal added to the constraint block of the KKT systems (self-stressed rows).",
    )
    damping: float = setting(
        1e-9, "Diagonal added to the fold-angle metric of the Gauss-Newton direction (DOF > 1)."
    )
    stall_steps: int = setting(
        5,
        "With DOF > 1 the path stops short when this many steps in a row each lower the "
        "folding measure by less than ``path_stall_ratio`` (of its lowest so far).",
    )
    stall_ratio: float = setting(
        1e-4,
        "A step that lowers the folding measure by less than this fraction of its lowest so "
        "far makes no progress (``path_stall_steps``, ``path_wander_steps``).",
    )
    pace_steps: int = setting(
        50,
        "With DOF > 1 the path's pace is the fall of the folding measure over this many "
        "steps (``path_pace_margin``).",
    )
    pace_margin: float = setting(
        2.0,
        "With DOF > 1 the path ends out of budget (``max_steps``) where, at its pace "
        "(``path_pace_steps``), the flat state lies more than this many times the steps left "
        "of ``path_max_steps`` away: a descent that creeps (every step lowers the measure a "
        "little, so it never stalls) would run out of steps anyway. On a Huffman waterbomb on "
        "the dome, two such traces of DOF 2 and 3 fell by 3.5e-4 of the design's measure a "
        "step and took 80 s each to end at 1000 steps, 31 % of the way (docs/deployability.md, "
        "session 35).",
    )
    wander_steps: int = setting(
        40,
        "With DOF 1 the path stops short when this many steps in a row bring the folding "
        "measure no lower (by ``path_stall_ratio``) than its lowest so far.",
    )
    reduce: bool = setting(
        True,
        "Where the projection continuation of a 1-DOF shape with self-stressed constraints "
        "stalls (near-singular values of the constraint Jacobian at the regularisation "
        "``path_regularization``, so its corrections are lost), drop the redundant rows "
        "there (a basis of the self-stresses from one dense SVD, the rows by a pivoted QR of "
        "it) and go on by pseudo-arclength continuation on the square system of the "
        "independent rows and the tangent, unregularised, with a Gauss-Newton corrector (the "
        "residual's part in the self-stresses is left, spread by least squares); where that "
        "stalls too, J's near flexes (``path_escape_tol``) are held and their near "
        "self-stresses' rows dropped as well (as where a trace of constraints without "
        "redundant rows stalls after its dense steps, ``path_escape_tol``). Every row is "
        "still met to ``path_tol``: where "
        "the least-squares residual exceeds it, the path stops short there. Up to "
        "``mechanism_second_order_vertices`` vertices.",
    )
    escape_tol: float = setting(
        1e-6,
        "Where the sparse continuation stalls (the step halved below ``path_min_step``: a "
        "singular or bifurcation point, where the regularised systems lose the corrections), "
        "the null space of the constraint Jacobian there is taken from a dense SVD: the "
        "singular values below this times the largest. The path continues along it (the last "
        "tangent's part in it, else the branches of the bifurcation equation in the plane of "
        "the two smallest singular vectors, else the part of the steepest descent of the "
        "folding measure), "
        "corrected by Gauss-Newton with the pseudo-inverse truncated at "
        "``mechanism_rank_tol`` to ``path_tol``; up to ``mechanism_second_order_vertices`` "
        "vertices.",
    )
    max_escapes: int = setting(
        5,
        "Dense steps past stalls (``path_escape_tol``) one direction of a trace may take: each "
        "costs a dense SVD and dense corrections (seconds at 200 vertices), and a path that "
        "stalls again after 5 rarely gets through (docs/deployability.md).",
    )

    def __post_init__(self) -> None:
        self._integer(pace_steps=1, corrector_factorizations=0)
        self._positive("pace_margin")


@dataclass(frozen=True)
class DeformationSettings(Group):
    """The large-deformation check (Step 9, paper Section 6.1: the frame of tubes pushed to
    the plane) and the folding motion."""

    PREFIX = "deform_"

    tube_diameter: float = setting(
        0.020,
        "Outside diameter of the frame's tubular beams, metres (20 mm).",
        flat="tube_diameter",
    )
    tube_wall: float = setting(
        0.001, "Wall thickness of the frame's tubular beams, metres (1 mm).", flat="tube_wall"
    )
    youngs_modulus: float = setting(
        200e9, "Young's modulus of the beams' material, Pa (200 GPa).", flat="youngs_modulus"
    )
    poisson_ratio: float = setting(
        0.3, "Poisson's ratio of the beams' material.", flat="poisson_ratio"
    )
    steps: int = setting(20, "Load steps from the folded shape to the plane.")
    max_halvings: int = setting(
        6, "A load step that does not converge is retried with half the increment this often."
    )
    tol: float = setting(1e-9, "Newton convergence: norm of the displacement increment (metres).")
    max_iter: int = setting(30, "Newton iteration limit of a load step.")
    penalty: float = setting(
        1e6,
        "Penalty factor of the pins of the frame model (OpenSees ``Penalty`` handler), times "
        "E A / (mean edge length).",
    )
    load_tol: float = setting(
        1e-12, "The analysis has reached the plane when the load factor is within this of 1."
    )
    plane_tol: float = setting(
        1e-6,
        "The plane is reached when every frame node ends within this distance (m) of z = 0.",
        flat="plane_tol",
    )
    motion_frames: int = setting(
        11,
        "Frames of the folding motion from flat to the designed shape.",
        flat="motion_frames",
    )
    motion_length_tol: float = setting(
        1e-3,
        "A shape whose development diagram misses its edge lengths by more than this "
        "(relative) is not developable for the folding motion's verdict (``deform.compare``).",
        flat="motion_length_tol",
    )


@dataclass(frozen=True)
class StructureSettings(Group):
    """The structure under load (``rigidfold structure``, :mod:`rigidfold.structure`)."""

    PREFIX = "structure_"

    thickness: float = setting(0.018, "Panel thickness, metres (18 mm: a common plywood sheet).")
    material: str = setting(
        "plywood", "The panels' material preset (``rigidfold.structure.MATERIALS``)."
    )
    hinge_stiffness: float = setting(
        0.0,
        "Rotational stiffness of a free crease's hinge, N m/rad per metre of crease (0: free).",
    )
    subdivisions: int = setting(
        2, "Each triangle of the pattern is divided into this squared shell elements."
    )
    limit: float = setting(
        250.0, "Serviceability: the largest displacement may be at most span / this (L/250)."
    )
    gravity: float = setting(9.81, "Acceleration of gravity for the self-weight, m/s^2.")
    modes: int = setting(3, "Natural frequencies computed (0: none).")
    steps: int = setting(10, "Load steps of the geometrically nonlinear analysis.")
    max_halvings: int = setting(
        4, "How often a nonlinear load step that does not converge is halved before it stops."
    )
    tol: float = setting(
        1e-8,
        "Newton convergence of the static analysis: norm of the displacement increment (m).",
    )
    max_iter: int = setting(
        20, "Newton iteration limit of the static analysis (and of the flex correction)."
    )
    soft_modes: float = setting(
        1e-2,
        "Motions of the design whose singular value of the kinematic constraint matrix (rows "
        "of unit norm) is at most this fraction of the largest are free motions that the "
        "supports must hold (the rigid-body motions, the mechanisms, and the near-mechanisms "
        "of nearly flat vertices), ``rigidfold.structure.supports``.",
    )
    sparse_vertices: int = setting(
        400,
        "The free motions of a design of more vertices (``rigidfold.structure.supports``) "
        "come from a sparse factorisation of C^T C (subspace iteration and Rayleigh-Ritz on "
        "C) instead of the dense singular value decomposition of C, whose time grows with "
        "the cube of the size (3 V x 3 V singular vectors).",
    )
    soft_shift: float = setting(
        1e-8,
        "The sparse free motions: delta of the filter ``(C^T C + delta s_max^2 I)^-1`` "
        "(s_max the largest singular value of C): each solve keeps a direction of singular "
        "value s with the factor ``delta / (s^2 / s_max^2 + delta)``.",
    )
    soft_iterations: int = setting(
        3,
        "The sparse free motions: solves with that filter (each followed by a QR) before "
        "the Rayleigh-Ritz step; the subspace doubles while the motions found leave fewer "
        "than half of ``mechanism_sparse_oversampling`` columns to spare.",
    )
    rigidity_tol: float = setting(
        1e-6,
        "The supports make the design first-order rigid when the smallest eigenvalue of the "
        "stiffness on those motions (their own, sigma^2, plus the supports', rows of unit "
        "norm) exceeds this.",
    )
    max_support_sets: int = setting(
        100_000,
        "``--supports auto`` tries every set of this many candidate sets or fewer of one size "
        "(the smallest that can be rigid first); more, and it searches greedily.",
    )
    service_max_pins: int = setting(
        50,
        "``--supports service`` adds at most this many pins to the rigid set of ``auto`` "
        "while the deflection exceeds the limit, one linear analysis each "
        "(:mod:`rigidfold.structure.service`).",
    )
    hint_hinge_stiffness: float = setting(
        1e6,
        "Where ``--supports service`` pins every candidate it may and still misses the "
        "deflection limit, the hinge stiffness (N m/rad per metre of crease) that would meet "
        "it on those pins is searched up to this (beyond it a hinge is a rigid joint) and "
        "named in the verdict.",
    )
    hint_iterations: int = setting(
        8,
        "Bisections, in log scale, of that search (8: the stiffness named within about 6 % "
        "of the least that meets the limit between the design's own and the largest).",
    )
    ground_tol: float = setting(
        1e-3,
        "``--support-candidates ground``: boundary vertices within this (m) of the lowest "
        "boundary vertex's height.",
    )
    balance_tol: float = setting(
        1e-3,
        "A static answer whose reactions miss the loads by more than this share of them did "
        "not carry the load (0.1 %: a singular stiffness).",
    )
    prestress_tol: float = setting(
        1e-8,
        "Second order (``rigidfold.mechanism.second_order``): the supports are prestress stable "
        "when the smallest eigenvalue of the best self-stress's stress matrix on the flexes "
        "exceeds this fraction of the stress matrices' largest entry; stress matrices below "
        "this fraction of the largest are dropped.",
    )
    prestress_cuts: int = setting(
        200, "Cutting planes (linear programs) of the search for that self-stress."
    )
    flex_step: float = setting(
        0.05,
        "A flex is a finite mechanism when the design moved this many mean edge lengths along "
        "it is corrected (at right angles, Gauss-Newton, ``structure_max_iter`` iterations) "
        "to meet every constraint within ``structure_flex_tol`` of the mean edge length.",
    )
    flex_tol: float = setting(
        1e-10,
        "A corrected flex meets every constraint within this fraction of the mean edge length "
        "(``structure_flex_step``).",
    )

    def __post_init__(self) -> None:
        self._integer(sparse_vertices=0, soft_iterations=1)
        self._positive("soft_shift")


@dataclass(frozen=True)
class FabricateSettings(Group):
    """Thick panels (``rigidfold fabricate``, :mod:`rigidfold.fabricate`)."""

    PREFIX = "fabricate_"

    side: str = setting(
        "bottom",
        'Which side of the design surface the solids lie on: ``"bottom"`` (below it, against '
        'the faces\' normals, which point up: the surface is the outer skin) or ``"top"``.',
    )
    clearance_angle: float = setting(
        math.radians(2.0),
        "Every solid is bevelled along each hinge so that the two solids stay apart up to the "
        "crease's largest fold over the motion plus this angle, radians (2 degrees).",
    )
    clearance_share: float = setting(
        0.05,
        "Smallest gap that solids of panels without a common hinge keep at every point of "
        "the motion, as a share of the thickness (5 %: 1 mm at 20 mm, 0.05 mm at 1 mm; "
        "never below ``fabricate_clearance_min``). The room two parts need to pass each "
        "other (cutting tolerance, a hinge's play, a panel's warp) grows with the panels, "
        "and the gaps the vertex reliefs open between such panels are a share of the "
        "thickness too (``fabricate_vertex_relief``), so a fixed length is out of scale "
        "(a fixed 1 mm was a whole relief at 1 mm of thickness, which no check can prove).",
    )
    clearance_min: float = setting(
        1e-5,
        "The least gap, metres, that solids of panels without a common hinge keep whatever "
        "the thickness (0.01 mm: about what a laser cutter or a CNC router holds; a gap "
        "below it cannot be made). It acts below 0.2 mm of thickness.",
    )
    thinnest: float = setting(
        1e-6,
        "The thinnest panels built, as a share of the design's size (the diagonal of its "
        "box): 1e-6, 1 um on a 1 m design, far below any sheet (paper is 100 um). The "
        "solids are computed in double precision next to the design's coordinates, and a "
        "slab much thinner than that share is not resolved (0.1 um on the 1.6 m A-frame, "
        "6e-8 of its size: its triangles' pieces vanish while the panels keep their whole "
        "volume), so a thinner thickness is refused and the thinner tries stop there.",
    )
    vertex_relief: float = setting(
        1.0,
        "Where panels without a common hinge meet at a vertex, every solid's corner there is "
        "cut off at this many thicknesses from the vertex (a relief; the hinges end there).",
    )
    relief_rounds: int = setting(
        4,
        "Where two such panels still come closer than the clearance (``clearance_share`` of "
        "the thickness, at least ``clearance_min``) near a shared vertex, the relief there "
        "is doubled and the check run again, this many times at most.",
    )
    frame_step: float = setting(
        math.radians(2.0),
        "Largest change of a hinge's fold angle, radians, between two frames of the motion "
        "that are checked (2 degrees): the design file's motion frames when they are that "
        "fine, else the traced folding path sampled that finely.",
    )
    frame_tol: float = setting(
        1e-6,
        "A design file's motion frames are used only as a rigid motion of the design from "
        "flat: every panel's vertices within this share of the design's size (the diagonal "
        "of its box) of their rigid motion, the last frame as close to the design, and the "
        "first flat (``path_flat_tol``); else the folding path is traced.",
    )
    subdivisions: int = setting(
        8,
        "Between two frames, the motion is halved at most this many times where the bound on "
        "the gap between two solids does not yet prove the clearance.",
    )
    min_depth: float = setting(
        1.0,
        "A panel is too thin when its solid is nowhere this share of the thickness deep (its "
        "bevels meet above it); ``fabricate --min-thickness`` gives the length itself.",
    )
    trimmed_away: float = setting(
        0.2,
        "A panel is trimmed away when its solid keeps less than this share of its area times "
        "the thickness, or one of its triangles keeps nothing.",
    )
    sheet_width: float = setting(
        2440.0, "Width of the stock sheet the cut sheets are nested onto, millimetres."
    )
    sheet_height: float = setting(
        1220.0, "Height of the stock sheet the cut sheets are nested onto, millimetres."
    )
    sheet_gap: float = setting(
        10.0, "Gap between parts and from the stock sheet's edge, millimetres."
    )
    nest_parts: int = setting(
        250,
        "The cut sheets are nested by the parts' true outlines (besides their boxes, the "
        "fewer sheets kept) where at most this many parts go on stock sheets: a bound on "
        "the time, which grows about as the parts times the sheets (each part is tried on "
        "every sheet so far; 163 parts on 5 sheets: 2-3 s).",
    )
    nest_pair_window: int = setting(
        16,
        "The cut sheets' pairing by boxes offers each part only to the parts that follow it "
        "in the order of their convex hulls' longest sides, this many at most: the pairing "
        "costs the parts times this, not the parts squared (before: every pair, 34 s and "
        "343 MB for 242 triangles).",
    )
    progress_panels: int = setting(
        200,
        "``rigidfold fabricate`` (and ``generate --thickness``) prints a line on stderr as "
        "each step that can take long begins (the path traced, the solids and their check, "
        "a thinner try, the nesting, the files) for designs of at least this many panels.",
    )
    nest_gap_sides: int = setting(
        8,
        "The true-outline nesting keeps the gap around a part by a regular polygon of this "
        "many sides (even) drawn round the gap's circle: the gap is kept, at most "
        "1/cos(180°/sides) - 1 of it wider at a corner (8: 8%).",
    )
    nest_margin: float = setting(
        1e-3,
        "The true-outline nesting keeps this much more than the gap, millimetres, against "
        "rounding.",
    )
    nest_concavity: float = setting(
        0.05,
        "The true-outline nesting takes a part whose convex hull exceeds its area by at most "
        "this share as that hull (a part more concave is cut into triangles).",
    )
    nest_round: float = setting(
        1e-3,
        "The true-outline nesting compares spots and areas rounded to this many millimetres "
        "(ties then go by the order of the turns and sheets), so that its result does not "
        "depend on floating-point noise.",
    )
    thickness_tries: int = setting(
        8,
        "When a thickness fails, thinner ones (halving, then bisection) are tried this many "
        "times to name one that passes.",
    )

    def clearance(self, thickness: float) -> float:
        """The smallest gap, metres, that solids of panels ``thickness`` metres thick and
        without a common hinge keep over the motion: ``clearance_share`` of the thickness,
        at least ``clearance_min``."""
        return max(self.clearance_share * thickness, self.clearance_min)

    def __post_init__(self) -> None:
        self._choice("side", SIDES)
        if not 0 <= self.clearance_angle < math.pi / 2:
            raise RigidfoldError(
                "fabricate_clearance_angle must lie in [0, 90) degrees, got "
                f"{math.degrees(self.clearance_angle):g}"
            )
        self._non_negative("clearance_share", "clearance_min", "vertex_relief", "sheet_gap")
        self._non_negative("nest_margin")
        self._non_negative("nest_concavity")
        self._positive("frame_step", "frame_tol", "sheet_width", "sheet_height", "nest_round")
        self._positive("thinnest")
        self._fraction("min_depth", "trimmed_away")
        self._integer(relief_rounds=0, subdivisions=0, thickness_tries=0, nest_parts=0)
        self._integer(nest_pair_window=1, progress_panels=0)
        self._integer(nest_gap_sides=4)
        if self.nest_gap_sides % 2:
            raise RigidfoldError(
                f"fabricate_nest_gap_sides must be even, got {self.nest_gap_sides}"
            )


@dataclass(frozen=True)
class DriveSettings(Group):
    """The drive that deploys a design under its own weight (``rigidfold deploy``,
    :mod:`rigidfold.drive`)."""

    PREFIX = "drive_"

    gravity: float = setting(
        9.80665, "Acceleration of gravity of the self-weight, m/s^2 (the standard value)."
    )
    max_step: float = setting(
        math.radians(1.0),
        "The motion is refined so that no crease turns more than this between two states, "
        "radians (1 degree): the derivatives along it are central differences of that step.",
    )
    max_turn: float = setting(
        math.radians(1.0),
        "Where the motion comes from the design file's frames, they are refined until the "
        "motion, a curve in the space of all vertex coordinates, turns no more than this "
        "from one chord to the next, radians (1 degree): near a bifurcation the path bends "
        "sharply while no hinge turns far (a 12 m x 8 m roof: 7 degrees between two states "
        "of 1 degree of hinge turn, the torque's differences flipping sign there).",
    )
    refine_tol: float = setting(
        1e-13,
        "Every state of the motion is corrected onto the rigid-folding constraints to this "
        "residual (edge lengths in mean edge lengths, fold angles in radians) where the "
        "constraints are square (pseudo-arclength, ``rigidfold.drive.motion.settle``), "
        "else to ``path_tol``: along a near flex of singular value sigma a residual r leaves "
        "a state anywhere within r / sigma, and the energy's differences between states "
        "wander with it (a 12 m x 8 m roof, sigma 1e-8: at ``path_tol`` the torque's sign "
        "flipped from one state to the next; the 722-panel waterbomb within half a degree "
        "of flat: 4 % off at 1e-7).",
    )
    hinge_stiffness: float = setting(
        0.0,
        "Rotational stiffness of every hinge, N m/rad per metre of crease (0: free), as "
        "``structure --hinge-stiffness``.",
    )
    friction: float = setting(
        0.0,
        "Coulomb friction torque of every hinge, N m per metre of crease (0: none); it resists "
        "the motion in both directions.",
    )
    hardware: float = setting(
        0.0, "Mass of the hinge hardware, kg per metre of hinge (at the hinge's midpoint)."
    )
    dead_fraction: float = setting(
        0.05,
        "A drive is at a dead point where its rate (the driven crease's turn, a cable's "
        "length change, per unit of s) falls below this share of its largest over the motion "
        "(its effort there beyond 1 / this times its typical one) or changes sign; its peak "
        "is taken away from those states.",
    )
    still_fraction: float = setting(
        1e-3,
        "A hinge (or cable) whose largest rate over the motion is below this share of the "
        "largest of all hinges does not move: it drives nothing (no peak, ranked last).",
    )
    pair_candidates: int = setting(
        30,
        "Where the best single crease has a dead point, the pairs of creases are searched "
        "among this many best creases of the ranking.",
    )
    auto_cables: int = setting(
        3, "``--cables auto`` names this many best pairs of boundary vertices as cables."
    )
    auto_cable_vertices: int = setting(
        200,
        "``--cables auto`` tries every pair of at most this many boundary vertices (evenly "
        "spread along the boundary where there are more): pairs cost their square.",
    )
    ground_tol: float = setting(
        1e-4,
        "A vertex is below the ground when it is more than this (m, 0.1 mm) under it.",
    )
    check_states: int = setting(
        5, "States along the motion at which the independent OpenSees check runs (>= 5)."
    )
    check_tolerance: float = setting(
        0.02,
        "The OpenSees check agrees when every held crease's reaction moment is within this "
        "share of the torque curve's peak of the torque there (2 %).",
    )
    check_subdivisions: int = setting(
        1,
        "Each triangle is divided into this squared shell elements in the OpenSees check "
        "(the reaction of a held crease of a mechanism does not depend on the mesh).",
    )
    check_spread: float = setting(
        0.25,
        "A state of the OpenSees check decides nothing where its reaction moment changes by "
        "more than this share of the tolerance (``drive_check_tolerance`` of the peak) when "
        "the held crease is made ten times stiffer: the moment does not depend on that "
        "stiffness, so the model is near singular (a near-mechanism besides the held one: "
        "on the demo's final design, whose constraints with the crease held have singular "
        "values of 1e-9 to 4e-9 of their largest, the two analyses gave -6 and -20, 104 and 2 "
        "N m where the curve has -26 and -31), and the built design is softer than its rigid "
        "motion.",
    )
    check_hold: float = setting(
        1e3,
        "The held crease of the OpenSees check is a rotational spring of this many times "
        "the panels' plate rigidity (E t^3 / 12 (1 - nu^2)) per metre of crease and mean "
        "edge length: the moment it carries does not depend on it (a mechanism held at one "
        "crease), its size keeps the hinge's turn small.",
    )

    def __post_init__(self) -> None:
        self._positive(
            "gravity",
            "max_step",
            "refine_tol",
            "check_tolerance",
            "check_spread",
            "check_hold",
        )
        self._non_negative("hinge_stiffness", "friction", "hardware", "ground_tol")
        self._fraction("dead_fraction", "still_fraction", below_one=True)
        self._integer(
            pair_candidates=2,
            auto_cables=0,
            auto_cable_vertices=2,
            check_states=5,
            check_subdivisions=1,
        )
