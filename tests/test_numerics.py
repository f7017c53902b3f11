"""Reproducible numerics (rigidfold.runtime.numerics): the tests run pinned, every entry point pins,
and the canary tells each CPU-dependent part of the floating point apart.

The counts and digits of one generation path that other tests assert (the demo's N_lock,
the README's printed lines) hold on every x86-64 CPU because of what is checked here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import rigidfold
from rigidfold.runtime import numerics
from rigidfold.runtime.numerics import (
    BLAS_KERNEL_NAMES,
    OPT_OUT_ENV,
    RESTARTED_ENV,
    NumericsStatus,
    numeric_environment,
    pinned_environ,
)
from rigidfold.study.markdown import markdown
from rigidfold.study.runner import check_worker_numerics
from rigidfold.study.store import Key, Store

PIN_VARS = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "NPY_ENABLE_CPU_FEATURES", "GLIBC_TUNABLES")
X86_LINUX = numerics._supported()


def cpu_flags() -> set[str]:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("flags"):
                    return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return set()


FLAGS = cpu_flags()


def unpinned_env(**extra: str) -> dict[str, str]:
    """This process's environment without any pin, as a user's shell would have it."""
    env = {k: v for k, v in os.environ.items() if k not in (*PIN_VARS, RESTARTED_ENV)}
    env.pop("NPY_DISABLE_CPU_FEATURES", None)
    env.pop(OPT_OUT_ENV, None)
    env.update(extra)
    return env


def child_environment(env: dict[str, str]) -> dict:
    """numeric_environment() of ``python -m rigidfold.pinned`` started with ``env``."""
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.pinned"],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


needs_x86 = pytest.mark.skipif(not X86_LINUX, reason="numerics are pinned on x86-64 Linux only")


@needs_x86
def test_the_tests_run_with_pinned_numerics():
    env = numeric_environment()
    assert env.status is NumericsStatus.PINNED, env.unpinned
    assert env.pinned and env.unpinned == ()
    assert env.simd == "baseline"
    assert env.libm.endswith("hwcaps -AVX,-AVX2,-FMA,-FMA4")
    kernels = [b.rsplit(" ", 1)[-1] for b in env.blas if "casadi" not in b]
    assert kernels and all(k in BLAS_KERNEL_NAMES for k in kernels)
    assert len(env.canary) == 16 and env.canary in env.key
    d = env.to_dict()
    assert d["status"] == "pinned" and d["key"] == env.key and d["cpu"]


def coretypes() -> list[str | None]:
    """OpenBLAS kernels this CPU can run, besides its own choice (None)."""
    kinds: list[str | None] = [None, "Prescott", "Nehalem"]
    if "avx2" in FLAGS and "fma" in FLAGS:
        kinds += ["Haswell", "Zen"]
    if "avx512f" in FLAGS:
        kinds.append("SkylakeX")
    return kinds


@needs_x86
@pytest.mark.parametrize("coretype", coretypes())
def test_a_process_started_with_any_kernel_computes_the_same_bits(coretype):
    """Started as a user would (any OPENBLAS_CORETYPE, no pins), an entry point restarts
    itself pinned and computes the canary of this test process."""
    env = unpinned_env(**({"OPENBLAS_CORETYPE": coretype} if coretype else {}))
    child = child_environment(env)
    assert child["status"] == "pinned", child["unpinned"]
    assert child["canary"] == numeric_environment().canary
    assert child["key"] == numeric_environment().key


@needs_x86
@pytest.mark.parametrize(
    ("part", "unpin", "needs"),
    [
        ("BLAS kernel", {"OPENBLAS_CORETYPE": "Haswell"}, {"avx2", "fma"}),
        ("NumPy SIMD", {"NPY_ENABLE_CPU_FEATURES": None}, {"avx512f", "avx512dq"}),
        ("libm", {"GLIBC_TUNABLES": None}, {"fma", "avx2"}),
    ],
)
def test_the_canary_sees_each_part_that_follows_the_cpu(part, unpin, needs):
    """Each of the three parts, left to the CPU alone, changes the canary (so a key that
    matches is evidence that every part computed the same bits)."""
    if not needs <= FLAGS:
        pytest.skip(f"this CPU lacks {', '.join(sorted(needs - FLAGS))}: {part} is the baseline")
    env = pinned_environ(unpinned_env())
    for name, value in unpin.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    env[OPT_OUT_ENV] = "native"  # keep exactly this environment: no pin, no restart
    child = child_environment(env)
    assert child["status"] != "pinned" and child["unpinned"]
    assert child["canary"] != numeric_environment().canary


@needs_x86
def test_native_opt_out_keeps_the_machine_kernels():
    child = child_environment(unpinned_env(**{OPT_OUT_ENV: "native"}))
    assert child["status"] == "native"
    assert child["libm"].endswith("hwcaps native")


def test_pinned_environ_merges_and_replaces():
    env = pinned_environ(
        {
            "GLIBC_TUNABLES": "glibc.malloc.check=3:glibc.cpu.hwcaps=-AVX512F",
            "OPENBLAS_CORETYPE": "Haswell",
            "NPY_DISABLE_CPU_FEATURES": "X86_V4",
            "HOME": "/x",
        }
    )
    if not X86_LINUX:
        assert env["OPENBLAS_CORETYPE"] == "Haswell"
        return
    assert env["OPENBLAS_CORETYPE"] == "Prescott" and env["HOME"] == "/x"
    assert "NPY_DISABLE_CPU_FEATURES" not in env  # NumPy refuses it beside ENABLE
    tunables = env["GLIBC_TUNABLES"].split(":")
    assert "glibc.malloc.check=3" in tunables
    assert "glibc.cpu.hwcaps=-AVX512F,-AVX,-AVX2,-FMA,-FMA4" in tunables
    assert pinned_environ(env) == env  # idempotent
    assert pinned_environ({OPT_OUT_ENV: "native"}) == {OPT_OUT_ENV: "native"}


NUMERICS_A = {"key": "aaaa numpy=1", "status": "pinned"}
NUMERICS_B = {"key": "bbbb numpy=1", "status": "pinned"}
ROW = {
    "status": "target DOF 1 reached", "n_reduce": 3, "n_lock": 1, "n_exceed": 0,
    "mean_f_accepted": 1e-13, "initial_dof": 4, "final_dof": 1, "n_solutions": 4, "n_solves": 5,
    "time_build": 0.1,
    "time_solve": 1.0, "time_analysis": 0.1, "time_selection": 0.0, "time_total": 1.3,
    "version": "t", "numerics": "aaaa",
}  # fmt: skip


def test_a_study_database_refuses_runs_of_other_numerics(tmp_path):
    db = tmp_path / "s.sqlite"
    with_a = Store(db, {"c": 1}, numerics=NUMERICS_A)
    with_a.add(Key("bezier", 1, "1", "s", False), ROW, [])
    with_a.close()
    before = db.read_bytes()
    with pytest.raises(ValueError, match=r"other numerics|--allow-mixed-numerics") as err:
        Store(db, {"c": 1}, numerics=NUMERICS_B)
    assert "\n" not in str(err.value) and "bbbb" in str(err.value)
    assert db.read_bytes() == before  # refused untouched
    again = Store(db, {"c": 1}, numerics=NUMERICS_A)  # the same numerics resume
    again.close()
    mixed = Store(db, {"c": 1}, numerics=NUMERICS_B, allow_mixed_numerics=True)
    mixed.add(Key("bezier", 2, "1", "s", False), ROW | {"numerics": "bbbb"}, [])
    assert mixed.numerics() == NUMERICS_A  # the first runs' environment is kept
    assert {r.numerics for r in mixed.runs()} == {"aaaa", "bbbb"}
    mixed.close()
    report = markdown(Store(db, readonly=True))
    assert "Numerics: pinned, `aaaa numpy=1`; the runs come from 2 numeric environments" in report


def test_a_database_without_recorded_numerics(tmp_path):
    """Runs of an earlier rigidfold have unknown numerics: refused unless asked; an empty
    database takes this process's."""
    db = tmp_path / "old.sqlite"
    old = Store(db, {"c": 1})
    old.add(Key("bezier", 1, "1", "s", False), ROW, [])
    old.close()
    with pytest.raises(ValueError, match="not recorded"):
        Store(db, {"c": 1}, numerics=NUMERICS_A)
    Store(db, {"c": 1}, numerics=NUMERICS_A, allow_mixed_numerics=True).close()
    empty = tmp_path / "empty.sqlite"
    Store(empty, {"c": 1}, numerics=NUMERICS_B).close()
    store = Store(empty, {"c": 1}, numerics=NUMERICS_A)  # no runs: nothing to mix
    assert store.numerics() == NUMERICS_A
    store.close()


