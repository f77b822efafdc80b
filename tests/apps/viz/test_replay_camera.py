"""The replay shows a run's first camera and first imaging sonar at the replay's time."""

from __future__ import annotations

import numpy as np
from conftest import ROOT

from uvms_pin.apps.viz.camera_panel import image_panels, sonar_rgb
from uvms_pin.apps.viz.replay import replay_html
from uvms_pin.results.figures.perception import decibels
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

CAMERA = {"name": "front", "width": 48, "height": 32, "rate_hz": 10.0,
          "rpy_rad": [-2.4, 0.0, -1.5708]}  # fmt: skip


def _rollout(sensors):
    overrides = {"scenario.duration_s": 0.3, **sensors}
    return simulate(load_scenario(ROOT / "scenarios" / "seabed_landing.toml", overrides),
                    progress=False)  # fmt: skip


SONARS = [
    {"name": "alt", "type": "altimeter", "beams": 1, "bins": 16, "rate_hz": 10.0,
     "horizontal_fov_rad": 0.1, "max_range_m": 5.0},
    {"name": "profiler", "type": "multibeam", "beams": 8, "bins": 16, "rate_hz": 10.0,
     "max_range_m": 5.0},
    {"name": "fls", "beams": 24, "bins": 32, "rate_hz": 5.0, "max_range_m": 6.0,
     "rpy_rad": [0.0, 0.4, 0.0]},
]  # fmt: skip


def test_the_replay_holds_every_image_of_the_first_camera():
    page = replay_html(_rollout({"sensors.camera": [CAMERA]}), max_frames=5)
    assert '<img id="uvms-camera" alt="camera front">' in page
    assert '<img id="uvms-sonar"' not in page
    assert page.count("data:image/jpeg;base64,") == 4  # t = 0, 0.1, 0.2, 0.3 s
    assert '"times": [0.0, 0.1' in page


def test_the_replay_shows_the_first_imaging_sonar_in_db():
    """Not the altimeter's single beam nor the multibeam's profile: the imaging sonar's
    frames (5 Hz: t = 0, 0.2 s), coloured by dB with range up and port on the left."""
    rollout = _rollout({"sensors.camera": [CAMERA], "sensors.sonar": SONARS})
    page = replay_html(rollout, max_frames=5)
    assert '<img id="uvms-camera" alt="camera front"><img id="uvms-sonar" alt="sonar fls">' in page
    panels = image_panels(rollout, 0.0)
    assert [p["id"] for p in panels] == ["uvms-camera", "uvms-sonar"]
    assert panels[1]["times"] == [0.0, 0.2] and len(panels[1]["images"]) == 2
    fls = rollout.sonar("fls")
    _, low, high = decibels(fls.intensity)
    rgb = sonar_rgb(fls.intensity[1], low, high)
    assert rgb.shape == (32, 24, 3)
    brightest = np.unravel_index(np.argmax(fls.intensity[1]), fls.intensity[1].shape)
    shown = (31 - brightest[0], 23 - brightest[1])  # nearest bin at the bottom, port left
    assert rgb[shown].sum() == rgb.sum(axis=2).max() > 0
    assert np.all(sonar_rgb(np.zeros((2, 2)), low, high) == 0)  # no echo: black


def test_a_replay_without_a_camera_has_no_image():
    page = replay_html(_rollout({}), max_frames=5)
    assert 'uvms-panels"' not in page.split("<script>")[0]
    assert "const UVMS_PANELS = [];" in page


def test_a_browser_shows_each_panels_image_of_the_replays_time(tmp_path):
    """In headless Chromium: both panels hold a decoded image, and seeking past the sonar's
    second firing (0.2 s) shows that firing's image (the camera's too: 0.1 s apart)."""
    from viz_support import HeadlessPage

    from uvms_pin.apps.viz.replay import write_replay

    rollout = _rollout({"sensors.camera": [CAMERA], "sensors.sonar": SONARS})
    path = write_replay(rollout, tmp_path / "replay.html")
    panels = image_panels(rollout, float(rollout.time_s[0]))
    page = HeadlessPage()
    try:
        page.open(path.as_uri(), "viewer.animator.actions.length > 0")
        for t, shown in ((0.05, 0), (0.25, 1)):
            page.evaluate(f"animator.pause(); seek({t}); true")
            page.next_frames()
            for panel in panels:
                got = page.evaluate(f"document.getElementById('{panel['id']}').src")
                k = max(i for i, start in enumerate(panel["times"]) if start <= t + 1e-9)
                assert got == panel["images"][k]
                loaded = f"document.getElementById('{panel['id']}').naturalWidth > 0"
                page.wait_until(loaded, 10.0)
            assert page.evaluate("panelShown[1]") == shown
    finally:
        page.close()
