"""The XML of an SVG crease pattern, checked before svgelements reads it
(:func:`rigidfold.io.svg_read.read_svg`).

One walk over the XML, without recursion: elements nested deeper than
``Settings.limits.max_svg_depth``, a drawing larger than ``Settings.limits.max_svg_size`` once
its ``<use>`` elements are expanded (a loop of them named), an ``<svg>`` ``width`` or
``height`` that is not a positive finite length, a ``viewBox`` that is not four finite numbers
with a positive size, path data that is not commands and numbers, and a ``transform`` that
is not transform functions of finite numbers are refused in one line, before svgelements
sees them (it would fail with a RecursionError, ZeroDivisionError, IndexError or TypeError,
or take minutes).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ElementTree

import svgelements as se

from rigidfold.config import Settings
from rigidfold.errors import RigidfoldError

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_LENGTH = re.compile(rf"\s*({_NUMBER})\s*([A-Za-z%]*)\s*")
_SEPARATORS = re.compile(r"[\s,]+")
_TRANSFORM_NUMBERS = {
    "matrix": (6,),
    "translate": (1, 2),
    "translatex": (1,),
    "translatey": (1,),
    "scale": (1, 2),
    "scalex": (1,),
    "scaley": (1,),
    "rotate": (1, 3),
    "skew": (1, 2),
    "skewx": (1,),
    "skewy": (1,),
}
"""How many numbers each transform function of svgelements takes."""


def check_xml(data: bytes, settings: Settings) -> None:
    """Walk the XML once before svgelements reads it, without recursion: ValueError for
    elements nested deeper than ``settings.limits.max_svg_depth``, for the attributes svgelements
    would fail on with a ZeroDivisionError, IndexError or TypeError
    (:func:`_check_attributes`), and for a drawing larger than ``settings.limits.max_svg_size``
    once its ``<use>`` elements are expanded (:func:`_expanded_size`: a loop of them is
    named); ``ElementTree.ParseError`` for text that is not XML."""
    parser: ElementTree.XMLPullParser = ElementTree.XMLPullParser(events=("start", "end"))
    # per open element: [its size and its children's, {id: <use>s of it}]
    # (Settings.limits.max_svg_size)
    stack: list[list] = [[0, {}]]
    found: dict[str, list[tuple[int, dict[str, int]]]] = {}
    step = 1 << 16
    for start in range(0, len(data) + 1, step):
        if start < len(data):
            parser.feed(data[start : start + step])
        else:
            parser.close()
        for event in parser.read_events():
            kind, element = event[0], event[-1]
            if not isinstance(element, ElementTree.Element):
                continue  # only "start" and "end" events are asked for
            if kind == "end":
                size, uses = stack.pop()
                key = element.get("id")
                if key is not None:
                    found.setdefault(key, []).append((size, uses))
                parent = stack[-1]
                parent[0] += size
                for target, count in uses.items():
                    parent[1][target] = parent[1].get(target, 0) + count
                element.clear()
                continue
            if len(stack) > settings.limits.max_svg_depth:
                raise RigidfoldError(
                    f"its elements nest more than {settings.limits.max_svg_depth} levels deep (at "
                    f"<{_local(element.tag)}>; Settings.limits.max_svg_depth)"
                )
            _check_attributes(element)
            size = ELEMENT_SIZE + sum(len(value) for value in element.attrib.values())
            used: dict[str, int] = {}
            if _local(element.tag) == "use":
                target = element.get(_XLINK_HREF, element.get("href", ""))
                if target.startswith("#"):
                    used[target[1:]] = 1
            stack.append([size, used])
    size, uses = stack[0]
    total = _expanded_size(size, uses, found, settings.limits.max_svg_size)
    if total > settings.limits.max_svg_size:
        raise RigidfoldError(
            f"its elements are larger than {settings.limits.max_svg_size} characters of attributes "
            f"and {ELEMENT_SIZE} per element, each <use> counted as what it refers to "
            "(Settings.limits.max_svg_size)"
        )


ELEMENT_SIZE = 100
"""What one element adds to the size of a drawing besides its attributes' characters
(``Settings.limits.max_svg_size``): svgelements takes about as long to read an element as to read
a hundred characters of path data."""
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"


def _expanded_size(
    size: int,
    uses: dict[str, int],
    found: dict[str, list[tuple[int, dict[str, int]]]],
    limit: int,
) -> int:
    """``size`` plus what the ``<use>`` elements counted in ``uses`` ({id: how many}) refer
    to, each element with an id in ``found`` ([(its size, its uses)], the largest if several
    share the id) expanded likewise, without recursion; at most ``limit + 1`` (it stops
    there). ValueError naming an id whose element uses itself, directly or not."""
    cap = limit + 1
    sizes: dict[str, int] = {}
    for first in uses:
        todo, open_ = [first], {first}
        while todo:
            key = todo[-1]
            if key in sizes or key not in found:
                sizes.setdefault(key, 0)  # an unknown id draws nothing
                todo.pop()
                open_.discard(key)
                continue
            waiting = [t for _, inner in found[key] for t in inner if t not in sizes or t in open_]
            loop = [t for t in waiting if t in open_]
            if loop:
                raise RigidfoldError(
                    f'its <use> elements refer to each other in a loop (through id="{loop[0]}")'
                )
            if waiting:
                todo += waiting
                open_.update(waiting)
                continue
            sizes[key] = max(
                min(cap, own + sum(count * sizes[t] for t, count in inner.items()))
                for own, inner in found[key]
            )
            todo.pop()
            open_.discard(key)
    return min(cap, size + sum(count * sizes[t] for t, count in uses.items()))


def _check_attributes(element: ElementTree.Element) -> None:
    """ValueError naming the element and the value for a ``width`` or ``height`` of an
    ``<svg>`` that is not a positive finite length, a ``viewBox`` that is not four finite
    numbers with a positive width and height, and a ``transform`` that is not a list of
    transform functions of finite numbers."""
    tag = _local(element.tag)
    key = element.get("id")
    name = f'<{tag} id="{key}">' if key else f"<{tag}>"
    if tag == "svg":
        for size in ("width", "height"):
            text = element.get(size)
            length = None if text is None else _LENGTH.fullmatch(text)
            if text is not None and not (length and 0 < float(length[1]) < math.inf):
                raise RigidfoldError(
                    f'{name} has {size}="{text}": a {size} is a positive finite length, such '
                    "as 210mm or 800"
                )
    text = element.get("viewBox")
    if text is not None and text.strip():
        try:
            box = [float(v) for v in _SEPARATORS.split(text.strip())]
        except ValueError:
            box = []
        if not (len(box) == 4 and all(map(math.isfinite, box)) and min(box[2:]) > 0):
            raise RigidfoldError(
                f'{name} has viewBox="{text}": a viewBox is four finite numbers "min-x min-y '
                'width height", the width and height positive'
            )
    if tag == "path":
        text = element.get("d")
        if text is None or not _path_data_ok(text):
            flat = " ".join((text or "").split())  # the data's newlines and tabs as spaces
            shown = "no d" if text is None else f'd="{flat[:40]}{"..." if len(flat) > 40 else ""}"'
            raise RigidfoldError(
                f"{name} has {shown}: path data is moveto, lineto and closepath commands (M, "
                "L, H, V, Z) and numbers, starting with M"
            )
    text = element.get("transform")
    if text is not None and not _transform_ok(text):
        raise RigidfoldError(
            f'{name} has transform="{text}": a transform is a list of matrix(a,b,c,d,e,f), '
            "translate, scale, rotate, skewX or skewY of finite numbers"
        )


_PATH_TOKEN = re.compile(rf"({_NUMBER})|([A-Za-z])|[\s,]+|(.)", re.DOTALL)


def _path_data_ok(text: str) -> bool:
    """Whether svgelements reads the path data ``text`` as written: empty, or M first, then
    commands each followed by numbers (Z by none). A command without its numbers, a word in
    place of a number (``nan``) and no leading M end in its TypeError or AttributeError.
    Curves pass here and are refused later by name. Linear in the text."""
    command, numbers = "", 0
    for number, letter, other in _PATH_TOKEN.findall(text):
        if other:
            return False
        if letter:
            if letter not in "MmLlHhVvCcSsQqTtAaZz" or (not command and letter not in "Mm"):
                return False
            if command and command not in "Zz" and not numbers:
                return False
            command, numbers = letter, 0
        elif number:
            if not command or command in "Zz":
                return False
            numbers += 1
    return not command or command in "Zz" or numbers > 0


def _transform_ok(text: str) -> bool:
    """Whether svgelements reads the transform attribute ``text`` as written: only transform
    functions, each with as many finite numbers as it takes (``"none"`` is none)."""
    text = text.lower()
    if text.strip() in ("", "none"):
        return True
    if _SEPARATORS.sub("", se.REGEX_TRANSFORM_TEMPLATE.sub("", text)):
        return False  # something besides the functions: unknown words, a missing bracket
    for function, arguments in se.REGEX_TRANSFORM_TEMPLATE.findall(text):
        numbers = [float(v) for v, _ in se.REGEX_TRANSFORM_PARAMETER.findall(arguments)]
        if _SEPARATORS.sub("", se.REGEX_TRANSFORM_PARAMETER.sub("", arguments)):
            return False  # something besides numbers: nan, inf, words
        if len(numbers) not in _TRANSFORM_NUMBERS[function]:
            return False
        if not all(map(math.isfinite, numbers)):
            return False
    return True


def _local(tag: str) -> str:
    """An XML tag without its namespace: ``{http://www.w3.org/2000/svg}g`` -> ``g``."""
    return tag.rpartition("}")[2]
