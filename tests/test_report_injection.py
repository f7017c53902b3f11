"""Names from the user's files in the documents rigidfold writes (issue 30, item 16): a
pattern named ``q<img src=x onerror=...>.fold`` ran script where results.md is rendered and a
``|`` in it broke the tables; a solution file named with ``<a href=...>`` became a link in
the 3D view's title. They read as text now."""

from __future__ import annotations

import html
from html.parser import HTMLParser

import numpy as np
import pytest

from rigidfold.reporting import view_figure
from rigidfold.rundir import SolutionFile
from rigidfold.study import Key, Store, StudyConfig
from rigidfold.study.markdown import md_code, md_text, write_report
from rigidfold.study.store import RUN_FIELDS

NAMES = [
    "q<img src=x onerror=alert(1)>.fold",
    "a|b.fold",
    "[x](javascript:alert(1)).fold",
    "![i](http://evil.example/i.png).fold",
    "http://evil.example/p.fold",
    "www.evil.example.fold",
    "u_*b*_~~s~~`c`.fold",
    "e\x1b[31mred\nline.fold",
    "back\\|slash.fold",
    "amp&lt;.fold",
]
"""Pattern names that are Markdown or HTML, or break a line or a table row."""


class _Rendered(HTMLParser):
    """The tags, the links, the text and the cells per table row of an HTML document."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.links: list[str] = []
        self.text: list[str] = []
        self.rows: list[list[int]] = []  # per table: cells of each row

    def handle_starttag(self, tag, attrs) -> None:
        self.tags.append(tag)
        self.links += [v for k, v in attrs if k in ("href", "src") and v]
        if tag == "table":
            self.rows.append([])
        elif tag == "tr":
            self.rows[-1].append(0)
        elif tag in ("td", "th"):
            self.rows[-1][-1] += 1

    def handle_data(self, data) -> None:
        self.text.append(data)


def render(markdown: str) -> _Rendered:
    """``markdown`` rendered as GitHub does (CommonMark, tables, raw HTML let through), then
    parsed."""
    markdown_it = pytest.importorskip("markdown_it")
    md = markdown_it.MarkdownIt("commonmark", {"html": True}).enable("table")
    parsed = _Rendered()
    parsed.feed(md.render(markdown))
    return parsed


def test_study_report_writes_pattern_names_as_text(tmp_path):
    db = tmp_path / "s.sqlite"
    store = Store(db, StudyConfig().as_dict())
    numbers = dict.fromkeys(
        (f for f in RUN_FIELDS if f.startswith(("n_", "mean_f", "time_", "initial", "final"))), 1
    )
    for name in NAMES:
        for seed in range(2):
            row = numbers | {
                "stop": "target_reached",
                "status": "target DOF 1 reached",
                "n_lock": seed,
                "version": "t",
            }
            store.add(Key("bezier", seed, name, "s"), row, [])
    store.add(
        Key("bezier", 5, NAMES[0], "s"),
        {
            "status": "error: cannot read <script>alert(1)</script> | [x](javascript:y)",
            "version": "t",
        },
        [],
    )
    argv = ["rigidfold", "study", "--patterns", "a|b.fold,`x`,<b>y</b>"]
    store.add_invocation(
        started="2026", argv=argv, workers=1, scheduler=None, ran=1, skipped=0, total=1,
        wall_s=1.0, outcome="completed <i>x</i>", version="<b>v</b>",
    )  # fmt: skip
    store.close()
    reader = Store(db, readonly=True)
    path = write_report(reader, tmp_path / "rep")
    reader.close()
    text = path.read_text()
    page = render(text)
    made = {"script", "a", "b", "i", "em", "strong", "del", "s"} & set(page.tags)
    assert not made, made
    assert [t for t in page.tags if t == "img"] == ["img"] * len(NAMES)  # the box plots only
    assert all(link.endswith(".png") and "/" not in link for link in page.links), page.links
    assert page.tags.count("code") == 2  # the numerics key and the command
    for table in page.rows:  # every row of a table has the cells of its head
        assert len(set(table)) == 1, table
    shown = "".join(page.text)
    for name in NAMES:
        assert name.replace("\x1b", "\\x1b").replace("\n", "\\n") in shown, name
    assert "cannot read <script>alert(1)</script> | [x](javascript:y)" in shown
    assert "rigidfold study --patterns a|b.fold,`x`,<b>y</b>" in shown
    assert "completed <i>x</i>" in shown and "<b>v</b>" in shown
    assert "\x1b" not in text


def test_markdown_escapes():
    assert md_text("a|b") == "a\\|b"
    assert md_text("<i>&") == "&lt;i&gt;&amp;"
    assert md_text("x\ny\x1b") == "x\\\\ny\\\\x1b"
    assert md_text("see https://x.org or WWW.x.org") == "see https:\\/\\/x.org or WWW\\.x.org"
    assert md_code("plain") == "`plain`"
    assert md_code("a ``b`` |c", cell=True) == "```a ``b`` \\|c```"
    assert md_code("`x`") == "`` `x` ``"


def test_the_3d_views_title_shows_the_file_name_as_text():
    name = 'solutions/<a href="https:/evil.example">x</a>.fold'
    design = SolutionFile(
        name=name,
        step=0,
        dof=1,
        coords=np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]),
        faces=np.array([[0, 1, 2]]),
        edges=np.array([[0, 1], [1, 2], [2, 0]]),
        assignment=["B", "B", "B"],
        fold_deg=np.zeros(3),
        coords2d=None,
        motion=np.zeros((0, 3, 3)),
        fraction=np.zeros(0),
        history=[],
    )
    title = view_figure(design, None)["layout"]["title"]["text"]
    assert "<" not in title and ">" not in title
    assert html.unescape(title) == f"{name}: DOF 1"  # plotly.js shows the entities as text
