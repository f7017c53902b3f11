"""Output files (io/files.py): output directory, atomic writes, JSON data."""

from __future__ import annotations

import json
import math
import os
import stat

import numpy as np
import pytest

from rigidfold.io import (
    atomic_write,
    jsonable,
    prepare_output_dir,
    refuse_replacing_inputs,
    write_json,
)
from rigidfold.outcomes import Outcome


class Color(Outcome):
    RED = "red", "a colour"


def test_atomic_write_text_and_bytes(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    assert atomic_write(path, "néw\n") == path
    assert path.read_bytes() == "néw\n".encode()
    atomic_write(str(path), b"\x00\xff")
    assert path.read_bytes() == b"\x00\xff"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_atomic_write_creates_files_like_any_other(tmp_path):
    """The temporary file is created with the umask's permissions, not mkstemp's 0600."""
    new, plain = tmp_path / "new.txt", tmp_path / "plain.txt"
    atomic_write(new, "x")
    plain.write_text("x")
    assert stat.S_IMODE(new.stat().st_mode) == stat.S_IMODE(plain.stat().st_mode)


def test_atomic_write_replaces_a_link_without_following_it(tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text("keep")
    (tmp_path / "out").mkdir()
    link = tmp_path / "out" / "a.txt"
    link.symlink_to(outside)
    (tmp_path / "out" / "a.txt.tmp").symlink_to(outside)  # the old fixed temporary name
    atomic_write(link, "new")
    assert outside.read_text() == "keep"
    assert not link.is_symlink() and link.read_text() == "new"


def test_atomic_write_error_leaves_nothing(tmp_path):
    """The cases of test_fold.py::test_write_fold_unwritable, and: the path is quoted."""
    path = tmp_path / "dir"
    path.mkdir()
    with pytest.raises(ValueError, match=r"^cannot write '.+': \w") as info:
        atomic_write(path, "text")
    assert str(info.value) == f"cannot write '{path}': Is a directory"
    assert [p.name for p in tmp_path.iterdir()] == ["dir"] and list(path.iterdir()) == []


def test_atomic_write_needs_str_or_bytes(tmp_path):
    with pytest.raises(ValueError, match=r"data must be str or bytes, got dict"):
        atomic_write(tmp_path / "a", {})
    assert list(tmp_path.iterdir()) == []


def test_prepare_output_dir(tmp_path):
    out = prepare_output_dir(tmp_path / "a" / "b")
    assert out.is_dir() and list(out.iterdir()) == []
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match=r"^cannot write to output directory '.+file': "):
        prepare_output_dir(tmp_path / "file")


def test_prepare_output_dir_probe_does_not_follow_links(tmp_path):
    target = tmp_path / "target"
    target.write_text("keep")
    out = tmp_path / "out"
    out.mkdir()
    (out / ".rigidfold-write-test").symlink_to(target)  # the old fixed probe name
    prepare_output_dir(out)
    assert target.read_text() == "keep"
    assert [p.name for p in out.iterdir()] == [".rigidfold-write-test"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_prepare_output_dir_read_only(tmp_path):
    tmp_path.chmod(0o500)
    try:
        with pytest.raises(ValueError, match=r"cannot write to output directory .*: Permission"):
            prepare_output_dir(tmp_path)
    finally:
        tmp_path.chmod(0o700)


def test_jsonable_rules():
    value = {
        1: (np.float32(0.5), np.int64(3), np.bool_(False), np.str_("s")),
        "array": np.array([[1.0, np.nan], [np.inf, -2.0]]),
        "scalar array": np.array(7),
        "nested": [{"x": -math.inf}, None, True, "t", 4, Color.RED],
    }
    clean = jsonable(value)
    assert clean == {
        "1": [0.5, 3, False, "s"],
        "array": [[1.0, None], [None, -2.0]],
        "scalar array": 7,
        "nested": [{"x": None}, None, True, "t", 4, "red"],
    }
    assert type(clean["1"][1]) is int and type(clean["1"][2]) is bool
    json.dumps(clean, allow_nan=False)


@pytest.mark.parametrize("bad", [{1, 2}, object(), np.datetime64("2024-01-01"), b"x"])
def test_jsonable_refuses_what_is_not_json(bad):
    with pytest.raises(ValueError, match=r"^metadata 'k' holds a \w+, which is not JSON data$"):
        jsonable({"a": [bad]}, where="metadata 'k'")


def test_write_json(tmp_path):
    path = tmp_path / "s.json"
    assert write_json(path, {"F": np.float64(np.nan), "n": np.int32(2)}) == path
    assert path.read_text() == '{\n  "F": null,\n  "n": 2\n}\n'
    with pytest.raises(ValueError, match=r"the JSON data of '.+s\.json' holds a set"):
        write_json(path, {"x": {1}})
    assert json.loads(path.read_text()) == {"F": None, "n": 2}


def test_refuse_replacing_inputs(tmp_path):
    """An output that is an input, by its own name, through a symbolic link to it or from it,
    or as a hard link, is refused; naming the input. An output that is not there yet is
    compared by its resolved path."""
    given = tmp_path / "in.fold"
    given.write_text("{}")
    (tmp_path / "sub").mkdir()
    link = tmp_path / "sub" / "link.fold"
    link.symlink_to(given)
    hard = tmp_path / "hard.fold"
    os.link(given, hard)
    for inp, out in (
        (given, given),
        (given, tmp_path / "sub" / ".." / "in.fold"),
        (link, given),
        (given, link),
        (hard, given),
    ):
        with pytest.raises(ValueError, match=f"would replace the input file '{inp}'"):
            refuse_replacing_inputs([tmp_path / "other.fold", inp], [tmp_path / "x.svg", out])
    refuse_replacing_inputs([given], [tmp_path / "new" / "in.fold", tmp_path / "in.svg"])
    refuse_replacing_inputs([], [given])
