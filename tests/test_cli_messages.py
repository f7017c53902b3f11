"""Every user-error message of the command line is one line, control characters escaped."""

from __future__ import annotations

import unicodedata

import pytest

from rigidfold.cli.commands import main, one_line


def control_free(text: str) -> bool:
    return not any(unicodedata.category(ch) in ("Cc", "Zl", "Zp") for ch in text)


def run(argv: list[str], capsys) -> tuple[int, str]:
    """(exit code, stderr) of ``rigidfold ARGV``, argparse's own exits included."""
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    return code, capsys.readouterr().err


def test_one_line_escapes_control_characters():
    assert one_line("a\nb\r\tc\x1b[2J\x00\x7f\x85\u2028\u2029d") == (
        "a\\nb\\r\\tc\\x1b[2J\\x00\\x7f\\x85\\u2028\\u2029d"
    )
    assert one_line("plain text, é, 折り紙 and a \\ backslash") == (
        "plain text, é, 折り紙 and a \\ backslash"
    )


def test_svg_id_with_a_newline_and_escape(tmp_path, capsys):
    """An SVG id with &#10; and &#x9b; (a newline and CSI in the message before) is escaped."""
    path = tmp_path / "p.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="9" height="9" '
        'stroke="black"/><line id="evil&#10;rigidfold: all good&#x9b;2J" x1="0" y1="0" '
        'x2="9" y2="9" stroke="cyan"/></svg>'
    )
    code, err = run(
        ["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path / "o")],
        capsys,
    )
    assert code == 2 and err.count("\n") == 1 and control_free(err[:-1]), err
    assert '<line id="evil\\nrigidfold: all good\\x9b2J"> has stroke colour cyan' in err


@pytest.mark.parametrize("name", ["bad\x1b]0;owned\x07name.fold", "two\nlines.fold"])
def test_file_names_with_control_characters(tmp_path, capsys, name):
    code, err = run(["analyze", str(tmp_path / name)], capsys)
    assert code == 2 and err.count("\n") == 1 and control_free(err[:-1]), err
    assert one_line(name) in err


def test_argparse_errors_are_escaped(capsys):
    code, err = run(
        [
            "optimize",
            "--surface",
            "dome",
            "--pattern",
            "1",
            "--diagonals",
            "x\x1b[31m\ny",
            "--out",
            "o",
        ],
        capsys,
    )
    assert code == 2 and err.count("\n") == 1 and control_free(err[:-1]), err
    assert "invalid choice: 'x\\x1b[31m\\ny'" in err
