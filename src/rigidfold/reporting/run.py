"""A finished (or running) ``rigidfold generate`` directory, read back for its report.

:func:`load_run` reads ``DIR/summary.json``, ``DIR/log.json`` and every solution's FOLD file
(``DIR/solutions/step_XX_dof_YY.fold``: the folded form, its development diagram as a
``creasePattern`` frame, the folding motion as ``foldedForm`` frames, and the figures of
Steps 8-9 with the large-deformation history under ``rigidfold:deformation``), and rebuilds
the target surface from the case's metadata where it can. Anything that is not a generate
run is a one-line ``ValueError``.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.io import parse_json, read_fold
from rigidfold.protocols import TargetSurface
from rigidfold.surfaces import Bezier, SplineSurface, get_surface

_PERCENT = re.compile(r"([0-9.]+)% folded")
"""The fraction folded in a motion frame's title (:func:`rigidfold.io.motion_frames`)."""

SUMMARY_KEYS = ("stop", "stop_reason", "final_dof", "N_lock", "solutions", "per_solution", "case")
"""Keys every ``summary.json`` of ``rigidfold generate`` has (those the report reads)."""


@dataclass(frozen=True)
class Nullable:
    """A shape (see :data:`SUMMARY_SHAPE`) that may also be JSON ``null``."""

    shape: object


@dataclass(frozen=True)
class Record:
    """A JSON object whose keys, when present (``required``: always), have these shapes;
    other keys may hold anything."""

    keys: dict
    required: tuple[str, ...] = ()


_NUMBERS = Nullable(float)
SUMMARY_SHAPE = Record(
    {
        "stop": str,
        "stop_reason": str,
        "final_dof": Nullable(int),
        "initial_dof": Nullable(int),
        "N_reduce": Nullable(int),
        "N_lock": Nullable(int),
        "N_exceed": Nullable(int),
        "N_path": Nullable(int),
        "deploy_check": Nullable(bool),
        "final_step": Nullable(int),
        "final_deploys": Nullable(bool),
        "solutions": [str],
        "per_solution": [
            Record(
                {
                    "step": Nullable(int),
                    "dof": Nullable(int),
                    "development": Nullable(
                        Record(
                            {
                                "status": Nullable(str),
                                "D": _NUMBERS,
                                "flipped": Nullable(int),
                                "overlaps": Nullable(int),
                            }
                        )
                    ),
                    "motion": Nullable(
                        Record({"status": Nullable(str), "max_length_error": _NUMBERS})
                    ),
                    "deployability": Nullable(
                        Record({"status": Nullable(str), "deploys": Nullable(bool)})
                    ),
                    "deformation": Nullable(
                        Record(
                            {
                                "status": Nullable(str),
                                "reached_plane": Nullable(bool),
                                "max_dl_mm": _NUMBERS,
                                "max_drho_fix_deg": _NUMBERS,
                            }
                        )
                    ),
                    "verdicts": Nullable(
                        Record({"agreement": Nullable(str), "reason": Nullable(str)})
                    ),
                    "fit": Nullable(Record({"max_abs_dz_m": _NUMBERS})),
                }
            )
        ],
        "case": Record(
            {
                "surface": Nullable(
                    Record(
                        {
                            "name": Nullable(str),
                            "plan_box_m": Nullable((float, float)),
                            "control_heights": Nullable([[float]]),
                            "expression": Nullable(str),
                        }
                    )
                ),
                "F_tol": _NUMBERS,
                "dz_m": _NUMBERS,
            }
        ),
        "options": Nullable(Record({"target_dof": Nullable(int)})),
        "verdict": Nullable(Record({"outcome": str, "message": str}, ("outcome", "message"))),
        "target_surface": Nullable(str),
    },
    SUMMARY_KEYS,
)
"""What the report reads of ``summary.json`` and the shape it must have (:func:`check_shape`):
``int`` a whole number, ``float`` a finite number, ``str`` text, ``bool`` true or false, a
list ``[S]`` a list of S, a tuple a list of that many items of those shapes, a
:class:`Record` an object, :class:`Nullable` also null."""

LOG_SHAPE = Record(
    {
        "attempts": [
            Record(
                {
                    "index": int,
                    "outcome": str,
                    "dof": Nullable(int),
                    "F": _NUMBERS,
                    "iterations": Nullable(int),
                    "path": Nullable(Record({"status": Nullable(str), "deploys": Nullable(bool)})),
                },
                ("outcome", "dof"),
            )
        ]
    },
    ("attempts",),
)
"""What the report reads of ``log.json`` (see :data:`SUMMARY_SHAPE`)."""

