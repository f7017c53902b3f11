"""The Python API's front (issue 30, item 26): the package docstring's example runs, and the
user errors that the library's entry points raise are one family, ``RigidfoldError``, a
``ValueError``."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

import rigidfold
from rigidfold import RigidfoldError
from rigidfold.config import DEFAULTS
from rigidfold.exports import check_formats
from rigidfold.generate.case import fixed_mask
from rigidfold.generate.specs import (
    case_from_specs,
    parse_expression,
    parse_pattern,
    parse_surface_spec,
)
from rigidfold.io import read_fold
from rigidfold.pipeline.workflows import analyze_file, report_run
from rigidfold.surfaces import mesh_surface


def test_the_package_docstring_shows_the_generation_function_and_runs():
    doc = rigidfold.__doc__
    assert doc is not None and "generate(case" in doc and "RigidfoldError" in doc
    code = "\n".join(
        line[4:] for line in re.search(r"::\n\n((?:    .*\n|\n)+)", doc)[1].splitlines()
    )
    scope: dict = {}
    exec(code, scope)  # the example as written
    assert scope["run"].final_dof == 1 and scope["design"].n_vertices == 49


def test_rigidfold_error_is_a_value_error_exported_lightly():
    assert issubclass(RigidfoldError, ValueError) and rigidfold.RigidfoldError is RigidfoldError
    code = (
        "import sys, rigidfold; "
        "print(rigidfold.RigidfoldError.__mro__[1].__name__, 'numpy' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["ValueError", "False"]  # import rigidfold stays light


@pytest.mark.parametrize(
    "call",
    [
        lambda tmp: case_from_specs("nosuch", "1"),
        lambda tmp: case_from_specs("dome", "grid:1500x900"),
        lambda tmp: case_from_specs("dome", "grid:3x3", size="axb"),
        lambda tmp: case_from_specs("bezier", "1", seed=-1),
        lambda tmp: parse_pattern("mesh:0,0;1,0"),
        lambda tmp: parse_surface_spec("expr", expr="__import__('os')"),
        lambda tmp: parse_expression("x +* y"),
        lambda tmp: mesh_surface(tmp / "none.obj"),
        lambda tmp: read_fold(tmp / "none.fold"),
        lambda tmp: fixed_mask((0, 99), case_from_specs("dome", "grid:3x3").pattern),
        lambda tmp: check_formats(["obj", "docx"]),
        lambda tmp: DEFAULTS.with_(dz=-1.0),
        lambda tmp: DEFAULTS.with_(theta_min=2.0, theta_max=1.0),
        lambda tmp: analyze_file(tmp / "none.fold"),
        lambda tmp: report_run(tmp / "no-run"),
    ],
)
def test_user_errors_are_rigidfold_errors(call, tmp_path):
    with pytest.raises(RigidfoldError) as info:
        call(tmp_path)
    assert "\n" not in str(info.value) and str(info.value)
