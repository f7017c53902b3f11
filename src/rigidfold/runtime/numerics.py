"""Reproducible numerics: the same floating-point results on every x86-64 CPU.

Problem (6) has no unique minimiser: F is zero on a family of developable shapes, and
round-off decides which one the solver reaches, so a last-bit difference changes the path of
a generation (another fixed crease, another N_lock). Three parts of a machine's floating
point pick their code by the CPU they run on; each was measured to change the demo's path
(``benchmarks/numerics.py`` prints which):

1. **OpenBLAS** (NumPy's and SciPy's copies) picks its kernel from CPUID, and the Prescott
   kernel's blocking from the L2 size: pinned to ``OPENBLAS_CORETYPE=Prescott`` (SSE3, which
   every x86-64 CPU has) and ``OPENBLAS_L2_SIZE=1024`` (KiB). CasADi's own OpenBLAS (MUMPS
   inside IPOPT) is built for Core2 alone, the same everywhere.
2. **NumPy's SIMD dispatch**: with AVX-512, ``arccos``, ``arctan2``, ``exp`` and ``log`` run
   Intel's SVML, whose last bits differ from the C library's. Pinned to the baseline of the
   wheel (``NPY_ENABLE_CPU_FEATURES``).
3. **glibc's libm** takes FMA variants of ``sin``, ``cos``, ``exp``, ``log``, ``pow``,
   ``atan``, ``acos`` ... on CPUs with FMA and AVX2 (used by NumPy, CasADi's expressions and
   Python's ``math``). Pinned by ``GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-FMA4``,
   which the dynamic loader reads when a process starts, so only a process *started* with it
   is pinned.

The variables of 1 and 2 are read when the libraries load, so ``import rigidfold`` before
NumPy sets them (:func:`pin_in_process`). Part 3 needs a new process: the command line
restarts itself once with the pinned environment (:func:`restart_pinned`); study workers
inherit it; ``make test`` runs pytest through it. A Python session started otherwise runs
with the machine's libm and says so (:attr:`NumericEnvironment.pinned` is False, and
``unpinned`` names the part). ``RIGIDFOLD_NUMERICS=native`` keeps the machine's own kernels.

What stays machine-dependent: the versions of the libraries and of glibc (recorded, and part
of :attr:`NumericEnvironment.key`), and CPUs that are not x86-64 (nothing is pinned there).

:func:`numeric_environment` records what a process runs with, with a *canary*: the hash of
a fixed set of libm, NumPy, BLAS and LAPACK results on inputs where the CPU-specific code
paths differ in the last bit. Two processes with the same canary computed the same bits on
every one of them.
"""

from __future__ import annotations

import functools
import hashlib
import os
import platform
import subprocess
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field

from rigidfold.outcomes import Outcome
from rigidfold.runtime import libm_probe

OPT_OUT_ENV = "RIGIDFOLD_NUMERICS"
"""Set to ``native`` to keep the machine's own BLAS kernel, SIMD and libm variants."""

RESTARTED_ENV = "RIGIDFOLD_NUMERICS_RESTARTED"
"""Set in a process that :func:`restart_pinned` started, so that it never restarts twice."""

BLAS_CORETYPE = "Prescott"
BLAS_KERNEL_NAMES = ("Prescott", "Katmai")
"""What OpenBLAS reports for the forced Prescott kernel: SciPy's builds alias the kernels
older than Core2 to it and name the first alias."""
BLAS_L2_SIZE_KIB = "1024"
NUMPY_FEATURES = "X86_V2"  # the baseline group of NumPy's x86-64 wheels (NumPy >= 2.4)
LIBM_HWCAPS = ("AVX", "AVX2", "FMA", "FMA4")  # glibc's libm ifuncs select on these
_TUNABLE = "glibc.cpu.hwcaps"


