"""Headless Chromium driven over the DevTools protocol, for the report's browser test.

:func:`load_page` opens a local HTML file in a fresh headless Chromium (its own profile, no
host name resolves: ``--host-resolver-rules=MAP * ~NOTFOUND``), waits for the plotly view to
draw, and returns a screenshot, the box of the 3D view and every request the page made
(``Network.requestWillBeSent``: its own file, ``data:`` URIs, anything else). The protocol
runs over ``--remote-debugging-pipe`` (file descriptors 3 and 4, NUL-terminated JSON), so no
port is opened.

Run as a script to save a screenshot (docs/report_screenshot.png is the demo's):
``python tests/chromium.py REPORT.html OUT.png``.
"""

from __future__ import annotations

import base64
import fcntl
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

BROWSERS = ("chromium", "chromium-browser", "google-chrome")

WAIT_FOR_PLOT = """new Promise(done => {
  const start = Date.now();
  const gl = () => {
    const c = document.querySelector('#view3d .gl-container canvas');
    return !!(c && (c.getContext('webgl2') || c.getContext('webgl')));
  };
  (function poll() {
    if ((gl() && document.readyState === 'complete') || Date.now() - start > 20000) {
      requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(() => done(gl()), 500)));
    } else {
      setTimeout(poll, 100);
    }
  })();
})"""
"""Resolves, once the page has drawn its 3D view (20 s at most), to whether the view's canvas
has a WebGL context (plotly's 3D scene draws there)."""


def browser() -> str | None:
    """The Chromium executable on PATH, None when there is none."""
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


@dataclass(frozen=True)
class PageLoad:
    """screenshot : PNG bytes of the viewport; plot_box : (x, y, width, height) of the 3D
    view in CSS pixels (device scale 1); has_webgl : the view's canvas has a WebGL context;
    requests : the URL of every request the page made, in order."""

    screenshot: bytes
    plot_box: tuple[float, float, float, float]
    has_webgl: bool
    requests: list[str]


class _Pipe:
    """The DevTools protocol over Chromium's pipe: ``call`` sends a command and returns its
    result; events that arrive meanwhile are kept in ``events``."""

    def __init__(self, write_fd: int, read_fd: int) -> None:
        self.write, self.read = write_fd, read_fd
        self.buffer, self.next_id, self.events = b"", 0, []

    def call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.write, json.dumps(message).encode() + b"\0")
        while True:
            while b"\0" not in self.buffer:
                chunk = os.read(self.read, 1 << 20)
                if not chunk:
                    raise RuntimeError(f"Chromium closed the pipe during {method}")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)


def load_page(path: Path, *, width: int = 1200, height: int = 900) -> PageLoad:
    """Open ``path`` in headless Chromium with the network off (see the module's text)."""
    exe = browser()
    if exe is None:
        raise RuntimeError("no Chromium on PATH")
    to_browser_r, to_browser_w = map(_above_4, os.pipe())
    from_browser_r, from_browser_w = map(_above_4, os.pipe())
    with tempfile.TemporaryDirectory(prefix="rigidfold-chromium-") as scratch:
        log = Path(scratch) / "chromium.log"
        args = [
            exe,
            "--headless=new",
            "--no-sandbox",
            "--disable-gpu",
            "--remote-debugging-pipe",
            "--host-resolver-rules=MAP * ~NOTFOUND",
            "--no-first-run",
            "--disable-extensions",
            "--disable-background-networking",
            f"--user-data-dir={Path(scratch) / 'profile'}",
            f"--window-size={width},{height}",
            "about:blank",
        ]
        with log.open("wb") as err:
            proc = subprocess.Popen(
                ["bash", "-c", f'exec "$0" "$@" 3<&{to_browser_r} 4>&{from_browser_w}', *args],
                pass_fds=(to_browser_r, from_browser_w),
                stdout=err,
                stderr=err,
            )
        os.close(to_browser_r)
        os.close(from_browser_w)
        try:
            shot, box, drawn, requests = _visit(
                _Pipe(to_browser_w, from_browser_r), path, width, height
            )
        except RuntimeError as exc:
            proc.kill()
            proc.wait()
            tail = log.read_text(errors="replace")[-2000:]
            raise RuntimeError(f"{exc}; Chromium's output ends with:\n{tail}") from None
        finally:
            os.close(to_browser_w)
            os.close(from_browser_r)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
    return PageLoad(shot, box, drawn, requests)


def _visit(pipe: _Pipe, path: Path, width: int, height: int):
    """(screenshot PNG, box of the 3D view, whether it has a canvas, requests) of ``path``
    opened in a new tab of the browser at the other end of ``pipe``, which is then closed."""
    target = pipe.call("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = pipe.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    for method in ("Network.enable", "Page.enable"):
        pipe.call(method, session=session)
    pipe.call(
        "Emulation.setDeviceMetricsOverride",
        {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        session=session,
    )
    pipe.call("Page.navigate", {"url": path.resolve().as_uri()}, session=session)
    drawn = _evaluate(pipe, session, WAIT_FOR_PLOT)
    box = _evaluate(
        pipe,
        session,
        "(() => { const r = document.querySelector('#view3d').getBoundingClientRect();"
        " return [r.x, r.y, r.width, r.height]; })()",
    )
    shot = pipe.call("Page.captureScreenshot", {"format": "png"}, session=session)
    requests = [
        e["params"]["request"]["url"]
        for e in pipe.events
        if e.get("method") == "Network.requestWillBeSent"
    ]
    try:
        pipe.call("Browser.close")
    except RuntimeError:
        pass  # the browser may close the pipe before it answers
    return base64.b64decode(shot["data"]), tuple(box), bool(drawn), requests


def _above_4(fd: int) -> int:
    """``fd`` moved to a number above 4, so that bash's ``3<&A 4>&B`` cannot clobber it."""
    high = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 5)
    os.close(fd)
    return high


def _evaluate(pipe: _Pipe, session: str, expression: str):
    """The value of a JavaScript expression (a promise is awaited)."""
    reply = pipe.call(
        "Runtime.evaluate",
        {"expression": expression, "awaitPromise": True, "returnByValue": True},
        session=session,
    )
    if "exceptionDetails" in reply:
        raise RuntimeError(f"JavaScript failed: {reply['exceptionDetails']}")
    return reply["result"].get("value")


def save_screenshot(report: Path, out: Path, *, width: int = 1200, height: int = 1060) -> None:
    """Save the top of ``report`` as seen in Chromium to ``out``: a 256-colour PNG (Pillow,
    which matplotlib requires), small enough for the repository's docs."""
    from PIL import Image

    page = load_page(report, width=width, height=height)
    image = Image.open(io.BytesIO(page.screenshot)).convert("RGB")
    small = image.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
    small.save(out, optimize=True)
    print(f"{out}: 3D view at {page.plot_box}, WebGL {page.has_webgl}")
    print("requests:", *(u[:80] for u in page.requests), sep="\n  ")


if __name__ == "__main__":
    save_screenshot(Path(sys.argv[1]), Path(sys.argv[2]))