def test_workers_of_other_numerics_are_named():
    check_worker_numerics({"tcp://a:1": "k", "tcp://b:2": "k"}, "k")
    with pytest.raises(ValueError, match=r"tcp://b:2 computes with numerics 'other'"):
        check_worker_numerics({"tcp://a:1": "k", "tcp://b:2": "other"}, "k")


# ------------------------------------------------------ the pin measured; restarts that fail
@needs_x86
def test_the_libm_pin_is_measured():
    """This process (started pinned) computes the pinned libm's bits; one started with the
    machine's own libm is found unpinned where the CPU has the FMA variants."""
    assert numerics.libm_pinned()
    if not {"fma", "avx2"} <= FLAGS:
        pytest.skip("this CPU has no FMA variants: its libm is the pinned one")
    env = pinned_environ(unpinned_env())
    env.pop("GLIBC_TUNABLES")
    env[OPT_OUT_ENV] = "native"
    code = "from rigidfold.runtime.numerics import libm_pinned; print(libm_pinned())"
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert proc.stdout.strip() == "False", proc.stderr


def test_a_restart_that_fails_says_so(monkeypatch, capsys):
    def refused(*args):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(numerics, "restart_wanted", lambda: True)
    monkeypatch.setattr(numerics.os, "execve", refused)
    numerics.restart_pinned()  # carries on
    (line,) = capsys.readouterr().err.splitlines()
    assert "could not restart with the pinned numerics (Permission denied)" in line


def test_pinned_refuses_a_file_it_cannot_run_in_one_line(tmp_path):
    script = tmp_path / "script"
    script.write_text("print('hi')\n")  # no #! line
    script.chmod(0o755)
    proc = subprocess.run(
        [sys.executable, "-m", "rigidfold.pinned", str(script)], capture_output=True, text=True
    )
    assert proc.returncode == 126 and "Traceback" not in proc.stderr
    (line,) = proc.stderr.splitlines()
    assert line.startswith(f"rigidfold.pinned: cannot run {str(script)!r}: ")


def test_a_program_that_calls_the_entry_point_runs_once(tmp_path):
    """rigidfold.cli.launch.main() called from a program does not restart the process (which
    would run the program again from the top); the rigidfold command does."""
    script = tmp_path / "program.py"
    script.write_text(
        "import sys\nprint('top')\nsys.argv[1:] = ['--version']\n"
        "import rigidfold.cli.launch\nraise SystemExit(rigidfold.cli.launch.main())\n"
    )
    proc = subprocess.run(
        [sys.executable, str(script)], env=unpinned_env(), capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == ["top", f"rigidfold {rigidfold.__version__}"]
