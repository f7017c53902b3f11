"""The workflows behind the command line: read, compute, write, and return a result.

Each function takes validated library objects (or a file path, validated on reading), runs
the library, writes its files through the shared writers of :mod:`rigidfold.report` and
:mod:`rigidfold.io`, and returns a frozen result whose ``to_dict()`` is what ``--json``
prints. ``rigidfold.cli`` only parses arguments, calls these functions and prints.

=====================  ====================================================================
``analyze_file``       mechanism analysis of a FOLD shape (``rigidfold analyze``)
``develop_file``       Step 8 of a FOLD shape: FOLD with its diagram, and an SVG
``deform_file``        Steps 8-9 and the folding motion of a FOLD shape
``optimize_case``      one solve of problem (6): ``solution.fold`` and ``summary.json``
``generate_case``      Steps 2-9 into a :class:`rigidfold.report.RunWriter`
=====================  ====================================================================
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigidfold.case import Case, parse_fixed, shape_report
from rigidfold.config import DEFAULTS, Settings
from rigidfold.deform.check import Verification, verify
from rigidfold.generate import Attempt, Generation, generate
from rigidfold.io import FoldData, prepare_output_dir, read_fold, write_fold, write_json
from rigidfold.mechanism import Mechanism, analyze
from rigidfold.optimize import OptimizeResult
from rigidfold.report import RunWriter, write_checked_shape


# ------------------------------------------------------------------------------ analyze
@dataclass(frozen=True, eq=False)
class ShapeAnalysis:
    """Mechanism analysis of a shape read from a FOLD file.

    file : str; data : FoldData (the file's pattern and edge numbering); mechanism : Mechanism.
    """

    file: str
    data: FoldData
    mechanism: Mechanism

    @property
    def locked_edges(self) -> list[int]:
        """Locked creases that are edges of the file (indices into its ``edges_vertices``)."""
        return [e for e in self.mechanism.locked_creases.tolist() if e < self.data.n_file_edges]

    def fold_angles_deg(self, edges: np.ndarray) -> np.ndarray:
        """(k,) fold angles in degrees (valley > 0) of the given pattern edges."""
        return np.degrees(self.data.pattern.fold_angles[edges])

    def to_dict(self) -> dict:
        pattern, mech = self.data.pattern, self.mechanism
        n_file = self.data.n_file_edges
        return {
            "file": self.file,
            "vertices": pattern.n_vertices,
            "faces": pattern.n_faces,
            "free_creases": len(mech.hinges),
            "fixed_creases": len(pattern.fixed_creases),
            "dof": mech.dof,
            "locked_edges": self.locked_edges,
            "locked_vertex_pairs": [pattern.edges[e].tolist() for e in mech.locked_creases],
            "fold_angles_deg": np.round(self.fold_angles_deg(np.arange(n_file)), 6).tolist(),
        }


def analyze_file(path: str | os.PathLike, *, settings: Settings = DEFAULTS) -> ShapeAnalysis:
    """DOF, locked creases and fold angles of the shape in a FOLD file."""
    data = read_fold(path)
    return ShapeAnalysis(str(path), data, analyze(data.pattern, settings=settings))


# ------------------------------------------------------------------- develop and deform
@dataclass(frozen=True, eq=False)
class ShapeCheck:
    """Steps 8(-9) of a shape read from a FOLD file, and the files written.

    verification : Verification; written : the files, in the order written.
    """

    file: str
    verification: Verification
    written: tuple[Path, ...]

    def to_dict(self) -> dict:
        """The checked stage's figures at the top level (the deformation's when Step 9 ran,
        else the development's, without the load-step history), the others under their
        names."""
        figures = self.verification.to_dict()
        stage = "development" if figures["deformation"] is None else "deformation"
        top = {k: v for k, v in figures.pop(stage).items() if k != "history"}
        return {**top, **{k: v for k, v in figures.items() if v is not None}}


def develop_file(
    path: str | os.PathLike, out: str | os.PathLike, *, settings: Settings = DEFAULTS
) -> ShapeCheck:
    """Step 8 of a FOLD shape: ``OUT/<name>.fold`` (the input plus its development diagram
    as a ``creasePattern`` frame) and ``OUT/<name>.svg``."""
    return _check_file(path, out, deform=False, settings=settings)


def deform_file(
    path: str | os.PathLike, out: str | os.PathLike, *, settings: Settings = DEFAULTS
) -> ShapeCheck:
    """Steps 8-9 and the folding motion of a FOLD shape: ``OUT/<name>.fold`` (the input plus
    its development diagram and motion frames), ``OUT/<name>.svg`` and
    ``OUT/<name>_deform.json`` (every figure and the load-step history)."""
    return _check_file(path, out, deform=True, settings=settings)


def _check_file(path, out, *, deform: bool, settings: Settings) -> ShapeCheck:
    out_dir = prepare_output_dir(out)
    data = read_fold(path)
    check = verify(data.pattern, run_deform=deform, run_motion=deform, settings=settings)
    stem = Path(path).stem
    written = write_checked_shape(
        out_dir / f"{stem}.fold",
        data.pattern,
        check,
        title=f"{stem} (folded form)",
        metadata=data.metadata,
        svg_title=f"{stem}: development",
    )
    if deform:
        written.append(write_json(out_dir / f"{stem}_deform.json", check.to_dict()))
    return ShapeCheck(str(path), check, tuple(written))


# ------------------------------------------------------------------------------ optimize
@dataclass(frozen=True, eq=False)
class OptimizeOutput:
    """One solve of problem (6): the result, ``summary.json``'s content, the files written."""

    result: OptimizeResult
    build_time: float
    report: dict
    written: tuple[Path, ...]

    def to_dict(self) -> dict:
        return self.report


def optimize_case(
    case: Case, out: str | os.PathLike, *, fixed: str | None = None, solver: str = "ipopt"
) -> OptimizeOutput:
    """Solve (6) once with the creases ``fixed`` ("I,J,...") fixed; write
    ``OUT/solution.fold`` and ``OUT/summary.json`` whatever the outcome."""
    out_dir = prepare_output_dir(out)
    mask = parse_fixed(fixed, case.pattern)
    problem = case.problem(build_ipopt=solver == "ipopt")
    result = problem.solve(fixed=mask, solver=solver)
    report = shape_report(case, result, problem.build_time)
    fold = write_fold(
        out_dir / "solution.fold",
        result.pattern,
        title=f"rigidfold optimize: {case.surface.name} on pattern {case.pattern_name}",
        metadata={**case.metadata(), **result.to_dict()},
    )
    summary = write_json(out_dir / "summary.json", report)
    return OptimizeOutput(result, problem.build_time, report, (fold, summary))


# ------------------------------------------------------------------------------ generate
def generate_case(
    writer: RunWriter,
    *,
    criterion: str,
    target_dof: int,
    seed: int,
    solver: str,
    lookahead: bool = False,
    progress: Callable[[Generation, Attempt | None], None] | None = None,
) -> Generation:
    """Steps 2-9 on ``writer.case``, every attempt and solution written by ``writer`` as it
    comes (so an interrupt loses nothing); ``progress(run, attempt)`` after each of them.
    ``lookahead``: skip the candidates predicted to lock (``generate``'s option).
    ``summary.json`` is written once more at the end."""

    def on_attempt(run: Generation, attempt: Attempt) -> None:
        writer.on_attempt(run, attempt)
        if progress:
            progress(run, attempt)

    def on_solution(run: Generation, solution) -> None:
        writer.on_solution(run, solution)
        if progress:
            progress(run, None)

    run = generate(
        writer.case,
        criterion=criterion,
        target_dof=target_dof,
        seed=seed,
        solver=solver,
        lookahead=lookahead,
        on_attempt=on_attempt,
        on_solution=on_solution,
    )
    writer.write_summary(run)
    return run
