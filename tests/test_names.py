"""File names whose bytes are not UTF-8 (issue 39, item 11): written and read as the names
they are, the documents' text valid UTF-8, no file written before a refusal."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rigidfold.io.files import text_bytes

DATA = Path(__file__).parent / "data"


@pytest.mark.skipif(os.name != "posix", reason="file names as bytes are POSIX's")
def test_fabricate_takes_and_writes_names_that_are_not_utf8(tmp_path):
    raw = os.fsencode(tmp_path) + b"/bad\xff.fold"
    shutil.copy(DATA / "aframe.fold", raw)
    out = os.fsencode(tmp_path) + b"/out\xfe"
    command = [sys.executable, "-m", "rigidfold", "fabricate", raw, "--thickness", "18mm"]
    done = subprocess.run([*command, b"--out", out], capture_output=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert b"bad\xff" in done.stdout  # printed as the bytes it is, as ls does
    names = sorted(os.listdir(out))
    assert b"bad\xff_solids.3dm" in names and b"bad\xff_fabricate.json" in names
    for name in names:  # every text document is valid UTF-8
        if name.endswith((b".dxf", b".svg", b".json", b".csv", b".obj")):
            (Path(os.fsdecode(out)) / os.fsdecode(name)).read_bytes().decode("utf-8")


def test_text_bytes_keeps_utf8_and_replaces_undecodable_bytes():
    assert text_bytes("pli\u00e9") == "pli\u00e9".encode()
    assert text_bytes(os.fsdecode(b"bad\xff")) == "bad\ufffd".encode()
