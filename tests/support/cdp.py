"""Headless Chromium driven over the DevTools protocol: real mouse clicks and key presses
(``Input.dispatch*Event``: trusted input events, as a person's), page scripts, screenshots.

A small client on the ``websockets`` package (which the serve extra brings), so the tests need no
browser automation package: Debian's ``chromium`` is enough (.ci/run installs it where it can).
"""

from __future__ import annotations

import base64
import contextlib
import json
import shutil
import subprocess
import tempfile
import time
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from websockets.sync.client import connect

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
#: WebGL without a GPU: SwiftShader, which Chromium now enables only when asked.
FLAGS = (
    "--headless=new",
    "--no-sandbox",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-extensions",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--window-size=1280,800",
    "--remote-debugging-port=0",
)

#: Keys as the DevTools protocol wants them: (key, code, virtual key code, text).
SPECIAL = {
    "Enter": ("Enter", "Enter", 13, "\r"),
    " ": (" ", "Space", 32, " "),
    "Escape": ("Escape", "Escape", 27, ""),
    "]": ("]", "BracketRight", 221, "]"),
    "[": ("[", "BracketLeft", 219, "["),
}


def chromium() -> str | None:
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    return None


class Page:
    """One tab: ``call`` a DevTools method, ``js`` an expression, ``click``, ``key``."""

    def __init__(self, ws_url: str) -> None:
        self._stack = contextlib.ExitStack()
        self.ws = self._stack.enter_context(connect(ws_url, max_size=None, open_timeout=30))
        self.next_id = 0

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                result: dict[str, Any] = msg.get("result", {})
                return result

    def js(self, expression: str) -> Any:
        out = self.call(
            "Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True
        )
        if "exceptionDetails" in out:
            raise RuntimeError(f"{expression}: {out['exceptionDetails']}")
        return out["result"].get("value")

    def wait(self, expression: str, timeout: float = 30.0) -> Any:
        deadline = time.monotonic() + timeout
        while True:
            value = self.js(expression)
            if value:
                return value
            if time.monotonic() > deadline:
                raise TimeoutError(f"waited {timeout} s for {expression}")
            time.sleep(0.05)

    def click(self, x: float, y: float, shift: bool = False) -> None:
        mods = 8 if shift else 0
        self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y, modifiers=mods)
        for kind in ("mousePressed", "mouseReleased"):
            self.call(
                "Input.dispatchMouseEvent",
                type=kind,
                x=x,
                y=y,
                button="left",
                clickCount=1,
                modifiers=mods,
            )

    def key(self, key: str) -> None:
        if key in SPECIAL:
            name, code, vk, text = SPECIAL[key]
        else:
            name, text = key, key
            code = f"Key{key.upper()}" if key.isalpha() else f"Digit{key}"
            vk = ord(key.upper())
        mods = 8 if key.isalpha() and key.isupper() else 0
        down: dict[str, Any] = {"key": name, "code": code, "windowsVirtualKeyCode": vk}
        if text:
            down["text"] = text
        self.call("Input.dispatchKeyEvent", type="keyDown", modifiers=mods, **down)
        self.call("Input.dispatchKeyEvent", type="keyUp", modifiers=mods, key=name, code=code)

    def screenshot(self) -> bytes:
        return base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])

    def close(self) -> None:
        self._stack.close()


@contextlib.contextmanager
def browser(executable: str) -> Iterator[str]:
    """A headless Chromium; yields its DevTools HTTP address (http://127.0.0.1:PORT)."""
    with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:
        proc = subprocess.Popen(
            [executable, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            port_file = Path(profile) / "DevToolsActivePort"
            deadline = time.monotonic() + 60
            while not port_file.exists() or not port_file.read_text().strip():
                if time.monotonic() > deadline or proc.poll() is not None:
                    raise RuntimeError("chromium did not start")
                time.sleep(0.05)
            yield f"http://127.0.0.1:{port_file.read_text().split()[0]}"
        finally:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def open_page(devtools: str, url: str) -> Page:
    request = urllib.request.Request(
        f"{devtools}/json/new?{urllib.parse.quote(url, safe='')}", method="PUT"
    )
    with urllib.request.urlopen(request, timeout=30) as answer:
        target = json.loads(answer.read())
    page = Page(target["webSocketDebuggerUrl"])
    page.call("Page.enable")
    page.call("Runtime.enable")
    return page
