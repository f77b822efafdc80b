"""replay.html in a real headless Chromium: it renders the vehicle, its animation moves and
scrubs, and the page makes no network request (checked in the file and in the browser)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from PIL import Image
from viz_support import SPRING, HeadlessPage, short_scenario

from uvms_pin.apps.viz.replay import REPLAY_FILE, write_replay
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

DURATION_S = 1.0


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    """A 1 s run with a spring and a current, its replay.html and its rollout."""
    tmp = tmp_path_factory.mktemp("replay")
    rollout = simulate(load_scenario(short_scenario(tmp, DURATION_S, extra=SPRING)))
    assert rollout.metadata["status"] == "ok"
    assert np.max(np.abs(rollout.wrench_measured_world[:, :3])) > 0.05  # an arrow to draw
    return write_replay(rollout, tmp / REPLAY_FILE), rollout


@pytest.fixture(scope="module")
def page(replay):
    path, _ = replay
    browser = HeadlessPage()
    try:
        browser.open(path.as_uri(), "viewer.animator.actions.length > 0")
        yield browser
    finally:
        browser.close()


def _pixels(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=float)


def _at(page, t: float, out) -> np.ndarray:
    page.evaluate(f"animator.pause(); seek({t}); true")
    page.next_frames()
    return _pixels(page.screenshot(out))


def test_every_url_in_the_file_is_inert(replay):
    """No <script src>, <link>, <img> or CSS url(); the only URLs are an XML namespace and
    meshcat's websocket default, used by ``viewer.connect()``, which the page never calls."""
    text = replay[0].read_text()
    urls = set(re.findall(r"""(?:https?|wss?|ftp)://[^\s"'`)<>\\]*""", text))
    assert urls <= {"http://www.w3.org/1999/xhtml", "ws://${location.host}"}, urls
    assert "viewer.connect(" not in text
    assert not re.search(r"""<(script|link|img|iframe)[^>]+(src|href)\s*=""", text, re.I)
    assert not re.search(r"url\(\s*['\"]?(https?:)?//", text)
    csp = re.search(r'http-equiv="Content-Security-Policy" content="([^"]+)"', text)
    assert csp and "default-src 'none'" in csp.group(1) and "http" not in csp.group(1)


def test_the_page_renders_the_vehicle_and_its_animation_moves(replay, page, tmp_path):
    early = _at(page, 0.05, tmp_path / "early.png")
    late = _at(page, DURATION_S - 0.05, tmp_path / "late.png")
    for image in (early, late):
        assert image.std() > 10.0  # not a blank canvas
        assert len(np.unique(image.reshape(-1, 3), axis=0)) > 200
        # the hull's yellow (URDF colour 1.0 0.78 0.05) is on screen
        hull = (image[..., 0] > 170) & (image[..., 1] > 120) & (image[..., 2] < 90)
        assert hull.sum() > 500
    difference = np.abs(early - late).max(axis=2) > 30
    assert difference.sum() > 500  # the vehicle, arrows and trail moved


def test_play_pause_and_scrubbing(page):
    assert page.evaluate("animator.pause(); animator.playing") is False
    page.evaluate("document.getElementById('uvms-play').click(); true")
    assert page.evaluate("animator.playing") is True
    page.evaluate("document.getElementById('uvms-play').click(); true")
    assert page.evaluate("animator.playing") is False
    duration = page.evaluate("animator.duration")
    assert duration == pytest.approx(DURATION_S, abs=0.05)
    # the slider scrubs: moving it seeks the animation
    page.evaluate(
        "const s = document.getElementById('uvms-slider'); s.value = 0.5; "
        "s.dispatchEvent(new Event('input')); true"
    )
    assert page.evaluate("currentTime()") == pytest.approx(0.5, abs=0.05)


def test_the_page_makes_no_network_request(page):
    """Every request the browser saw is the file itself or an inline data:/blob: URL."""
    page.next_frames(10)
    schemes = {url.split(":", 1)[0] for url in page.requests}
    assert schemes <= {"file", "data", "blob", "about"}, page.requests
    assert page.websockets == []


def test_decimated_frames_and_file_size(tmp_path):
    """A long run is decimated: at most 30 frames per simulated second, 1800 in all."""
    from uvms_pin.apps.viz.replay import frame_times

    time_s = np.arange(0.0, 100.0 + 1e-9, 0.005)
    idx, fps = frame_times(time_s, 30.0, 1800)
    assert len(idx) <= 1801 and fps == pytest.approx(1799 / 100.0)
    assert idx[0] == 0 and idx[-1] == len(time_s) - 1
    idx, fps = frame_times(np.arange(0.0, 2.0 + 1e-9, 0.005), 30.0, 1800)
    assert fps == 30.0 and len(idx) == 61