HISTORY_SHAPE = [
    Record(
        {k: float for k in ("load_factor", "mean_dl_mm", "max_dl_mm", "max_drho_fix_deg")},
        ("load_factor", "mean_dl_mm", "max_dl_mm", "max_drho_fix_deg"),
    )
]
"""The large-deformation history of a solution file (``deformation.history``)."""


def check_shape(value, shape, file: str | os.PathLike, where: str = "") -> None:
    """ValueError naming ``file`` and the key (``per_solution[0].development.D``) of the
    first part of ``value`` (JSON data) that does not have ``shape`` (:data:`SUMMARY_SHAPE`
    says how shapes are written), and what it holds instead."""
    stack = [(value, shape, where)]
    while stack:
        value, given, where = stack.pop()
        shape = given.shape if isinstance(given, Nullable) else given
        if value is None and shape is not given:
            continue
        if not _has_shape(value, shape):
            key = f"{where!r}" if where else "the document"
            raise RigidfoldError(
                f"'{file}': {key} is {_received(value)}, expected {_expected(given)}"
            )
        if isinstance(shape, Record):
            missing = [k for k in shape.required if k not in value]
            if missing:
                key = f"{where!r}" if where else "the document"
                raise RigidfoldError(f"'{file}': {key} has no {', '.join(map(repr, missing))}")
            stack += [
                (value[k], s, f"{where}.{k}" if where else k)
                for k, s in reversed(shape.keys.items())
                if k in value
            ]
        elif isinstance(shape, list):
            stack += [(v, shape[0], f"{where}[{i}]") for i, v in reversed(list(enumerate(value)))]
        elif isinstance(shape, tuple):
            stack += [
                (v, s, f"{where}[{i}]") for i, (v, s) in enumerate(zip(value, shape, strict=True))
            ]


def _has_shape(value, shape) -> bool:
    """Whether ``value`` is of the kind of ``shape`` (its items are checked apart)."""
    if shape is bool:
        return isinstance(value, bool)
    if shape is int:  # within int64: numpy and matplotlib take it
        return isinstance(value, int) and not isinstance(value, bool) and abs(value) < 2**63
    if shape is float:
        if not isinstance(value, int | float) or isinstance(value, bool):
            return False
        try:
            return math.isfinite(value)
        except OverflowError:  # an integer beyond the floats
            return False
    if shape is str:
        return isinstance(value, str)
    if isinstance(shape, Record):
        return isinstance(value, dict)
    if isinstance(shape, tuple):
        return isinstance(value, list) and len(value) == len(shape)
    return isinstance(value, list)


def _expected(shape) -> str:
    if isinstance(shape, Nullable):
        return f"{_expected(shape.shape)} or null"
    words = {
        bool: "true or false",
        int: "a whole number (64 bits)",
        float: "a finite number",
        str: "text",
    }
    if isinstance(shape, type):
        return words[shape]
    if isinstance(shape, Record):
        return "an object"
    if isinstance(shape, tuple):
        return f"a list of {len(shape)} items"
    return "a list"


