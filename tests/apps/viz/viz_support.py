"""Helpers of the visualisation tests: short scenario files and a headless Chromium driven
through the DevTools protocol (tornado's websocket client; no extra dependency)."""

from __future__ import annotations

import asyncio
import base64
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SCENARIOS = ROOT / "scenarios"
MODEL = ROOT / "models" / "uvms_lbv150.urdf"

# a spring at the tip and a current: every drawn element (arrow, spring, trail) moves
SPRING = '\n[environment]\ntype = "spring"\nstiffness_N_m = [20.0, 20.0, 20.0]\n'


def short_scenario(tmp: Path, duration_s: float, *, extra: str = "", name="short") -> Path:
    """scenarios/passive_current.toml shortened to ``duration_s`` (plus TOML ``extra``)."""
    text = (SCENARIOS / "passive_current.toml").read_text()
    text = text.replace("duration_s = 20.0", f"duration_s = {duration_s}")
    # the copy lives elsewhere: the scenario names its model as a shipped one
    assert f"duration_s = {duration_s}" in text and 'model = "uvms_lbv150"' in text
    path = tmp / f"{name}.toml"
    path.write_text(text + extra)
    return path


def chromium_or_skip() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    pytest.skip(
        "no chromium: `make test` installs Debian's chromium when run as root with apt-get; "
        "otherwise install it (apt-get install chromium) to run the browser tests"
    )


class HeadlessPage:
    """A headless Chromium with one page, driven over the DevTools protocol.

    Records every network request the page makes (``requests``) and WebSocket it opens.
    """

    def __init__(self, width: int = 900, height: int = 640):
        self.binary = chromium_or_skip()
        self.width, self.height = width, height
        self.requests: list[str] = []
        self.websockets: list[str] = []
        # a headless Chromium on a loaded machine now and then exits while starting (seen
        # once in ~900 CI tests): start it again, with a fresh profile, up to three times
        for _ in range(3):
            port_file = self._launch()
            if port_file is not None:
                break
            self.close()
        else:
            pytest.fail("chromium did not start its DevTools endpoint (3 attempts)")
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            targets = json.load(r)
        self.ws_url = next(t for t in targets if t["type"] == "page")["webSocketDebuggerUrl"]
        self.loop = asyncio.new_event_loop()
        self.loop.run_until_complete(self._connect())

    def _launch(self) -> Path | None:
        """Start Chromium with a new profile; its DevTools port file, or None if it exited or
        did not write it within 30 s."""
        self.profile = tempfile.TemporaryDirectory(
            prefix="uvms-chromium-", ignore_cleanup_errors=True
        )
        self.proc = subprocess.Popen(
            [
                self.binary,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--enable-unsafe-swiftshader",
                f"--user-data-dir={self.profile.name}",
                f"--window-size={self.width},{self.height}",
                "--remote-debugging-address=127.0.0.1",
                "--remote-debugging-port=0",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        port_file = Path(self.profile.name) / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not port_file.is_file() or len(port_file.read_text().split()) < 2:
            if time.monotonic() > deadline or self.proc.poll() is not None:
                return None
            time.sleep(0.05)
        return port_file

    async def _connect(self) -> None:
        from tornado.websocket import websocket_connect

        self.conn = await websocket_connect(self.ws_url, max_message_size=512 * 2**20)
        self.next_id = 0
        await self._call("Network.enable")
        await self._call("Page.enable")
        await self._call(
            "Emulation.setDeviceMetricsOverride",
            {"width": self.width, "height": self.height, "deviceScaleFactor": 1, "mobile": False},
        )

    async def _call(self, method: str, params: dict | None = None, timeout: float = 30.0):
        self.next_id += 1
        my_id = self.next_id
        await self.conn.write_message(
            json.dumps({"id": my_id, "method": method, "params": params or {}})
        )
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"no answer to {method}")
            raw = await asyncio.wait_for(self.conn.read_message(), left)
            if raw is None:
                raise ConnectionError("DevTools connection closed")
            msg = json.loads(raw)
            self._record(msg)
            if msg.get("id") == my_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})

    def _record(self, msg: dict) -> None:
        method = msg.get("method")
        if method == "Network.requestWillBeSent":
            self.requests.append(msg["params"]["request"]["url"])
        elif method == "Network.webSocketCreated":
            self.websockets.append(msg["params"]["url"])

    def call(self, method: str, params: dict | None = None):
        return self.loop.run_until_complete(self._call(method, params))

    def evaluate(self, expression: str):
        result = self.call(
            "Runtime.evaluate",
            {"expression": expression, "awaitPromise": True, "returnByValue": True},
        )
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def open(self, url: str, ready: str, timeout_s: float = 30.0) -> None:
        """Navigate and wait until the JS expression ``ready`` is true."""
        self.call("Page.navigate", {"url": url})
        self.wait_until(ready, timeout_s, url)

    def wait_until(self, ready: str, timeout_s: float = 30.0, where: str = "the page") -> None:
        """Wait until the JS expression ``ready`` is true (the timeout only ends a test
        that would otherwise hang: nothing waits for a time to pass)."""
        deadline = time.monotonic() + timeout_s
        while not self.evaluate(
            f"(() => {{ try {{ return !!({ready}); }} catch (e) {{ return false; }} }})()"
        ):
            if time.monotonic() > deadline:
                raise TimeoutError(f"{where}: {ready} never became true")
            time.sleep(0.1)

    def next_frames(self, n: int = 3) -> None:
        """Let the page render ``n`` animation frames."""
        self.evaluate(
            f"new Promise(done => {{ let k = {n + 1}; (function f() {{ if (--k <= 0) done(true); "
            "else requestAnimationFrame(f); })(); })"
        )

    def screenshot(self, path: Path) -> Path:
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        path.write_bytes(base64.b64decode(data))
        return path

    def close(self) -> None:
        if getattr(self, "conn", None) is not None:
            self.conn.close()
            self.conn = None
        if getattr(self, "loop", None) is not None:
            self.loop.close()
            self.loop = None
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.profile.cleanup()
