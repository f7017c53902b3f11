"""A finished (or running) ``rigidfold generate`` directory, read back.

:func:`load_run` reads ``DIR/summary.json`` (:class:`~rigidfold.rundir.RunSummary`),
``DIR/log.jsonl`` (:class:`rigidfold.generate.Attempt` each, :func:`read_log`) and every
final design's FOLD file (``DIR/solutions/step_XX_dof_YY.fold``: the folded form, its
development diagram and folding motion as frames (:func:`rigidfold.io.read_frames`), and
the figures of Steps 8-9 with the large-deformation history under
``rigidfold:deformation``), and rebuilds the target surface from the case's metadata where
it can. Anything that is not a generate run is a one-line
``ValueError``, and so is a file of the run that a symbolic link leads out of its directory
(:func:`rigidfold.io.inside_dir`): nothing outside the run is read.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from rigidfold.config import DEFAULTS
from rigidfold.errors import RigidfoldError
from rigidfold.generate import Attempt
from rigidfold.generate.specs import parse_surface_spec
from rigidfold.io import inside_dir, parse_json, read_fold, read_frames, read_png
from rigidfold.protocols import TargetSurface
from rigidfold.rundir.json_shapes import check_shape, received
from rigidfold.rundir.schema import (
    DESIGN_SHAPE,
    LOG_FILE,
    LOG_NAN_FIELDS,
    LOG_SHAPE,
    STAGES,
    RunSummary,
    SolutionRecord,
    Stage,
    aggregate,
    check_version,
)
from rigidfold.surfaces import Bezier, SplineSurface, SurfaceKind, SurfaceSpec, surface_of


@dataclass(frozen=True, eq=False)
class SolutionFile:
    """One accepted solution of the run, read from its FOLD file.

    name : str, the file's path relative to the run directory; step, dof : int.
    coords : (V, 3) float64, the folded form in metres (z up); faces : (F, 3) int64;
    edges : (E, 2) int64; assignment : E FOLD letters (``B`` boundary, ``M`` mountain, ``V``
    valley, ``F`` flat, ``J`` fixed); fold_deg : (E,) float64, fold angles in degrees (valley
    > 0). coords2d : (V, 2) float64 development diagram, or None when the file has none.
    motion : (K, V, 3) float64, the folding motion from flat to folded ((0, V, 3) when it was
    not traced); fraction : (K,) fraction folded of each motion frame. history : the
    large-deformation load steps (dicts of ``load_factor``, ``mean_dl_mm``, ``max_dl_mm``,
    ``max_drho_fix_deg``), empty when Step 9 did not run. panels : (F,) int64, the panel
    (facets joined by fixed creases, numbered as the exports and the thick panels number
    them) of each face (empty where not known).
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
    panels: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def panel_vertices(self) -> list[np.ndarray]:
        """The vertices ((k,) int, sorted) of each panel."""
        n = int(self.panels.max(initial=-1)) + 1
        return [np.unique(self.faces[self.panels == k]) for k in range(n)]

    def dz(self, surface: TargetSurface) -> np.ndarray:
        """(V,) float64: z minus the target's height at each vertex's (x, y), metres."""
        x, y, z = self.coords.T
        return z - np.broadcast_to(np.asarray(surface.height(x, y), dtype=float), z.shape)


def read_solution(path: Path, name: str) -> SolutionFile:
    """The :class:`SolutionFile` in the FOLD file ``path`` (``name``: its path in the run)."""
    data = read_fold(path)
    pattern, meta = data.pattern, data.metadata
    check_shape(data.raw, DESIGN_SHAPE, path)
    frames = read_frames(data.raw, pattern.n_vertices, str(path))
    deformation = meta.get("deformation") or {}
    return SolutionFile(
        name=name,
        step=int(meta.get("step", -1)),
        dof=int(meta.get("dof", -1)),
        coords=pattern.coords,
        faces=pattern.faces,
        edges=pattern.edges,
        assignment=["F" if a == "U" else a for a in data.assignment],
        fold_deg=np.degrees(pattern.fold_angles),
        coords2d=frames.diagram,
        motion=frames.motion,
        fraction=frames.fraction,
        history=list(deformation.get("history") or []),
        panels=np.asarray(pattern.facets, dtype=np.int64),
    )


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
            return surface_of(SurfaceSpec(SurfaceKind(name)), box=(box[0], box[1])), ""
        if name == "expr":  # the text summary.json holds, read as the command line's
            return surface_of(parse_surface_spec("expr", expr=metadata.get("expression"))), ""
    except (TypeError, ValueError) as exc:
        return None, f"the target surface could not be rebuilt ({' '.join(str(exc).split())})"
    return None, f"the target surface {name!r} cannot be rebuilt from summary.json"


