"""The broad set's cases (issue 49, item 7): patterns the search was never tuned on, each run as
``rigidfold generate`` with the same options (``benchmarks/broad_set.py`` runs them).

Six families, every seed written here or derived from the case's name (so adding a case
changes no other case), and no option chosen for one case: every run uses the command
line's defaults (criterion S-hat, target DOF 1, the fold-limit ladder, backtracking) with
``--lookahead --no-deform --time-limit 180``; a pattern's size and a surface's expression are
part of the case, as a user would give them.

``drawn``
    Every crease pattern of Origami Simulator in ``tests/data/origami_simulator/*.svg``
    (globbed: files added there join the set), each on the dome, the HP and a Bezier surface.
    A file the reader refuses, or whose initial shape ``generate`` refuses (sector angles far
    outside the bounds: a stated geometric reason of the method), is left out and listed by
    :func:`skipped`.
``perturbed``
    Tessellations of that folder (:data:`PERTURBED_BASES`) with their inner vertices moved in
    plan by a fixed random draw (:func:`perturbed_plan`): up to :data:`PERTURB_FRACTION` of
    the shortest crease at each vertex, every triangle kept counter-clockwise and every plan
    angle within the sector-angle bounds or a tenth of its room beyond. Written as FOLD
    files in metres (:func:`write_perturbed`) into the run's work folder.
``mesh``
    ``mesh:POLYGON`` footprints: random star-shaped polygons of 4 to 8 corners about 3 m
    across (:func:`random_polygon`), triangulated at the default edge length.
``grid``
    ``grid:NXxNY`` patterns of five vertex counts and plan sizes, each with every diagonal
    choice (centre, parallel, alternate).
``paper``
    The paper's patterns 1, 1p, 2 and 11 on Bezier surfaces of seeds outside the study's.
``building``
    Building-size patterns: the 15 x 9 roof of ``benchmarks/deploy_anywhere.py``, a 41 x 41
    grid on the dome, larger grids on the HP, Bezier and a barrel vault, an L-shaped
    ``mesh:`` footprint.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DRAWN_DIR = ROOT / "tests" / "data" / "origami_simulator"
SURFACES = ("dome", "hp", "bezier")
"""The built-in surfaces the drawn, perturbed, mesh and grid families are spread over."""

PERTURBED_BASES = (
    "miura-ori.svg",
    "waterbomb.svg",
    "reschTriTessellation.svg",
    "whirlpool.svg",
    "huffmanWaterbomb.svg",
    "langWedgeDoubleFaced.svg",
)
"""The tessellations of :data:`DRAWN_DIR` that the perturbed family moves."""
PERTURB_SEEDS = (11, 29)
"""Two perturbations of each base (the random draw of its vertices' offsets)."""
PERTURB_FRACTION = 0.12
"""Largest in-plane offset of a vertex, as a fraction of its shortest crease."""
PERTURB_ANGLE_KEPT = 0.9
"""A perturbed plan angle stays inside the design's sector-angle bounds [theta_min,
theta_max], or moves at most ``1 -`` this of its room toward 0 or 180 degrees."""

MESH_SEEDS = (3, 8, 14, 21, 27, 35, 42, 50, 57, 63, 71, 88)
"""One random footprint per seed; the seed is also the run's ``--seed``."""

GRID_SPECS = (
    ("grid:5x5", "3x3"),
    ("grid:7x7", "3x3"),
    ("grid:6x9", "3x4.5"),
    ("grid:9x9", "3x3"),
    ("grid:11x7", "4x2.5"),
)
"""The grid family's vertex counts and plan sizes (metres); each with every diagonal choice."""
GRID_DIAGONALS = ("centre", "parallel", "alternate")
GRID_SEEDS = (17, 4, 93, 58, 36, 71, 12, 85, 44, 29, 66, 7, 51, 90, 23)
"""One seed per grid case, in the order of :func:`grid_cases`."""

PAPER_PATTERNS = ("1", "1p", "2", "11")
PAPER_SEEDS = (1013, 2027)
"""Bezier seeds of the paper family: outside the study's seeds 0-99."""

ROOF_EXPR = "0.08*x*(12-x)/6 + 0.02*(y-4)**2 - 0.05*y"
"""The 12 m x 8 m roof of ``benchmarks/deploy_anywhere.py``: a barrel vault with a cross fall."""


@dataclass(frozen=True)
class BroadCase:
    """One case: what ``rigidfold generate`` is given besides the common options.

    name : str, unique, without commas (``--only`` splits on them), ``family/what/surface``;
    family : str, one of :data:`FAMILIES`;
    surface : str, ``--surface``; pattern : str, ``--pattern`` (for ``perturbed``: the base
    SVG, the FOLD file is made by :func:`write_perturbed`); seed : int, ``--seed``;
    size, expr, diagonals : ``--size``, ``--expr``, ``--diagonals`` or None;
    perturb_seed : int, the perturbation's random seed (``perturbed`` only).
    """

    name: str
    family: str
    surface: str
    pattern: str
    seed: int
    size: str | None = None
    expr: str | None = None
    diagonals: str | None = None
    perturb_seed: int | None = None

    def pattern_spec(self, work: Path) -> str:
        """The ``--pattern`` argument: a perturbed case's FOLD file in ``work`` (written when
        missing), otherwise :attr:`pattern`."""
        if self.perturb_seed is None:
            return self.pattern
        return str(write_perturbed(Path(self.pattern), self.perturb_seed, work))

    def cli_args(self, work: Path) -> list[str]:
        """The case's own arguments of ``rigidfold generate``."""
        args = ["--surface", self.surface, "--pattern", self.pattern_spec(work)]
        args += ["--seed", str(self.seed)]
        for flag, value in (
            ("--size", self.size),
            ("--expr", self.expr),
            ("--diagonals", self.diagonals),
        ):
            if value is not None:
                args += [flag, value]
        return args

    def make_case_kwargs(self, work: Path) -> dict:
        """The keywords of :func:`rigidfold.generate.specs.case_from_specs` that build this
        case's initial shape as the command line does (no solve)."""
        kwargs: dict = {"seed": self.seed, "expr": self.expr}
        if self.size is not None:
            kwargs["size"] = self.size
        if self.diagonals is not None:
            kwargs["diagonals"] = self.diagonals
        return {"surface": self.surface, "pattern": self.pattern_spec(work), **kwargs}


FAMILIES = ("drawn", "perturbed", "mesh", "grid", "paper", "building")

SAMPLE_40 = (
    "grid/11x7-parallel/hp",
    "grid/5x5-centre/dome",
    "grid/5x5-parallel/hp",
    "grid/6x9-parallel/hp",
    "grid/7x7-alternate/bezier",
    "grid/7x7-centre/dome",
    "grid/9x9-alternate/bezier",
    "grid/9x9-centre/dome",
    "mesh/poly4-r14/bezier",
    "mesh/poly4-r27/hp",
    "mesh/poly4-r42/dome",
    "mesh/poly4-r57/bezier",
    "mesh/poly8-r3/dome",
    "mesh/poly8-r71/hp",
    "paper/1/bezier:1013",
    "paper/1/bezier:2027",
    "paper/11/bezier:1013",
    "paper/1p/bezier:1013",
    "paper/2/bezier:1013",
    "paper/2/bezier:2027",
    "perturbed/huffmanWaterbomb-p11/bezier",
    "perturbed/langWedgeDoubleFaced-p11/hp",
    "perturbed/miura-ori-p11/dome",
    "perturbed/reschTriTessellation-p11/hp",
    "perturbed/waterbomb-p11/bezier",
    "perturbed/whirlpool-p11/dome",
    "drawn/6ptHypar-anti/dome",
    "drawn/MoosersTrainRigid-Gardner/bezier",
    "drawn/boatBase/hp",
    "drawn/cubeunwrapping/dome",
    "drawn/flat_crane/bezier",
    "drawn/huffmanExtrudedBoxes/hp",
    "drawn/huffmanWaterbomb/dome",
    "drawn/langHoneycomb/bezier",
    "drawn/langOvalTessellation/hp",
    "drawn/miura-ori/dome",
    "drawn/origamisimulator/bezier",
    "drawn/randlettflappingbird/hp",
    "drawn/simpleVertex/dome",
    "drawn/traditionalCrane/dome",
)
"""The sample of 40 cases measured since session 26 (``broad_set.py --only sample40``):
session 23's 26 of four families (perturbed tessellations, ``mesh:`` polygons, ``grid:``
patterns, the paper's patterns on other surfaces) and session 25's 14 drawn cases."""


def name_seed(text: str) -> int:
    """A seed derived from a case's name (CRC-32 mod 10000): fixed, and not chosen."""
    return zlib.crc32(text.encode("utf-8")) % 10000


def drawn_files() -> list[Path]:
    """Every SVG of :data:`DRAWN_DIR`, sorted by name."""
    return sorted(DRAWN_DIR.glob("*.svg"), key=lambda p: p.name)


def _drawn_candidates() -> list[BroadCase]:
    out = []
    for path in drawn_files():
        for surface in SURFACES:
            name = f"drawn/{path.stem}/{surface}"
            out.append(BroadCase(name, "drawn", surface, str(path), name_seed(name)))
    return out


def _perturbed_cases() -> list[BroadCase]:
    out = []
    k = 0
    for base in PERTURBED_BASES:
        path = DRAWN_DIR / base
        if not path.is_file():
            continue
        for pseed in PERTURB_SEEDS:
            surface = SURFACES[k % len(SURFACES)]
            k += 1
            name = f"perturbed/{path.stem}-p{pseed}/{surface}"
            out.append(
                BroadCase(
                    name, "perturbed", surface, str(path), name_seed(name), perturb_seed=pseed
                )
            )
    return out


def random_polygon(seed: int) -> np.ndarray:
    """A star-shaped simple polygon (N, 2) of 4 to 8 corners, about 3 m across, counter-
    clockwise, rounded to centimetres; its convex corners at least 50 degrees (a sharper one
    would leave slivers below theta_min). Drawn again from the same generator until it is."""
    rng = np.random.default_rng(seed)
    while True:
        n = int(rng.integers(4, 9))
        gaps = rng.uniform(0.6, 1.4, n)
        angles = np.cumsum(gaps / gaps.sum() * 2 * np.pi) + rng.uniform(0, 2 * np.pi)
        radii = rng.uniform(0.65, 1.0, n) * 1.6
        xy = np.round(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]), 2)
        xy -= xy.min(axis=0)
        if _corner_angles_ok(xy, np.radians(50.0)):
            return xy