def _received(value) -> str:
    """``value`` as JSON text, cut to 40 characters."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 40 else text[:39] + "…"


@dataclass(frozen=True, eq=False)
class Design:
    """One accepted solution of the run, read from its FOLD file.

    name : str, the file's path relative to the run directory; step, dof : int.
    coords : (V, 3) float64, the folded form in metres (z up); faces : (F, 3) int64;
    edges : (E, 2) int64; assignment : E FOLD letters (``B`` boundary, ``M`` mountain, ``V``
    valley, ``F`` flat, ``J`` fixed); fold_deg : (E,) float64, fold angles in degrees (valley
    > 0). coords2d : (V, 2) float64 development diagram, or None when the file has none.
    motion : (K, V, 3) float64, the folding motion from flat to folded ((0, V, 3) when it was
    not traced); fraction : (K,) fraction folded of each motion frame. history : the
    large-deformation load steps (dicts of ``load_factor``, ``mean_dl_mm``, ``max_dl_mm``,
    ``max_drho_fix_deg``), empty when Step 9 did not run.
    """

    name: str
    step: int
    dof: int
    coords: np.ndarray
    faces: np.ndarray
    edges: np.ndarray
    assignment: list[str]
    fold_deg: np.ndarray
    coords2d: np.ndarray | None
    motion: np.ndarray
    fraction: np.ndarray
    history: list[dict]

    def dz(self, surface: TargetSurface) -> np.ndarray:
        """(V,) float64: z minus the target's height at each vertex's (x, y), metres."""
        x, y, z = self.coords.T
        return z - np.broadcast_to(np.asarray(surface.height(x, y), dtype=float), z.shape)


def read_design(path: Path, name: str) -> Design:
    """The :class:`Design` in the FOLD file ``path`` (``name``: its path in the run)."""
    data = read_fold(path)
    pattern, meta = data.pattern, data.metadata
    check_shape(data.raw, DESIGN_SHAPE, path)
    n_v = pattern.n_vertices
    coords2d, motion, fraction = None, [], []
    for k, frame in enumerate(data.raw.get("file_frames") or []):
        classes = frame.get("frame_classes") or []
        if "creasePattern" in classes:
            coords2d = _frame_coords(frame, n_v, 2, f"{path}: file_frames[{k}]")
        elif "foldedForm" in classes:
            motion.append(_frame_coords(frame, n_v, 3, f"{path}: file_frames[{k}]"))
            share = _PERCENT.search(str(frame.get("frame_title", "")))
            fraction.append(float(share.group(1)) / 100 if share else np.nan)
    if np.isnan(fraction).any():  # frames of another writer: evenly spaced
        fraction = np.linspace(0.0, 1.0, len(motion)).tolist()
    deformation = meta.get("deformation") or {}
    return Design(
        name=name,
        step=int(meta.get("step", -1)),
        dof=int(meta.get("dof", -1)),
        coords=pattern.coords,
        faces=pattern.faces,
        edges=pattern.edges,
        assignment=["F" if a == "U" else a for a in data.assignment],
        fold_deg=np.degrees(pattern.fold_angles),
        coords2d=coords2d,
        motion=np.asarray(motion, dtype=float).reshape(-1, n_v, 3),
        fraction=np.asarray(fraction, dtype=float),
        history=list(deformation.get("history") or []),
    )


DESIGN_SHAPE = Record(
    {
        "rigidfold:step": int,
        "rigidfold:dof": int,
        "rigidfold:deformation": Nullable(Record({"history": Nullable(HISTORY_SHAPE)})),
    }
)
"""What the report reads of rigidfold's keys in a solution file (see :data:`SUMMARY_SHAPE`)."""


def _frame_coords(frame: dict, n_vertices: int, dim: int, where: str) -> np.ndarray:
    """(V, dim) float64 ``vertices_coords`` of a frame (2D frames padded with z = 0 to 3D
    when ``dim`` is 3)."""
    try:
        xy = np.asarray(frame["vertices_coords"], dtype=float)
    except (KeyError, TypeError, ValueError):
        raise RigidfoldError(f"{where} has no numeric vertices_coords") from None
    if xy.ndim != 2 or xy.shape[0] != n_vertices or xy.shape[1] not in (2, 3):
        raise RigidfoldError(
            f"{where}: vertices_coords of shape {xy.shape}, expected ({n_vertices}, 2|3)"
        )
    if not np.isfinite(xy).all():
        raise RigidfoldError(f"{where}: non-finite vertices_coords")
    if dim == 3 and xy.shape[1] == 2:
        xy = np.column_stack([xy, np.zeros(n_vertices)])
    return xy[:, :dim]


def target_surface(metadata: dict) -> tuple[TargetSurface | None, str]:
    """(surface, "") rebuilt from ``summary.json``'s ``case.surface``, or (None, why not).

    A Bezier surface is rebuilt from its control heights, the dome and the hyperbolic
    paraboloid from their plan box, an expression from its text: the surface the run used.
    """
    name = metadata.get("name")
    try:
        box = tuple(float(v) for v in metadata.get("plan_box_m") or (3.0, 3.0))
        if name == "bezier" and metadata.get("control_heights") is not None:
            heights = np.asarray(metadata["control_heights"], dtype=float)
            return Bezier.from_heights(heights, box=(box[0], box[1])), ""
        if name in ("dome", "hp"):
            return get_surface(name, box=(box[0], box[1])), ""
        if name == "expr":
            return get_surface("expr", expr=metadata.get("expression")), ""
    except (TypeError, ValueError) as exc:
        return None, f"the target surface could not be rebuilt ({' '.join(str(exc).split())})"
    return None, f"the target surface {name!r} cannot be rebuilt from summary.json"


@dataclass(frozen=True, eq=False)
class Check:
    """One verification stage over the run's solutions.

    name : str; passed : True, False, or None when the stage did not run; detail : str;
    failed_steps : the steps of the solutions it failed on; earlier : it failed on earlier
    solutions only, not on the final design (then ``passed`` is the final design's: True).
    """

    name: str
    passed: bool | None
    detail: str
    failed_steps: tuple = ()
    earlier: bool = False

    @property
    def word(self) -> str:
        """ "passed", "passed by the final design" (failed on earlier solutions), "FAILED"
        or "not run"."""
        if self.passed and self.earlier:
            return "passed by the final design"
        return {True: "passed", False: "FAILED", None: "not run"}[self.passed]


