"""The demo case takes the same path under every OpenBLAS kernel this CPU can run.

Runs ``rigidfold generate --surface bezier --seed 1 --pattern 1 --criterion shat --no-deform``
as a user would start it, with ``OPENBLAS_CORETYPE`` unset and set to each kernel the CPU
supports (at least Prescott and Nehalem; Haswell and Zen with AVX2, SkylakeX with AVX-512),
and compares the counters, both mean F (every digit) and the numeric environment's key.
Exit 1 when any differs: a result that depends on the machine fails here, on the
developer's own machine. ``make same-path``; run by ``.ci/run``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

COMMAND = [
    "generate", "--surface", "bezier", "--seed", "1", "--pattern", "1", "--criterion", "shat",
    "--no-deform",
]  # fmt: skip
COMPARED = ("n_reduce", "n_lock", "n_exceed", "n_path", "n_backtrack", "n_solves",
            "final_dof", "mean_f_accepted", "mean_f_all_solves", "final_deploys")  # fmt: skip
PINS = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "NPY_ENABLE_CPU_FEATURES",
        "NPY_DISABLE_CPU_FEATURES", "GLIBC_TUNABLES", "RIGIDFOLD_NUMERICS",
        "RIGIDFOLD_NUMERICS_RESTARTED")  # fmt: skip


def kernels() -> list[str | None]:
    flags: set[str] = set()
    with open("/proc/cpuinfo", encoding="utf-8") as f:
        for line in f:
            if line.startswith("flags"):
                flags = set(line.split(":", 1)[1].split())
                break
    out: list[str | None] = [None, "Prescott", "Nehalem"]
    if {"avx2", "fma"} <= flags:
        out += ["Haswell", "Zen"]
    if "avx512f" in flags:
        out.append("SkylakeX")
    return out


def run(kernel: str | None, out: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in PINS}
    if kernel:
        env["OPENBLAS_CORETYPE"] = kernel
    rigidfold = Path(sys.executable).with_name("rigidfold")
    proc = subprocess.run(
        [str(rigidfold), *COMMAND, "--out", str(out)],
        env=env, capture_output=True, text=True, check=False, timeout=900,
    )  # fmt: skip
    if proc.returncode != 0:
        sys.exit(f"same_path: {kernel or 'own kernel'}: exit {proc.returncode}: "
                 f"{proc.stderr.strip().splitlines()[-1:]}")  # fmt: skip
    summary = json.loads((out / "summary.json").read_text())
    return {k: summary[k] for k in COMPARED} | {"numerics": summary["numerics"]["key"]}


def main() -> int:
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for kernel in kernels():
            name = kernel or "(own)"
            results[name] = run(kernel, Path(tmp) / name)
            r = results[name]
            print(f"{name:10s} N_lock {r['n_lock']}  solves {r['n_solves']}  "
                  f"mean F {r['mean_f_accepted']!r}  numerics {r['numerics']}",
                  flush=True)  # fmt: skip
    first = next(iter(results.values()))
    differ = [name for name, r in results.items() if r != first]
    if differ:
        print(f"same_path: FAILED: {', '.join(differ)} differ from {next(iter(results))}")
        return 1
    print(f"same_path: the same path under {len(results)} OpenBLAS kernels")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