def _corner_angles_ok(xy: np.ndarray, smallest: float) -> bool:
    prev, nxt = np.roll(xy, 1, axis=0) - xy, np.roll(xy, -1, axis=0) - xy
    cross = prev[:, 0] * nxt[:, 1] - prev[:, 1] * nxt[:, 0]
    cos = (prev * nxt).sum(axis=1) / (np.linalg.norm(prev, axis=1) * np.linalg.norm(nxt, axis=1))
    inner = np.arccos(np.clip(cos, -1.0, 1.0))
    convex = cross < 0  # counter-clockwise polygon: a convex corner turns left
    return bool((inner[convex] >= smallest).all())


def polygon_spec(xy: np.ndarray) -> str:
    """``mesh:x1,y1;x2,y2;...`` of a polygon in metres."""
    return "mesh:" + ";".join(f"{x:g},{y:g}" for x, y in xy)


def _mesh_cases() -> list[BroadCase]:
    out = []
    for k, seed in enumerate(MESH_SEEDS):
        xy = random_polygon(seed)
        surface = SURFACES[k % len(SURFACES)]
        name = f"mesh/poly{len(xy)}-r{seed}/{surface}"
        out.append(BroadCase(name, "mesh", surface, polygon_spec(xy), seed))
    return out


def _grid_cases() -> list[BroadCase]:
    out = []
    k = 0
    for spec, size in GRID_SPECS:
        for diagonals in GRID_DIAGONALS:
            surface = SURFACES[k % len(SURFACES)]
            seed = GRID_SEEDS[k]
            k += 1
            name = f"grid/{spec.partition(':')[2]}-{diagonals}/{surface}"
            out.append(BroadCase(name, "grid", surface, spec, seed, size=size, diagonals=diagonals))
    return out