@dataclass(frozen=True, eq=False)
class RunData:
    """Everything the report shows of one generate run.

    directory : Path; summary : dict (``summary.json``); attempts : list of dict (``log.json``);
    designs : every solution in order (the last is the final design); surface : the target
    surface, or None with ``surface_note`` saying why.
    """

    directory: Path
    summary: dict
    attempts: list[dict]
    designs: tuple[Design, ...]
    surface: TargetSurface | None
    surface_note: str

    @property
    def final(self) -> Design | None:
        """The final design (the last solution, or the one ``final_step`` of summary.json
        names: the lowest-DOF solution that deploys of a run that fell short), None when the
        run has no solution."""
        if not self.designs:
            return None
        step = self.summary.get("final_step")
        if isinstance(step, int) and 0 <= step < len(self.designs):
            return self.designs[step]
        return self.designs[-1]

    @property
    def at_dz_bound(self) -> float | None:
        """The final design's max |z - target| (metres, summary.json's ``fit``) where it is at
        the dz bound (within ``Settings.dz_bound_tol`` of ``case.dz_m``), else None."""
        final, dz = self.final, (self.summary.get("case") or {}).get("dz_m")
        rows = self.summary["per_solution"]
        if final is None or dz is None or not 0 <= final.step < len(rows):
            return None
        reached = (rows[final.step].get("fit") or {}).get("max_abs_dz_m")
        if reached is None or reached < dz * (1 - DEFAULTS.dz_bound_tol):
            return None
        return float(reached)

    @property
    def target_dof(self) -> int | None:
        return (self.summary.get("options") or {}).get("target_dof")

    def fit(self) -> np.ndarray:
        """(S, 2) float64: max and RMS of |z - target| per solution, metres (NaN without a
        surface)."""
        out = np.full((len(self.designs), 2), np.nan)
        if self.surface is not None:
            for k, design in enumerate(self.designs):
                dz = np.abs(design.dz(self.surface))
                out[k] = dz.max(), np.sqrt(np.mean(dz**2))
        return out

    def checks(self) -> list[Check]:
        """Development (Step 8), folding motion and large deformation (Step 9) over every
        solution, from ``summary.json``'s ``per_solution``. A stage that failed on earlier
        solutions only, not on the final design, passed (as generate's verdict judges), and
        says at which steps it failed."""
        final = None if self.final is None else self.final.step
        return [
            Check(c.name, True, f"{c.detail} (not the final design)", c.failed_steps, True)
            if c.passed is False and final is not None and final not in c.failed_steps
            else c
            for c in self._stages()
        ]

    def _stages(self) -> list[Check]:
        """:meth:`checks` as every solution counts."""
        rows = self.summary["per_solution"]
        n = len(rows)
        dev = [r.get("development") or {} for r in rows]
        bad = [
            r.get("step") for r, d in zip(rows, dev, strict=True) if d.get("status") != "converged"
        ]
        max_d = max((d.get("D") or 0.0 for d in dev), default=0.0)
        checks = [
            Check(
                "development",
                None if n == 0 else not bad,
                f"{n - len(bad)}/{n} converged, "
                f"{sum(max(d.get('flipped') or 0, 0) for d in dev)} flipped, "
                f"{sum(max(d.get('overlaps') or 0, 0) for d in dev)} overlapping, "
                f"max D = {max_d:.2g}" + _steps(bad),
                tuple(bad),
            )
        ]
        motions = [(r.get("step"), r["motion"]) for r in rows if r.get("motion") is not None]
        bad = [s for s, m in motions if m.get("status") != "ok"]
        err = max((m.get("max_length_error") or 0.0 for _, m in motions), default=0.0)
        checks.append(
            Check(
                "folding motion",
                None if not motions else not bad,
                f"{len(motions) - len(bad)}/{len(motions)} traced{_checked(len(motions), n)}, "
                f"max |dl|/l = {err:.2g}" + _steps(bad)
                if motions
                else "no motion was traced",
                tuple(bad),
            )
        )
        deformed = [(r.get("step"), r["deformation"]) for r in rows if r.get("deformation")]
        bad = [s for s, d in deformed if not d.get("reached_plane")]
        checks.append(
            Check(
                "large deformation",
                None if not deformed else not bad,
                f"{len(deformed) - len(bad)}/{len(deformed)} reached the plane"
                f"{_checked(len(deformed), n)}, max |dl| = "
                f"{max(d.get('max_dl_mm') or 0.0 for _, d in deformed):.3g} mm, max |drho_fix| "
                f"= {max(d.get('max_drho_fix_deg') or 0.0 for _, d in deformed):.3g} deg"
                + _steps(bad)
                if deformed
                else "Step 9 did not run (--no-deform)",
                tuple(bad),
            )
        )
        return checks