class NumericsStatus(Outcome):
    PINNED = "pinned", "the same floating-point path on every x86-64 CPU"
    NATIVE = "native", f"the machine's own kernels ({OPT_OUT_ENV}=native)"
    PARTIAL = "partial", "some parts of the floating point follow this CPU"
    UNSUPPORTED = "unsupported", "not an x86-64 Linux machine: nothing is pinned"


def _supported() -> bool:
    return sys.platform.startswith("linux") and platform.machine() in ("x86_64", "AMD64")


def _opted_out(environ: Mapping[str, str]) -> bool:
    return environ.get(OPT_OUT_ENV, "").strip().lower() == "native"


def _hwcaps_tunables(value: str) -> str:
    """``GLIBC_TUNABLES`` with our hwcaps mask merged into any tunables already there."""
    parts = [p for p in value.split(":") if p and not p.startswith(_TUNABLE + "=")]
    old = [p for p in value.split(":") if p.startswith(_TUNABLE + "=")]
    masks = [m for p in old for m in p.split("=", 1)[1].split(",") if m]
    masks += [f"-{cap}" for cap in LIBM_HWCAPS if f"-{cap}" not in masks]
    return ":".join([*parts, f"{_TUNABLE}={','.join(masks)}"])


def pinned_environ(environ: Mapping[str, str]) -> dict[str, str]:
    """``environ`` with the pinned numerics set (a copy); unchanged off x86-64 Linux.

    An ``OPENBLAS_CORETYPE`` or ``NPY_ENABLE_CPU_FEATURES`` already there is replaced: the
    point is that no machine chooses its own.
    """
    env = dict(environ)
    if not _supported() or _opted_out(environ):
        return env
    env["OPENBLAS_CORETYPE"] = BLAS_CORETYPE
    env["OPENBLAS_L2_SIZE"] = BLAS_L2_SIZE_KIB
    env["NPY_ENABLE_CPU_FEATURES"] = NUMPY_FEATURES
    env.pop("NPY_DISABLE_CPU_FEATURES", None)  # NumPy refuses both together
    env["GLIBC_TUNABLES"] = _hwcaps_tunables(environ.get("GLIBC_TUNABLES", ""))
    return env


def _libm_masked(environ: Mapping[str, str]) -> bool:
    """Whether ``environ`` asks the dynamic loader for the pinned libm (what a process
    started with it runs with: :func:`libm_pinned` measures it)."""
    masks = {
        m
        for p in environ.get("GLIBC_TUNABLES", "").split(":")
        if p.startswith(_TUNABLE + "=")
        for m in p.split("=", 1)[1].split(",")
    }
    return all(f"-{cap}" in masks for cap in LIBM_HWCAPS)


@functools.cache
def _initial_environ() -> dict[str, str]:
    """The environment this process started with (what the dynamic loader read)."""
    try:
        with open("/proc/self/environ", "rb") as f:
            raw = f.read()
    except OSError:
        return dict(os.environ)
    pairs = (item.split(b"=", 1) for item in raw.split(b"\0") if b"=" in item)
    return {k.decode(errors="replace"): v.decode(errors="replace") for k, v in pairs}


def pin_in_process() -> bool:
    """Set the pinned OpenBLAS and NumPy variables in ``os.environ`` while NumPy is not yet
    loaded (they are read when it loads); True when they are (or were already) in effect.
    Called by ``import rigidfold``. The libm part needs a new process (:func:`restart_pinned`).
    """
    if not _supported() or _opted_out(os.environ):
        return False
    wanted = pinned_environ(os.environ)
    keys = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "NPY_ENABLE_CPU_FEATURES")
    if all(os.environ.get(k) == wanted[k] for k in keys):
        return True
    if "numpy" in sys.modules:
        return False  # too late: NumPy chose its kernels when it loaded
    for k in keys:
        os.environ[k] = wanted[k]
    os.environ.pop("NPY_DISABLE_CPU_FEATURES", None)
    return True