@dataclass(frozen=True, eq=False)
class ThickPanels:
    """The final design's thick panels, read back from the run's files.

    figures : the final design's ``fabrication`` record (thickness, verdict, closest pair);
    names : each solid's name (``panel_K``); panel : (P,) int64, the panel of each solid;
    vertices : P arrays (n, 3) float64, each solid's vertices in the design's place, metres,
    z up; faces : P arrays (m, 3) int64, its triangles; closest : the two panels that come
    closest over the motion (or meet first where they collide), None when no pair does.
    """

    figures: dict
    names: tuple[str, ...]
    panel: np.ndarray
    vertices: tuple[np.ndarray, ...]
    faces: tuple[np.ndarray, ...]
    closest: tuple[int, int] | None


def read_solids(path: Path) -> tuple[list[str], list[np.ndarray], list[np.ndarray]]:
    """(names, vertices, faces) of the objects of the OBJ file ``path`` that
    :func:`rigidfold.fabricate.files.obj_text` wrote (``o``/``g`` name, ``v``, ``f`` lines,
    one object per solid). ValueError (one line) for a file that is not of that form."""
    names: list[str] = []
    verts: list[list[list[float]]] = []
    faces: list[list[list[int]]] = []
    base, count = 1, 0  # OBJ's indices are global and 1-based
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise RigidfoldError(f"cannot read {str(path)!r}: {' '.join(str(exc).split())}") from None
    for n, line in enumerate(text.splitlines(), start=1):
        head, _, rest = line.strip().partition(" ")
        try:
            if head == "o":
                names.append(rest.strip())
                verts.append([])
                faces.append([])
                base = count + 1
            elif head == "v" and names:
                verts[-1].append([float(x) for x in rest.split()[:3]])
                count += 1
            elif head == "f" and names:
                faces[-1].append([int(x.split("/")[0]) - base for x in rest.split()[:3]])
        except ValueError:
            raise RigidfoldError(f"{str(path)!r}, line {n}: {received(line)} is not OBJ") from None
    out_v = [np.asarray(v, dtype=np.float64).reshape(-1, 3) for v in verts]
    out_f = [np.asarray(f, dtype=np.int64).reshape(-1, 3) for f in faces]
    for name, v, f in zip(names, out_v, out_f, strict=True):
        if len(f) and (f.min() < 0 or f.max() >= len(v)):
            raise RigidfoldError(f"{str(path)!r}: object {name!r} has a face out of its vertices")
    return names, out_v, out_f


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

    directory : Path; summary : ``summary.json``; attempts : ``log.jsonl``'s attempts, by index;
    names : the solutions' files in order (relative to ``directory``, each checked to be
    there); final : the final design read from its file (the last solution, or the one
    ``final_step`` of summary.json names: the lowest-DOF solution that deploys of a run that
    fell short), None when the run has no solution; surface : the target surface, or None
    with ``surface_note`` saying why. The other solutions' files are read only when asked
    for (:attr:`designs`): the report needs their figures only, which summary.json holds.
    """

    directory: Path
    summary: RunSummary
    attempts: tuple[Attempt, ...]
    names: tuple[str, ...]
    final: SolutionFile | None
    surface: TargetSurface | None
    surface_note: str

    @cached_property
    def designs(self) -> tuple[SolutionFile, ...]:
        """Every solution in order, read from its file (the final design's as read)."""
        k = final_index(self.summary, len(self.names))
        return tuple(
            self.final
            if i == k and self.final is not None
            else read_solution(self.directory / name, name)
            for i, name in enumerate(self.names)
        )

    @property
    def at_dz_bound(self) -> float | None:
        """The final design's max |z - target| (metres, summary.json's ``fit``) where it is at
        the dz bound (within ``Settings.design.dz_bound_tol`` of ``case.dz_m``), else None."""
        final, dz = self.final, self.summary.case.get("dz_m")
        rows = self.summary.per_solution
        if final is None or dz is None or not 0 <= final.step < len(rows):
            return None
        reached = (rows[final.step].fit or {}).get("max_abs_dz_m")
        if reached is None or reached < dz * (1 - DEFAULTS.design.dz_bound_tol):
            return None
        return float(reached)

    @property
    def target_dof(self) -> int | None:
        return self.summary.target_dof

    def fit(self) -> np.ndarray:
        """(S, 2) float64: max and RMS of |z - target| per solution, metres, as the run
        measured them (summary.json's ``fit``; NaN without a target surface or a figure)."""
        out = np.full((len(self.names), 2), np.nan)
        if self.surface is not None:
            for k, row in enumerate(self.summary.per_solution[: len(self.names)]):
                fit = row.fit or {}
                out[k] = fit.get("max_abs_dz_m", np.nan), fit.get("rms_dz_m", np.nan)
        return out

    @property
    def final_record(self) -> SolutionRecord | None:
        """The checks of the final design (its entry of ``per_solution``), None without."""
        final, rows = self.final, self.summary.per_solution
        if final is None or not 0 <= final.step < len(rows):
            return None
        return rows[final.step]

    def run_file(self, name: str | None) -> Path | None:
        """The file ``name`` (relative to the run's directory, as summary.json names it),
        None when there is none or it is not a file inside the directory. ValueError for
        one that a symbolic link leads out of the directory (:func:`rigidfold.io.inside_dir`)."""
        if not name:
            return None
        parts = Path(name).parts
        if Path(name).is_absolute() or ".." in parts:
            return None
        path = inside_dir(self.directory, self.directory / name)
        return path if path.is_file() else None

    def thick_panels(self) -> tuple[ThickPanels | None, str]:
        """(the final design's thick panels read back from their OBJ file, "") or (None,
        why not): they were not made (``generate --thickness``), or their file is missing
        or unreadable."""
        record = self.final_record
        figures = None if record is None else record.fabrication
        if figures is None:
            return None, "the thick panels were not made (generate --thickness T)"
        path = self.run_file(figures.get("solids"))
        if path is None:
            return None, f"the thick panels' solids file {figures.get('solids')!r} is missing"
        try:
            names, verts, faces = read_solids(path)
        except ValueError as exc:
            return None, str(exc)
        panel = np.array([_panel_number(n) for n in names], dtype=np.int64)
        closest = (figures.get("closest") or {}).get("panels")
        pair = None if closest is None else (int(closest[0]), int(closest[1]))
        return ThickPanels(figures, tuple(names), panel, tuple(verts), tuple(faces), pair), ""

    def structure_figure(self) -> bytes | None:
        """The PNG of the final design's deflected shape (``structure.png``), None when the
        structure was not checked or not analysed, or its file is missing. ValueError for a
        file that is not a PNG image (:func:`rigidfold.io.read_png`) or lies outside the run
        (:meth:`run_file`)."""
        record = self.final_record
        figures = None if record is None else record.structure
        return self._png(None if figures is None else figures.get("figure"))

    def drive_figure(self) -> bytes | None:
        """The PNG of the final design's deployment drive (``final/deploy/deploy.png``,
        ``generate --deploy``), None when it did not run or its file is missing; checked as
        :meth:`structure_figure`'s."""
        record = self.final_record
        figures = None if record is None else record.drive
        files = [] if figures is None else (figures.get("files") or [])
        png = (f for f in files if isinstance(f, str) and f.endswith(".png"))
        return self._png(next(png, None))

    def _png(self, name: str | None) -> bytes | None:
        """The PNG image of the run file ``name`` (:func:`rigidfold.io.read_png`), None
        without a name or where the file is missing (:meth:`run_file`)."""
        path = None if name is None else self.run_file(name)
        return None if path is None else read_png(path)

    def driven_creases(self) -> tuple[int, ...]:
        """The edges (of the final design's FOLD file) of its named drive, () without one or
        where the drive is a cable."""
        record = self.final_record
        drive = ((record.drive or {}).get("drive") or {}) if record is not None else {}
        if drive.get("kind") not in ("crease", "pair"):
            return ()
        return tuple(int(e) for e in drive.get("edges") or () if isinstance(e, int))

    def checks(self) -> list[Check]:
        """Development (Step 8), folding motion and large deformation (Step 9) over every
        solution, and every other :class:`~rigidfold.rundir.Stage` where it ran (the thick
        panels, the structure), in the words of the solutions it failed on, else of the last
        it ran on, from ``summary.json``'s ``per_solution``
        (:meth:`rigidfold.rundir.SolutionRecord.passed`). A stage that failed on earlier
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
        """:meth:`checks` as every solution counts: the figures are the run-wide ones of
        summary.json (:func:`~rigidfold.rundir.schema.aggregate`), whether a stage passed
        :meth:`SolutionRecord.passed`, its name and words ``STAGES``'s."""
        rows = self.summary.per_solution
        n = len(rows)
        figures = aggregate(rows)
        dev = figures["development"]
        bad = _failed(rows, Stage.DEVELOPMENT)
        drawn = sum(r.ran(Stage.DEVELOPMENT) for r in rows)
        checks = [
            Check(
                STAGES[Stage.DEVELOPMENT].name,
                None if not drawn else not bad,
                f"{drawn - len(bad)}/{drawn} converged{_checked(drawn, n)}, "
                f"{dev['flipped']} flipped, {dev['overlaps']} overlapping, "
                f"max D = {dev['max_D'] or 0.0:.2g}" + _steps(bad)
                if drawn
                else "no development diagram was drawn",
                tuple(bad),
            )
        ]
        traced = sum(r.ran(Stage.MOTION) for r in rows)
        bad = _failed(rows, Stage.MOTION)
        err = figures["motion"]["max_length_error"] or 0.0
        checks.append(
            Check(
                STAGES[Stage.MOTION].name,
                None if not traced else not bad,
                f"{traced - len(bad)}/{traced} traced{_checked(traced, n)}, "
                f"max |dl|/l = {err:.2g}" + _steps(bad)
                if traced
                else "no motion was traced",
                tuple(bad),
            )
        )
        deformed = figures["deformation"]
        checked = deformed["checked"]
        bad = _failed(rows, Stage.DEFORMATION)
        checks.append(
            Check(
                STAGES[Stage.DEFORMATION].name,
                None if not checked else not bad,
                f"{checked - len(bad)}/{checked} reached the plane"
                f"{_checked(checked, n)}, max |dl| = {deformed['max_dl_mm'] or 0.0:.3g} mm, "
                f"max |drho_fix| = {deformed['max_drho_fix_deg'] or 0.0:.3g} deg" + _steps(bad)
                if checked
                else "Step 9 did not run (--no-deform)",
                tuple(bad),
            )
        )
        for stage in (s for s in Stage if STAGES[s].detailed):  # shown by their words
            ran = [r for r in rows if r.ran(stage)]
            if ran:  # only where asked: a run without them does not list them as not run
                bad = _failed(rows, stage)
                said = [r for r in ran if r.passed(stage) is False] or ran[-1:]  # else the last
                detail = "; ".join(r.detail(stage) for r in said if r.detail(stage))
                checks.append(Check(STAGES[stage].name, not bad, detail + _steps(bad), tuple(bad)))
        return checks


def _panel_number(name: str) -> int:
    """K of a solid named ``panel_K``, -1 for another name."""
    head, _, number = name.rpartition("_")
    return int(number) if head == "panel" and number.isdigit() else -1


def _failed(rows: tuple[SolutionRecord, ...], stage: Stage) -> list:
    """The steps of the solutions on which ``stage`` ran and failed."""
    return [r.step for r in rows if r.passed(stage) is False]


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
    or malformed ``summary.json`` / ``log.jsonl`` (what the report reads of them not of the
    shape it must have, :data:`SUMMARY_SHAPE` and :data:`LOG_SHAPE`: the error names the
    file and the key; :func:`read_log`), either of another run schema version
    (:data:`~rigidfold.rundir.schema.SCHEMA_VERSION`), or a listed solution file that is not in
    the directory, is missing or is not a FOLD file of a generate run.
    """
    root = Path(directory)
    if not root.is_dir():
        raise RigidfoldError(
            f"{str(root)!r} is not a directory (give the --out of rigidfold generate)"
        )
    summary = RunSummary.from_dict(_json_object(root, "summary.json"), root / "summary.json")
    attempts = read_log(inside_dir(root, root / LOG_FILE))
    names = summary.solutions
    seen: dict[str, int] = {}
    for k, name in enumerate(names):
        if name in seen:  # each solution once: a repeated name is a damaged summary
            raise RigidfoldError(
                f"'{root / 'summary.json'}': 'solutions[{k}]' is {received(name)}, which "
                f"'solutions[{seen[name]}]' already lists"
            )
        seen[name] = k
        parts = Path(name).parts
        if not parts or Path(name).is_absolute() or ".." in parts:
            raise RigidfoldError(
                f"'{root / 'summary.json'}': 'solutions[{k}]' is {received(name)}, expected "
                "a file in the run's directory"
            )
        path = inside_dir(root, root / name)
        if not path.is_file():
            raise RigidfoldError(f"solution file {str(path)!r} listed in summary.json is missing")
    index = final_index(summary, len(names))
    final = (
        None
        if index is None
        else read_solution(inside_dir(root, root / names[index]), names[index])
    )
    surface, note = target_surface(summary.case.get("surface") or {})
    if surface is None and summary.target_surface is not None:
        surface, note = _stored_surface(root, summary.target_surface)
    if surface is not None and final is not None and not _measurable(final, surface):
        source = "" if summary.target_surface is None else f" (from {summary.target_surface})"
        surface, note = (
            None,
            f"the target surface could not be rebuilt{source}: its heights are too large",
        )
    return RunData(root, summary, attempts, tuple(names), final, surface, note)


def final_index(summary: RunSummary, count: int) -> int | None:
    """The index of the final design among ``count`` solutions: summary.json's
    ``final_step`` where it is one of them, else the last; None without a solution."""
    if count == 0:
        return None
    step = summary.final_step
    return step if step is not None and 0 <= step < count else count - 1


def _measurable(design: SolutionFile, surface: TargetSurface) -> bool:
    """Whether the distances of ``design`` to ``surface`` are numbers, their squares in mm
    too (a surface rebuilt from damaged heights may give distances beyond the floats)."""
    with np.errstate(over="ignore", invalid="ignore"):
        dz = design.dz(surface)
        return bool(np.all(np.isfinite((dz * 1e3) ** 2)))


def read_log(path: str | os.PathLike) -> tuple[Attempt, ...]:
    """The attempts of a run's log (``DIR/log.jsonl``, :data:`~rigidfold.rundir.schema.LOG_FILE`),
    by index: the last line of each index is its record (an attempt whose outcome
    backtracking changed was appended again).

    The first line is the header, ``{"schema_version": N}``; a log of another version is
    refused (:func:`~rigidfold.rundir.schema.check_version`), and so is one without a header
    (empty, or its only line torn): its version cannot be checked. A last line that does not end the
    file and does not parse (torn by a crash mid-write) is skipped, the lines before it
    kept. Raises ValueError (one line, naming the file and the line) for a missing or
    unreadable file, a line that is not JSON or an attempt of the wrong shape
    (:data:`~rigidfold.rundir.schema.LOG_SHAPE`), and an accepted attempt without a DOF.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise RigidfoldError(
            f"{str(path.parent)!r} is not a rigidfold generate run: it has no {path.name}"
        ) from None
    except OSError as exc:
        raise RigidfoldError(f"cannot read {str(path)!r}: {exc.strerror}") from None
    lines = data.split(b"\n")
    last = lines.pop()  # b"" after the final newline; else a line the writer did not end
    records = [_log_line(path, n, line) for n, line in enumerate(lines, start=1)]
    if last.strip():
        try:
            records.append(_log_line(path, len(lines) + 1, last))
        except ValueError:
            pass  # torn by a crash mid-write
    if not records:  # empty, or only a torn first line: no version to check
        what = "is empty" if not data.strip() else "holds only a torn first line"
        raise RigidfoldError(
            f'{str(path)!r} {what}: no header line {{"schema_version": N}}, so it is not a '
            "run log this version can read"
        )
    header, *rows = records
    if "schema_version" not in header:
        raise RigidfoldError(
            f"{str(path)!r}, line 1: {received(header)} is not the header of a run log "
            "(no 'schema_version')"
        )
    check_version(header["schema_version"], path)
    attempts: dict[int, Attempt] = {}
    for n, row in enumerate(rows, start=2):
        check_shape(row, LOG_SHAPE, path, line=n)
        if row["outcome"] == "accepted" and row["dof"] is None:
            raise RigidfoldError(
                f"{str(path)!r}, line {n}: 'dof' is null, expected a whole number (an accepted "
                "shape has a DOF)"
            )
        nan = {k: math.nan for k in LOG_NAN_FIELDS if row.get(k, 0) is None}  # written null
        attempts[row["index"]] = Attempt.from_dict(row | nan)
    return tuple(attempts[k] for k in sorted(attempts))


def _log_line(path: Path, n: int, line: bytes) -> dict:
    """The JSON object on line ``n`` of the log ``path``: ValueError (one line) otherwise."""
    try:
        value = parse_json(line)
    except (UnicodeDecodeError, ValueError) as exc:
        raise RigidfoldError(
            f"{str(path)!r}, line {n}: not JSON ({' '.join(str(exc).split())})"
        ) from None
    if not isinstance(value, dict):
        raise RigidfoldError(f"{str(path)!r}, line {n}: {received(value)} is not a JSON object")
    return value


def _stored_surface(root: Path, name: str) -> tuple[TargetSurface | None, str]:
    """(surface, "") of the fitted spline of a mesh target that the run stored in the file
    ``name`` of its directory (summary.json's ``target_surface``), or (None, why not)."""
    parts = Path(name).parts
    if len(parts) != 1 or parts[0] in (".", ".."):
        return None, f"the target surface could not be rebuilt: {name!r} is not a file name"
    if not inside_dir(root, root / name).is_file():
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
    path = inside_dir(root, root / name)
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
