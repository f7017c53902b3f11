"""A damaged binary STL, a long file name in a multi-byte script, Ctrl-C while the libraries
load: one-line answers, no traceback (issue 30, item 19)."""

from __future__ import annotations

import struct
import sys

import numpy as np
import pytest

from rigidfold.cli import launch
from rigidfold.io import atomic_write
from rigidfold.surfaces.mesh import read_mesh

TRIANGLE = struct.pack("<3f", 0, 0, 1) + np.eye(3, dtype="<f4").tobytes() + b"\0\0"
"""One binary STL triangle record: normal, three corners, attribute bytes (50 bytes)."""


def binary_stl(count: int, records: int, tail: bytes = b"") -> bytes:
    return b"\0" * 80 + struct.pack("<I", count) + TRIANGLE * records + tail


def test_binary_stl_reads(tmp_path):
    path = tmp_path / "one.stl"
    path.write_bytes(binary_stl(1, 1))
    vertices, triangles = read_mesh(path)
    assert vertices.shape == (3, 3) and triangles.tolist() == [[0, 1, 2]]


@pytest.mark.parametrize(
    ("data", "found"),
    [
        (binary_stl(1000, 2), "its header counts 1000 triangles, 50084 bytes, but it has 184"),
        (binary_stl(2, 2, b"xx"), "its header counts 2 triangles, 184 bytes, but it has 186"),
        (binary_stl(2, 1)[:100], "its header counts 2 triangles, 184 bytes, but it has 100"),
        (b"\0" * 50, "it has 50 bytes, fewer than the 84 of a binary STL header"),
        (b"solid x\n\xff\xfe" + b"\0" * 90, "its header counts"),
    ],
    ids=["count too large", "two bytes more", "cut short", "no header", "solid, not text"],
)
def test_damaged_binary_stl_is_named(tmp_path, data, found):
    """A binary STL whose triangle count lies (trimesh read it as text and failed with "No
    module named 'charset_normalizer'") is called damaged, in one line."""
    path = tmp_path / "damaged.stl"
    path.write_bytes(data)
    with pytest.raises(ValueError) as info:
        read_mesh(path)
    message = str(info.value)
    assert message.startswith(f"mesh {path}: a damaged binary STL (") and found in message
    assert "charset" not in message and "\n" not in message


def test_ascii_stl_still_reads(tmp_path):
    path = tmp_path / "text.stl"
    path.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid t\n"
    )
    vertices, triangles = read_mesh(path)
    assert len(vertices) == 3 and len(triangles) == 1


def test_long_multibyte_file_name(tmp_path):
    """80 CJK characters are 240 bytes, a legal name: its temporary name is cut by bytes (it
    was cut at 200 characters, 600 bytes: "File name too long")."""
    name = "折" * 80
    path = atomic_write(tmp_path / name, "text")
    assert path.read_text() == "text" and [p.name for p in tmp_path.iterdir()] == [name]
    mixed = "é" * 99 + "折" * 10 + ".txt"  # 198 + 30 + 4 bytes, cut within the 折
    assert atomic_write(tmp_path / mixed, b"x").read_bytes() == b"x"


def test_ctrl_c_while_the_libraries_load(monkeypatch, capsys):
    """Ctrl-C while the command line and its libraries are imported exits 130 with one line."""

    class Interrupt:
        def find_spec(self, name, path=None, target=None):
            if name == "rigidfold.cli.commands":
                raise KeyboardInterrupt
            return None

    monkeypatch.delitem(sys.modules, "rigidfold.cli.commands", raising=False)
    monkeypatch.setattr(sys, "meta_path", [Interrupt(), *sys.meta_path])
    assert launch.main(["--version"]) == 130
    assert capsys.readouterr().err == "rigidfold: interrupted\n"
