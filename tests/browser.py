"""A headless Chromium driven over the DevTools protocol on a pipe (no extra Python package).

``chromium --remote-debugging-pipe`` reads protocol messages (JSON, each ended by a NUL byte) on
file descriptor 3 and writes its answers and events on descriptor 4. :class:`Browser` starts it
with a private profile, opens one page, and offers what the report's browser test needs: a
device viewport (desktop or phone), loading a file, evaluating a script and a full-page
screenshot. :func:`inspect_page` measures a page: every image loaded, nothing wider than the
viewport.
"""
from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

#: Where to look for the browser: $TIRECLI_CHROMIUM first, then these names on PATH.
NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")


def find_chromium() -> str | None:
    """The browser's executable, or None."""
    env = os.environ.get("TIRECLI_CHROMIUM")
    if env:
        return env if Path(env).exists() else shutil.which(env)
    for name in NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


class BrowserError(RuntimeError):
    pass


class Browser:
    """One headless Chromium with one page; use as a context manager."""

    def __init__(self, executable: str, timeout: float = 60.0):
        self.timeout = timeout
        self._profile = tempfile.mkdtemp(prefix="tirecli-chromium-")
        to_chrome_r, self._to_chrome = os.pipe()
        self._from_chrome, from_chrome_w = os.pipe()
        # the child's descriptors 3 and 4 must be these pipe ends: copies above 10 (closed on exec) are
        # duplicated onto 3 and 4 in the child (dup2 makes them inheritable; nothing else is inherited)
        hi_r, hi_w = _dup_high(to_chrome_r), _dup_high(from_chrome_w)

        def child_fds():
            os.dup2(hi_r, 3)
            os.dup2(hi_w, 4)

        args = [executable, "--headless", "--remote-debugging-pipe", "--no-sandbox", "--disable-gpu",
                "--disable-dev-shm-usage", "--no-first-run", "--no-default-browser-check", "--hide-scrollbars",
                "--mute-audio", "--disable-extensions", "--allow-file-access-from-files",
                f"--user-data-dir={self._profile}", "about:blank"]
        try:
            self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                         stderr=subprocess.DEVNULL, close_fds=False,
                                         preexec_fn=child_fds)
        finally:
            for fd in {to_chrome_r, from_chrome_w, hi_r, hi_w}:
                os.close(fd)
        self._buf = b""
        self._id = 0
        self._events: list[dict] = []
        self.session = None
        target = self.send("Target.createTarget", {"url": "about:blank"}, session=False)["targetId"]
        self.session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True},
                                 session=False)["sessionId"]
        self.send("Page.enable")
        self.send("Runtime.enable")

    # -- protocol
    def _read_message(self, deadline: float) -> dict:
        import select

        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise BrowserError("no answer from the browser in time")
            ready, _, _ = select.select([self._from_chrome], [], [], left)
            if ready:
                chunk = os.read(self._from_chrome, 1 << 20)
                if not chunk:
                    raise BrowserError(f"the browser closed the pipe (exit code {self.proc.poll()})")
                self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def send(self, method: str, params: dict | None = None, session: bool = True) -> dict:
        """Send a command and return its result (events arriving meanwhile are kept)."""
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        data = json.dumps(msg).encode() + b"\0"
        while data:
            data = data[os.write(self._to_chrome, data):]
        deadline = time.monotonic() + self.timeout
        while True:
            ans = self._read_message(deadline)
            if ans.get("id") == self._id:
                if "error" in ans:
                    raise BrowserError(f"{method}: {ans['error'].get('message')}")
                return ans.get("result", {})
            if "method" in ans:
                self._events.append(ans)

    def wait_event(self, method: str) -> dict:
        deadline = time.monotonic() + self.timeout
        while True:
            for k, ev in enumerate(self._events):
                if ev["method"] == method:
                    del self._events[k]
                    return ev.get("params", {})
            self._events.append(self._read_message(deadline))

    # -- page
    def open(self, path: str | Path, width: int, height: int = 900, mobile: bool = False) -> None:
        """Load a local file in a viewport of ``width`` x ``height`` CSS pixels (a phone when ``mobile``)."""
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": mobile})
        self._events.clear()
        self.send("Page.navigate", {"url": Path(path).resolve().as_uri()})
        self.wait_event("Page.loadEventFired")

    def evaluate(self, expression: str):
        res = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True})
        if "exceptionDetails" in res:
            raise BrowserError(f"script failed: {res['exceptionDetails'].get('text')} "
                               f"{res['exceptionDetails'].get('exception', {}).get('description', '')}")
        return res["result"].get("value")

    def screenshot(self, path: str | Path, max_height: int = 16000) -> Path:
        """A PNG of the whole page (at most ``max_height`` CSS pixels tall)."""
        w, h = self.evaluate("[document.documentElement.clientWidth, document.documentElement.scrollHeight]")
        shot = self.send("Page.captureScreenshot", {
            "format": "png", "captureBeyondViewport": True,
            "clip": {"x": 0, "y": 0, "width": w, "height": min(h, max_height), "scale": 1}})
        path = Path(path)
        path.write_bytes(base64.b64decode(shot["data"]))
        return path

    def close(self) -> None:
        try:
            self.send("Browser.close", session=False)
        except (BrowserError, OSError):
            pass
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_chrome, self._from_chrome):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self._profile, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _dup_high(fd: int) -> int:
    import fcntl

    return fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10)


