"""The report in a real browser: headless Chromium, network off (``make test`` installs it)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from chromium import browser, load_page
from rigidfold.cli.commands import main
from rigidfold.pipeline.workflows import report_run

pytestmark = pytest.mark.skipif(
    browser() is None,
    reason="Chromium is not installed: `make test` installs Debian's chromium where apt-get "
    "can (as root); elsewhere install it to run the browser test of the report",
)


def drawn_share(png: bytes, box: tuple[float, float, float, float]) -> float:
    """Share of the pixels in the middle of ``box`` (the 3D scene, without the legend, the
    colour bar and the slider, which are not WebGL) that are not white or light grey."""
    import matplotlib.image

    pixels = matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]
    x, y, w, h = box
    middle = pixels[int(y + 0.15 * h) : int(y + 0.8 * h), int(x + 0.2 * w) : int(x + 0.8 * w)]
    assert middle.size, f"the 3D view's box {box} is outside the screenshot"
    return float(np.mean(middle.min(axis=-1) < 0.8))


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    args = ["generate", "--surface", "dome", "--pattern", "grid:4x4", "--target-dof", "8"]
    assert main([*args, "--quiet", "--no-deform", "--out", str(out)]) == 0
    return report_run(out).html


def test_report_renders_offline_without_any_request(report):
    page = load_page(report)
    assert page.has_webgl, "the 3D view has no WebGL canvas"
    assert drawn_share(page.screenshot, page.plot_box) > 0.05, "the 3D view is blank"
    own = report.resolve().as_uri()
    others = [u for u in page.requests if u != own and not u.startswith("data:image/png;")]
    assert page.requests[0] == own and others == []


def test_a_page_that_loads_something_is_caught(tmp_path):
    bad = tmp_path / "bad.html"
    bad.write_text(
        '<html><body><div id="view3d"></div>'
        '<img src="https://example.invalid/x.png"><script>fetch("http://cdn.invalid/a.js")'
        ".catch(() => {})</script></body></html>"
    )
    page = load_page(bad)
    assert "https://example.invalid/x.png" in page.requests
    assert "http://cdn.invalid/a.js" in page.requests
    assert not page.has_webgl
