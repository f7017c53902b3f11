"""Shared fixtures: small reference shapes built directly from arrays."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from rigidfold.mesh import CreasePattern
from rigidfold.runtime.numerics import restart_pinned, restart_wanted


def pytest_configure(config):
    """Run the tests, their xdist workers and the commands they start with the pinned
    numerics (rigidfold.runtime.numerics): tests that assert one generation path's counts or digits
    then hold on every x86-64 CPU. A pytest started without them restarts itself once, with
    pytest's capture of the terminal suspended so that the new process writes to it. (The
    capture is touched only then: resuming it here, where pytest has it suspended, would hand
    the terminal reporter pytest's capture file, closed before the session's last lines.)"""
    if not restart_wanted():
        return
    capture = config.pluginmanager.getplugin("capturemanager")
    if capture is not None:
        capture.suspend_global_capture(in_=True)
    restart_pinned()  # returns only when the restart failed
    if capture is not None:
        capture.resume_global_capture()


def degree_n_vertex(n: int, lift: float = 0.15, seed: int = 0) -> CreasePattern:
    """One interior vertex of degree n at the origin, rim vertices at random heights."""
    rng = np.random.default_rng(seed)
    phi = np.sort(2 * np.pi * (np.arange(n) + 0.3 * rng.uniform(-1, 1, n)) / n)
    rim = np.column_stack([np.cos(phi), np.sin(phi), lift * rng.uniform(-1, 1, n)])
    coords = np.vstack([[0.0, 0.0, 0.0], rim])
    faces = np.array([[0, 1 + k, 1 + (k + 1) % n] for k in range(n)])
    return CreasePattern.from_faces(coords, faces)


def folded_grid(n: int = 4, amplitude: float = 0.1, seed: int = 1) -> CreasePattern:
    """An n x n vertex grid with random heights (a generic folded triangulated sheet)."""
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    xy = np.column_stack([i.ravel(), j.ravel()]).astype(float)
    z = amplitude * rng.standard_normal(n * n)
    faces = []
    for b in range(n - 1):
        for a in range(n - 1):
            v = b * n + a
            faces += [(v, v + 1, v + n + 1), (v, v + n + 1, v + n)]
    return CreasePattern.from_faces(np.column_stack([xy, z]), np.array(faces))


def run_cli(*args: str, cwd=None, timeout: float = 600) -> subprocess.CompletedProcess:
    """``python -m rigidfold.cli ARGS`` in a new process; its exit code, stdout and stderr."""
    return subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        check=False,
        timeout=timeout,
    )


def run_cli_size_limited(limit: int, *args: str, timeout: float = 600):
    """``python -m rigidfold.cli ARGS`` in a new process whose files may be at most
    ``limit`` bytes (``RLIMIT_FSIZE``, as ``ulimit -f``; SIGXFSZ ignored, so a write past it
    fails with EFBIG): its exit code, stdout and stderr."""
    import resource
    import signal

    def limited() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

    return subprocess.run(
        [sys.executable, "-m", "rigidfold.cli", *args],
        capture_output=True,
        text=True,
        check=False,
        timeout=timeout,
        preexec_fn=limited,
    )


def files_of(directory) -> dict:
    """{name: bytes} of every file below ``directory`` (hidden ones too)."""
    from pathlib import Path

    root = Path(directory)
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def main_code(argv: list[str]) -> int:
    """``rigidfold.cli.commands.main``'s exit code in this process, argparse's errors (SystemExit)
    included."""
    from rigidfold.cli.commands import main

    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)


def dome_mesh(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The built-in dome's formula on n x n vertices over [0, 3]^2, as a triangle mesh:
    vertices (n*n, 3), triangles (2 (n-1)^2, 3)."""
    from rigidfold.surfaces import Dome, sample_mesh

    return sample_mesh(Dome(), n)


@pytest.fixture
def grid() -> CreasePattern:
    return folded_grid()


def paper_generate(case, **kwargs):
    """``rigidfold.generate.generate`` with the paper's Step 5 (no deployability check): the
    tests of the paper's method and counters use it."""
    from rigidfold.generate import generate

    return generate(case, deploy_check=False, **kwargs)
