"""The files of a drive, written together into one directory (:func:`write_drive`).

* ``deploy.json``: :meth:`rigidfold.drive.result.DriveResult.to_dict` (the keys of the
  issue's interface: ``schema_version``, ``base_panel``, ``panel_mass_kg``, ``states``,
  ``drive``, ``ranking``, ``check``; and the rest).
* ``deploy.fold``: the motion as the builder sees it: the built design (frame 0, metres,
  z up, the base where it is built) and one ``foldedForm`` frame per state of ``states``, in
  the same order, the base clamped in its built pose, titled with its s
  (``deploy: s = 0.3100``) and carrying it as ``rigidfold:fraction``
  (:func:`rigidfold.io.motion_frames`), so that ``rigidfold deploy deploy.fold`` reads its
  motion back.
* ``deploy.csv``: the motor schedule, one row per state: ``s``, the drive's angle (degrees)
  and torque (N m) deploying and folding back (a pair: both creases'; a cable: its length,
  m, and tension, N), U (J).
* ``deploy.png``: the effort against s with the dead points, the sign changes and the brake
  zones marked; the energy and its parts below (:mod:`rigidfold.drive.figure`).

Every file is made in memory first, then all are written together
(:func:`rigidfold.io.files.write_together`: on a full disk none appears).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path

import numpy as np

from rigidfold.drive.energy import derivative
from rigidfold.drive.result import DriveResult
from rigidfold.io.files import jsonable, prepare_output_dir, write_together
from rigidfold.io.fold_frames import motion_frames
from rigidfold.io.fold_write import fold_dict

DEPLOY_FILES = ("deploy.json", "deploy.fold", "deploy.csv", "deploy.png")
"""The files :func:`write_drive` writes."""


def fold_document(result: DriveResult) -> dict:
    """The FOLD document of ``deploy.fold`` (see the module's text)."""
    pattern = result.pattern
    frames = motion_frames(pattern, result.coords, result.s)
    for frame, s in zip(frames, result.s.tolist(), strict=True):
        frame["frame_title"] = f"deploy: s = {s:.4f}"
    built = pattern.with_coords(result.coords[-1])
    return fold_dict(
        built,
        title=f"rigidfold deploy: the built design, panel {result.base} clamped",
        frame_class="foldedForm",
        metadata={"deploy": {"base_panel": result.base, "summary": result.summary_line()}},
        frames=frames,
    )


def schedule_rows(result: DriveResult) -> tuple[tuple[str, ...], list[list[str]]]:
    """(columns, rows) of ``deploy.csv``."""
    d = result.drive
    u = result.u
    rows: list[list[str]] = []
    if d is None:
        columns: tuple[str, ...] = ("s", "U_J")
        for k, s in enumerate(result.s.tolist()):
            rows.append([f"{s:.6f}", f"{u[k]:.6g}"])
        return columns, rows
    if d.kind == "cable":
        columns = ("s", "length_m", "tension_N", "U_J")
        for k, s in enumerate(result.s.tolist()):
            rows.append([f"{s:.6f}", f"{d.coordinate[k]:.6f}", _num(d.effort[k]), f"{u[k]:.6g}"])
        return columns, rows
    back = result.slope - result.friction  # the power folding back
    if d.kind == "pair":
        a, b = d.ids
        columns = (
            "s",
            f"angle_{a}_deg",
            f"torque_{a}_Nm",
            f"angle_{b}_deg",
            f"torque_{b}_Nm",
            "U_J",
        )
        for k, s in enumerate(result.s.tolist()):
            rows.append(
                [
                    f"{s:.6f}",
                    f"{math.degrees(d.coordinate[0, k]):.4f}",
                    _num(d.effort[0, k]),
                    f"{math.degrees(d.coordinate[1, k]):.4f}",
                    _num(d.effort[1, k]),
                    f"{u[k]:.6g}",
                ]
            )
        return columns, rows
    columns = ("s", "angle_deg", "torque_Nm", "torque_folding_back_Nm", "U_J")
    with np.errstate(divide="ignore", invalid="ignore"):
        back_torque = back / derivative(d.coordinate, result.s)
    for k, s in enumerate(result.s.tolist()):
        rows.append(
            [
                f"{s:.6f}",
                f"{math.degrees(d.coordinate[k]):.4f}",
                _num(d.effort[k]),
                _num(back_torque[k]),
                f"{u[k]:.6g}",
            ]
        )
    return columns, rows


def _num(x: float) -> str:
    x = float(x)
    return f"{x:.6g}" if math.isfinite(x) else ""


def csv_text(result: DriveResult) -> str:
    columns, rows = schedule_rows(result)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows(rows)
    return out.getvalue()


def write_drive(result: DriveResult, out_dir: str | os.PathLike) -> list[Path]:
    """Write :data:`DEPLOY_FILES` of ``result`` into ``out_dir`` (made when missing),
    together; returns them, in that order. RigidfoldError (one line) when they cannot be
    written (none is)."""
    from dataclasses import replace

    from rigidfold.drive.figure import drive_png

    out = prepare_output_dir(out_dir)
    paths = [out / name for name in DEPLOY_FILES]
    named = replace(result, written=tuple(str(p) for p in paths))
    data = jsonable(named.to_dict(), where="the drive's deploy.json")
    fold = jsonable(fold_document(result), where="the drive's deploy.fold")
    files: list[tuple[Path, str | bytes]] = [
        (paths[0], json.dumps(data, indent=2, allow_nan=False) + "\n"),
        (paths[1], json.dumps(fold, allow_nan=False) + "\n"),
        (paths[2], csv_text(result)),
        (paths[3], drive_png(result)),
    ]
    return write_together(files)