def _paper_cases() -> list[BroadCase]:
    return [
        BroadCase(f"paper/{p}/bezier:{seed}", "paper", "bezier", p, seed)
        for p in PAPER_PATTERNS
        for seed in PAPER_SEEDS
    ]


def _building_cases() -> list[BroadCase]:
    footprint = "mesh:0,0;18,0;18,7;8,7;8,12;0,12"  # an L-shaped hall, 18 m x 12 m
    return [
        BroadCase("building/roof-15x9/expr", "building", "expr", "grid:15x9", 0, "12x8", ROOF_EXPR),
        BroadCase("building/41x41/dome", "building", "dome", "grid:41x41", 0, "3x3"),
        BroadCase("building/21x21/hp", "building", "hp", "grid:21x21", 5, "10x10"),
        BroadCase("building/25x25/bezier", "building", "bezier", "grid:25x25", 31, "8x8"),
        BroadCase(
            "building/vault-25x13/expr",
            "building",
            "expr",
            "grid:25x13",
            0,
            "24x12",
            "0.1*x*(24-x)/6",
        ),
        BroadCase(
            "building/hall-L/expr",
            "building",
            "expr",
            footprint,
            0,
            expr="2.5 - 0.015*(x-9)**2 - 0.02*(y-6)**2",
        ),
    ]


def candidates() -> list[BroadCase]:
    """Every case before the drawn files are checked (:func:`cases` drops those refused)."""
    return [
        *_drawn_candidates(),
        *_perturbed_cases(),
        *_mesh_cases(),
        *_grid_cases(),
        *_paper_cases(),
        *_building_cases(),
    ]


def refusal(case: BroadCase, work: Path) -> str | None:
    """Why ``rigidfold generate`` refuses the case's input before solving (the one-line
    message of the reader or of the initial shape's check), or None when it builds."""
    from rigidfold.errors import RigidfoldError
    from rigidfold.generate.specs import case_from_specs

    try:
        case_from_specs(**case.make_case_kwargs(work))
    except RigidfoldError as exc:
        return str(exc)
    return None