#: Measures the loaded page: images that failed to load, elements reaching past the viewport (outside any
#: element marked as scrolling sideways: a box that scrolls, with role=region, a label and tabindex, so that
#: a reader sees and reaches it), and whether the page itself scrolls sideways.
INSPECT = r"""
(() => {
  const doc = document.documentElement, vw = doc.clientWidth;
  const marked = p => ['auto', 'scroll'].includes(getComputedStyle(p).overflowX) && p.getAttribute('role') === 'region'
      && p.hasAttribute('aria-label') && p.getAttribute('tabindex') === '0' && p.getBoundingClientRect().right <= vw + 0.5;
  const clips = el => { for (let p = el.parentElement; p && p !== document.body; p = p.parentElement) {
      if (marked(p)) return true; } return false; };
  const images = [...document.images].map(img => ({
    alt: img.alt, loaded: img.complete && img.naturalWidth > 0, width: img.getBoundingClientRect().width,
    in_scroll_box: clips(img)}));
  const wide = [];
  for (const el of document.body.querySelectorAll('*')) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 || getComputedStyle(el).position === 'fixed') continue;
    if ((r.right > vw + 0.5 || r.left < -0.5) && !clips(el)) {
      wide.push({tag: el.tagName.toLowerCase(), id: el.id, cls: el.className, left: r.left, right: r.right,
                 text: (el.textContent || '').trim().slice(0, 60)});
    }
  }
  return {viewport: vw, scroll_width: doc.scrollWidth, body_scroll_width: document.body.scrollWidth,
          height: doc.scrollHeight, images, wide: wide.slice(0, 20), n_wide: wide.length};
})()
"""


def inspect_page(browser: Browser, path: str | Path, width: int, mobile: bool = False) -> dict:
    """Open ``path`` at ``width`` CSS pixels and measure it (see :data:`INSPECT`)."""
    browser.open(path, width, mobile=mobile)
    return browser.evaluate(INSPECT)


def problems(measure: dict) -> list[str]:
    """What is wrong with a measured page: images not loaded, sideways scrolling, elements past the edge."""
    out = [f"image not loaded: {i['alt']}" for i in measure["images"] if not i["loaded"]]
    if measure["scroll_width"] > measure["viewport"]:
        out.append(f"the page scrolls sideways: {measure['scroll_width']} px wide in a {measure['viewport']} px viewport")
    for w in measure["wide"]:
        out.append(f"<{w['tag']} id={w['id']!r} class={w['cls']!r}> spans {w['left']:.0f}-{w['right']:.0f} px "
                   f"(viewport {measure['viewport']} px): {w['text']!r}")
    return out