def restart_wanted() -> bool:
    """Whether :func:`restart_pinned` would replace this process (see there)."""
    if not _supported() or _opted_out(os.environ) or os.environ.get(RESTARTED_ENV):
        return False
    initial = _initial_environ()
    wanted = pinned_environ(initial)
    if all(initial.get(k) == v for k, v in wanted.items() if k != "GLIBC_TUNABLES") and (
        _libm_masked(initial)
    ):
        return False
    argv = list(getattr(sys, "orig_argv", [])) or [sys.executable, *sys.argv]
    # a script read from standard input cannot be read twice
    return "-" not in argv[1:2] and bool(sys.executable)


def restart_pinned() -> None:
    """Replace this process by the same command started with the pinned numerics, unless it
    already runs with them, was asked not to (``RIGIDFOLD_NUMERICS=native``), was started
    by this function already, or is not on x86-64 Linux. Returns only when no restart is
    made. For entry points (the command line, the test runner): call it before anything
    that imports NumPy, so that the first process loads nothing in vain.
    """
    if not restart_wanted():
        return
    argv = list(getattr(sys, "orig_argv", [])) or [sys.executable, *sys.argv]
    env = pinned_environ(os.environ)
    env[RESTARTED_ENV] = "1"
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execve(sys.executable, argv, env)
    except OSError as exc:  # carry on unpinned, and say so
        print(
            f"rigidfold: warning: could not restart with the pinned numerics "
            f"({exc.strerror or exc}); this process computes with this machine's libm",
            file=sys.stderr,
        )


# --- what a process runs with ------------------------------------------------------------