def cases(work: Path) -> tuple[list[BroadCase], list[tuple[str, str]]]:
    """(the cases, the drawn cases left out with the reason): a drawn case whose file the
    reader refuses, or whose initial shape ``generate`` refuses, is left out. ``work``: where
    the perturbed FOLD files are written."""
    kept, left = [], []
    for case in candidates():
        if case.family == "drawn":
            reason = refusal(case, work)
            if reason is not None:
                left.append((case.name, reason))
                continue
        kept.append(case)
    return kept, left


# --- perturbed tessellations -------------------------------------------------------------


def perturbed_plan(base: Path, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The plan of an SVG tessellation, as ``generate`` reads it (fitted into 3 m x 3 m),
    with every inner vertex moved by a random offset (uniform in a disc of radius
    :data:`PERTURB_FRACTION` of its shortest crease; generator of ``seed``). A triangle that
    would turn clockwise, or take a plan angle outside the design's sector-angle bounds
    [theta_min, theta_max] by more than a tenth of its room toward 0 or 180 degrees
    (:func:`_angle_room`), has its vertices' offsets halved until it does not. Returns the
    vertices (V, 2) and triangles (F, 3)."""
    from rigidfold.generate.specs import parse_pattern

    plan = parse_pattern(str(base))
    xy, faces = plan.xy, plan.faces
    rng = np.random.default_rng(seed)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    boundary = np.zeros(len(xy), dtype=bool)
    boundary[unique[count == 1].ravel()] = True
    length = np.linalg.norm(xy[unique[:, 0]] - xy[unique[:, 1]], axis=1)
    shortest = np.full(len(xy), np.inf)
    np.minimum.at(shortest, unique[:, 0], length)
    np.minimum.at(shortest, unique[:, 1], length)
    radius = PERTURB_FRACTION * shortest * np.sqrt(rng.uniform(0.0, 1.0, len(xy)))
    turn = rng.uniform(0.0, 2 * np.pi, len(xy))
    offset = np.column_stack([radius * np.cos(turn), radius * np.sin(turn)])
    offset[boundary] = 0.0
    low, high = _angle_room(_plan_angles(xy, faces))
    for _ in range(60):
        moved = xy + offset
        angles = _plan_angles(moved, faces)
        bad = (_signed_areas(moved, faces) <= 0) | ((angles < low) | (angles > high)).any(axis=1)
        if not bad.any():
            return moved, faces
        offset[np.unique(faces[bad])] *= 0.5
    return xy, faces  # not reached: 60 halvings leave offsets of 1e-18 of a crease


def _angle_room(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The range (F, 3) each plan angle may take when perturbed: the design's bounds, or
    :data:`PERTURB_ANGLE_KEPT` of the way from 0 or 180 degrees to the angle where that is wider
    (an angle at a bound, or outside, may move a little out)."""
    from rigidfold.config import DEFAULTS

    lo, hi = DEFAULTS.design.theta_min, DEFAULTS.design.theta_max
    low = np.minimum(lo, PERTURB_ANGLE_KEPT * angles)
    high = np.maximum(hi, angles + (1 - PERTURB_ANGLE_KEPT) * (np.pi - angles))
    return low, high


def _signed_areas(xy: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = xy[faces[:, 0]], xy[faces[:, 1]], xy[faces[:, 2]]
    u, v = b - a, c - a
    return 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])


def _plan_angles(xy: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The plan angles (F, 3) of the triangles, at their three corners, radians."""
    out = np.empty(faces.shape, dtype=float)
    for k in range(3):
        p = xy[faces[:, k]]
        u, v = xy[faces[:, (k + 1) % 3]] - p, xy[faces[:, (k + 2) % 3]] - p
        cos = (u * v).sum(axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        out[:, k] = np.arccos(np.clip(cos, -1.0, 1.0))
    return out


def write_perturbed(base: Path, seed: int, work: Path) -> Path:
    """``work/patterns/<base>-p<seed>.fold``: the perturbed plan of :func:`perturbed_plan` as
    a FOLD file in metres (triangles; every crease free), written once and reused."""
    from rigidfold.io import write_json

    path = work / "patterns" / f"{base.stem}-p{seed}.fold"
    if path.is_file():
        return path
    xy, faces = perturbed_plan(base, seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(
        path,
        {
            "file_spec": 1.1,
            "file_creator": "rigidfold benchmarks/broad_cases.py",
            "file_title": f"{base.name}, inner vertices perturbed (seed {seed})",
            "frame_unit": "m",
            "vertices_coords": [[float(x), float(y), 0.0] for x, y in xy],
            "faces_vertices": faces.tolist(),
        },
    )
    return path
