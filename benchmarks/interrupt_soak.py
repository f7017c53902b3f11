"""SIGTERM soak at the end of a run (docs/hardening.md, session 43): ``rigidfold generate`` on
the interrupt contract's case (``tests/test_interrupt_contract.py``) is signalled again and
again shortly after it writes its final design's FOLD file (where the exports import trimesh
and manifold3d lazily), two runs at a time, for ``--seconds``; every exit code is counted.
Each run writes Python's fault handler to a file beside it, so a crash (exit -11) leaves its
traceback: ``--work DIR`` keeps them. Load the machine's other cores (the test suite, busy
loops) to move the signal over the stages as a loaded CI machine does.

Usage::

    python benchmarks/interrupt_soak.py [--seconds 600] [--work DIR]
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_interrupt_contract import CASE, FINAL

DELAYS = (0.1, 0.12, 0.14, 0.15, 0.16, 0.18, 0.2, 0.25)
"""Seconds after the final design's FOLD file appears, in turn."""
WRAPPER = (
    "import faulthandler, os, runpy, sys\n"
    "faulthandler.enable(open(os.environ['SOAK_FAULTS'], 'w'), all_threads=True)\n"
    "sys.argv = ['rigidfold'] + sys.argv[1:]\n"
    "runpy.run_module('rigidfold.cli', run_name='__main__')\n"
)


def signalled(work: Path, k: int) -> int:
    """Run ``k``: the case, SIGTERM at its delay after the final FOLD file; the exit code."""
    out = work / f"run{k}"
    env = dict(os.environ, SOAK_FAULTS=str(work / f"faults{k}.txt"))
    cmd = [sys.executable, "-c", WRAPPER, *CASE, "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    marker = out / f"{FINAL}.fold"
    while not marker.exists() and proc.poll() is None:
        time.sleep(0.002)
    t0 = time.monotonic()
    while time.monotonic() - t0 < DELAYS[k % len(DELAYS)] and proc.poll() is None:
        time.sleep(0.002)
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    return proc.wait(timeout=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=600.0, help="how long to go on")
    parser.add_argument("--work", type=Path, default=None, help="keep the runs here")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        codes: Counter[int] = Counter()
        end, k = time.monotonic() + args.seconds, 0
        with ThreadPoolExecutor(2) as pool:
            while time.monotonic() < end:
                for code in pool.map(lambda j: signalled(work, j), (k, k + 1)):
                    codes[code] += 1
                k += 2
        crashes = sum(n for code, n in codes.items() if code not in (0, 130))
        print(f"{k} runs signalled: exit codes {dict(sorted(codes.items()))}; {crashes} crashes")


if __name__ == "__main__":
    main()
