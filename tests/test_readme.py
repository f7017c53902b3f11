"""The README's Python example runs as written (and prints what its comments say)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_python_example_runs(capsys):
    blocks = python_blocks()
    assert blocks, "the README has no ```python example"
    namespace: dict = {}
    for code in blocks:
        exec(compile(code, str(README), "exec"), namespace)
    status, F, n_variables = capsys.readouterr().out.split()
    assert status == "converged" and float(F) < 1e-7 and int(n_variables) == 83
    assert namespace["check"].motion.frames.shape[1:] == (namespace["shape"].n_vertices, 3)