def canary() -> str:
    """Hash of a fixed set of results from every floating-point path that follows the CPU:
    libm through Python's ``math`` (as CasADi's expressions use it), NumPy's ufuncs (SIMD
    dispatch), a matrix product (NumPy's OpenBLAS) and an SVD (SciPy's LAPACK and BLAS)."""
    import numpy as np
    import scipy.linalg

    xs, ps = libm_probe.canary_inputs()
    h = hashlib.sha256()
    libm_probe.update(h, xs, ps)
    x, p = np.array(xs), np.array(ps)
    for arr in (np.sin(x), np.cos(x), np.arccos(p), np.arctan2(x, x[::-1]), np.exp(x), np.log(p)):
        h.update(arr.tobytes())
    m = x[: 64 * 48].reshape(64, 48)
    h.update((m.T @ m).tobytes())
    h.update(scipy.linalg.svd(m, compute_uv=False).tobytes())
    return h.hexdigest()[:16]


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("rigidfold", "numpy", "scipy", "casadi"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    try:
        out["libc"] = " ".join(os.confstr("CS_GNU_LIBC_VERSION").split())  # type: ignore[union-attr]
    except (ValueError, OSError, AttributeError):
        out["libc"] = platform.libc_ver()[0] or "unknown"
    return out


def _blas() -> tuple[str, ...]:
    """Each loaded OpenBLAS: file prefix, version, kernel (after loading SciPy's LAPACK)."""
    import scipy.linalg  # noqa: F401  (loads SciPy's OpenBLAS)
    from threadpoolctl import threadpool_info

    return tuple(
        sorted(
            f"{i.get('prefix')} {i.get('version')} {i.get('architecture')}"
            for i in threadpool_info()
            if i.get("internal_api") == "openblas"
        )
    )


def _simd() -> str:
    """NumPy's dispatched SIMD features that are in use ("baseline" when none)."""
    try:
        from numpy._core._multiarray_umath import (  # type: ignore[import-not-found]
            __cpu_dispatch__,
            __cpu_features__,
        )
    except ImportError:  # pragma: no cover - a NumPy without these private names
        return "unknown"
    used = [name for name in __cpu_dispatch__ if __cpu_features__.get(name)]
    return " ".join(used) if used else "baseline"


@dataclass(frozen=True)
class NumericEnvironment:
    """The floating-point environment of a process.

    status : NumericsStatus
    unpinned : the parts that follow this CPU, in words (empty when pinned)
    blas : each loaded OpenBLAS as "prefix version kernel"
    simd : NumPy's dispatched SIMD features in use, "baseline" when none
    libm : the C library and the hwcaps mask its libm was loaded with
    versions : python, rigidfold, numpy, scipy, casadi, libc
    cpu : the CPU model (recorded, not compared)
    canary : hash of results of every CPU-dependent path (:func:`canary`)
    """

    status: NumericsStatus
    unpinned: tuple[str, ...]
    blas: tuple[str, ...]
    simd: str
    libm: str
    versions: dict[str, str] = field(default_factory=dict)
    cpu: str = ""
    canary: str = ""

    @property
    def pinned(self) -> bool:
        return self.status is NumericsStatus.PINNED

    @property
    def key(self) -> str:
        """What two runs must share to take the same path: the canary and the versions of
        the numerical libraries (not the CPU model: that is the point of pinning)."""
        v = self.versions
        parts = [self.canary, *(f"{k}={v.get(k)}" for k in ("numpy", "scipy", "casadi", "libc"))]
        return " ".join(parts)

    def to_dict(self) -> dict:
        return {
            "status": self.status.value,
            "message": self.status.message,
            "unpinned": list(self.unpinned),
            "blas": list(self.blas),
            "simd": self.simd,
            "libm": self.libm,
            "versions": dict(self.versions),
            "cpu": self.cpu,
            "canary": self.canary,
            "key": self.key,
        }


LIBM_PROBE_TIMEOUT_S = 60


@functools.cache
def libm_pinned() -> bool:
    """Whether this process's libm computes the bits of the pinned one: the libm canary
    (:func:`rigidfold.runtime.libm_probe.digest`) here and in a process started with the pinned
    hwcaps are the same (measured, so a CPU without FMA and AVX2 is pinned whatever the
    environment says, and a loader that ignored the mask is not). False when that process
    could not run."""
    env = dict(os.environ)  # this environment, with the hwcaps mask even where opted out
    env["GLIBC_TUNABLES"] = _hwcaps_tunables(env.get("GLIBC_TUNABLES", ""))
    try:
        proc = subprocess.run(
            [sys.executable, "-I", "-S", libm_probe.__file__],
            env=env,
            capture_output=True,
            text=True,
            timeout=LIBM_PROBE_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return False
    return proc.returncode == 0 and proc.stdout.strip() == libm_probe.digest()


@functools.cache
def numeric_environment() -> NumericEnvironment:
    """What this process computes with (cached: it cannot change once the libraries load)."""
    initial = _initial_environ()
    blas = _blas()
    simd = _simd()
    libm_mask = ",".join(f"-{c}" for c in LIBM_HWCAPS) if _libm_masked(initial) else "native"
    versions = _versions()
    libm = f"{versions['libc']}, hwcaps {libm_mask}"
    unpinned: list[str] = []
    if _supported():
        if any(b.rsplit(" ", 1)[-1] not in BLAS_KERNEL_NAMES for b in blas if "casadi" not in b):
            unpinned.append("OpenBLAS kernel chosen by this CPU (" + "; ".join(blas) + ")")
        if os.environ.get("OPENBLAS_L2_SIZE") != BLAS_L2_SIZE_KIB:
            unpinned.append("OpenBLAS blocking from this CPU's L2 size")
        if simd != "baseline":
            unpinned.append(f"NumPy SIMD dispatch of this CPU ({simd})")
        if not libm_pinned():
            unpinned.append(
                "libm variants of this CPU (its results differ from the pinned libm's: the "
                "process was not started pinned)"
            )
    if not _supported():
        status = NumericsStatus.UNSUPPORTED
    elif not unpinned:
        status = NumericsStatus.PINNED
    elif _opted_out(os.environ):
        status = NumericsStatus.NATIVE
    else:
        status = NumericsStatus.PARTIAL
    return NumericEnvironment(
        status=status,
        unpinned=tuple(unpinned),
        blas=blas,
        simd=simd,
        libm=libm,
        versions=versions,
        cpu=_cpu_model(),
        canary=canary(),
    )