def _checked(checked: int, solutions: int) -> str:
    """ " (the final design only; --check all for every solution)" where a stage ran on fewer
    than all ``solutions``, "" otherwise."""
    if checked >= solutions:
        return ""
    which = "the final design only" if checked == 1 else f"{checked} of {solutions} solutions"
    return f" ({which}; --check all for every solution)"


def _steps(bad: list) -> str:
    return f"; failed at step {', '.join(map(str, bad))}" if bad else ""


def load_run(directory: str | os.PathLike) -> RunData:
    """Read the generate run in ``directory`` (see the module's text).

    Raises ValueError (one line) when ``directory`` is not a generate run: no directory, no
    or malformed ``summary.json`` / ``log.json`` (what the report reads of them not of the
    shape it must have, :data:`SUMMARY_SHAPE` and :data:`LOG_SHAPE`: the error names the
    file and the key), or a listed solution file that is not in the directory, is missing or
    is not a FOLD file of a generate run.
    """
    root = Path(directory)
    if not root.is_dir():
        raise RigidfoldError(
            f"{str(root)!r} is not a directory (give the --out of rigidfold generate)"
        )
    summary = _json_object(root, "summary.json")
    missing = [k for k in SUMMARY_KEYS if k not in summary]
    if missing:
        raise RigidfoldError(
            f"{str(root / 'summary.json')!r} is not the summary of rigidfold generate "
            f"(no {', '.join(missing)})"
        )
    check_shape(summary, SUMMARY_SHAPE, root / "summary.json")
    log = _json_object(root, "log.json")
    if not isinstance(log.get("attempts"), list):
        raise RigidfoldError(f"{str(root / 'log.json')!r} has no list of attempts")
    check_shape(log, LOG_SHAPE, root / "log.json")
    attempts = log["attempts"]
    for k, attempt in enumerate(attempts):
        if attempt["outcome"] == "accepted" and attempt["dof"] is None:
            raise RigidfoldError(
                f"'{root / 'log.json'}': 'attempts[{k}].dof' is null, expected a whole number "
                "(an accepted shape has a DOF)"
            )
    names = summary["solutions"]
    designs = []
    for k, name in enumerate(names):
        parts = Path(name).parts
        if not parts or Path(name).is_absolute() or ".." in parts:
            raise RigidfoldError(
                f"'{root / 'summary.json'}': 'solutions[{k}]' is {_received(name)}, expected "
                "a file in the run's directory"
            )
        path = root / name
        if not path.is_file():
            raise RigidfoldError(f"solution file {str(path)!r} listed in summary.json is missing")
        designs.append(read_design(path, name))
    surface, note = target_surface((summary.get("case") or {}).get("surface") or {})
    if surface is None and summary.get("target_surface") is not None:
        surface, note = _stored_surface(root, summary["target_surface"])
    return RunData(root, summary, attempts, tuple(designs), surface, note)


def _stored_surface(root: Path, name: str) -> tuple[TargetSurface | None, str]:
    """(surface, "") of the fitted spline of a mesh target that the run stored in the file
    ``name`` of its directory (summary.json's ``target_surface``), or (None, why not)."""
    parts = Path(name).parts
    if len(parts) != 1 or parts[0] in (".", ".."):
        return None, f"the target surface could not be rebuilt: {name!r} is not a file name"
    if not (root / name).is_file():
        return None, f"the target surface could not be rebuilt: its file {name} is missing"
    try:
        grid = _json_object(root, name)
        x, y, z = grid.get("x"), grid.get("y"), grid.get("z")
        return SplineSurface(x, y, z, source=str(grid.get("source", "mesh"))), ""
    except ValueError as exc:
        return None, (
            f"the target surface could not be rebuilt from {name} ({' '.join(str(exc).split())})"
        )


def _json_object(root: Path, name: str) -> dict:
    path = root / name
    try:
        data = parse_json(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RigidfoldError(
            f"{str(root)!r} is not a rigidfold generate run: it has no {name}"
        ) from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise RigidfoldError(f"cannot read {str(path)!r}: {' '.join(str(exc).split())}") from None
    if not isinstance(data, dict):
        raise RigidfoldError(f"{str(path)!r} is not a JSON object")
    return data
