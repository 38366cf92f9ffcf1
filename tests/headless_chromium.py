"""Headless Chromium (Debian's ``chromium``) driven over the DevTools protocol, for the
page tests: navigate, evaluate JavaScript, click, type, press keys, take a screenshot.

The protocol is JSON over one WebSocket (``websockets``, installed with nicegui); no
driver binary, nothing downloaded at install time.
"""

from __future__ import annotations

import base64
import contextlib
import itertools
import json
import os
import shutil
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path


def chromium_path() -> str | None:
    """The Chromium binary on PATH, or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class Chromium:
    """One headless Chromium with one page (a tab).

    Args:
        profile: an empty folder for its profile.
        size_px: window width, height.
    """

    def __init__(self, profile: Path, size_px: tuple[int, int] = (1400, 1300)):
        from websockets.sync.client import connect

        self._socket_dir = tempfile.mkdtemp(prefix="chromium-")
        self.proc = subprocess.Popen(
            [chromium_path(), "--headless", "--no-sandbox", "--disable-gpu",
             "--hide-scrollbars", "--no-first-run", "--remote-debugging-port=0",
             "--remote-allow-origins=*", f"--user-data-dir={profile}",
             f"--window-size={size_px[0]},{size_px[1]}", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            # its singleton socket folders go into a short folder of their own, removed on
            # close (not into /tmp for good); a socket's path must stay under 108
            # characters, which a profile deep in pytest-xdist's tmp tree exceeds
            env={**os.environ, "TMPDIR": self._socket_dir})
        port_file = profile / "DevToolsActivePort"
        deadline = time.monotonic() + 60
        while not (port_file.exists() and port_file.read_text().strip()):
            if time.monotonic() > deadline or self.proc.poll() is not None:
                raise RuntimeError("chromium did not open its DevTools port")
            time.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list") as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        self._stack = contextlib.ExitStack()
        self.ws = self._stack.enter_context(connect(page["webSocketDebuggerUrl"],
                                                    max_size=None))
        self._ids = itertools.count(1)

    def close(self) -> None:
        self._stack.close()
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        shutil.rmtree(self._socket_dir, ignore_errors=True)

    def call(self, method: str, **params) -> dict:
        """One protocol command; its result (events on the way are dropped)."""
        i = next(self._ids)
        self.ws.send(json.dumps({"id": i, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == i:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg["result"]

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page."""
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                      awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def navigate(self, url: str) -> None:
        self.call("Page.navigate", url=url)

    def wait_for(self, expression: str, timeout_s: float = 30.0):
        """Evaluate ``expression`` until it is truthy; its value. While the page loads it
        may throw (no body yet): that counts as not yet."""
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                value = self.evaluate(expression)
            except RuntimeError as exc:
                value, why = None, exc
            else:
                why = None
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError(f"not true within {timeout_s:g} s: {expression}"
                                     + (f" ({why})" if why else ""))
            time.sleep(0.1)

    def text(self) -> str:
        """The page's visible text."""
        return self.evaluate("document.body.innerText")

    def click(self, css: str, text: str | None = None) -> None:
        """Click, with the mouse, the middle of the first element matching ``css`` whose
        text, trimmed and lower-cased, is ``text`` (any text when None)."""
        want = json.dumps(None if text is None else text.lower())
        box = self.evaluate(
            f"(() => {{ const e = [...document.querySelectorAll({json.dumps(css)})].find("
            f"e => {want} === null || e.textContent.trim().toLowerCase() === {want});"
            " if (!e) return null; e.scrollIntoView({block: 'center'});"
            " const r = e.getBoundingClientRect();"
            " return [r.left + r.width / 2, r.top + r.height / 2]; })()")
        if not box:
            raise AssertionError(f"nothing to click: {css} {text!r}")
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=box[0], y=box[1],
                      button="left", clickCount=1)

    def type_text(self, text: str) -> None:
        """Type into the focused element."""
        self.call("Input.insertText", text=text)

    def press(self, key: str) -> None:
        """Press and release one character key."""
        code = f"Key{key.upper()}"
        self.call("Input.dispatchKeyEvent", type="keyDown", key=key, code=code, text=key)
        self.call("Input.dispatchKeyEvent", type="keyUp", key=key, code=code)

    def screenshot(self, path: Path) -> None:
        path.write_bytes(base64.b64decode(self.call("Page.captureScreenshot")["data"]))
