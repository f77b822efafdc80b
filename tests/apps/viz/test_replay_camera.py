"""The replay shows a run's first camera at the replay's time."""

from __future__ import annotations

from conftest import ROOT

from uvms_pin.apps.viz.replay import replay_html
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

CAMERA = {"name": "front", "width": 48, "height": 32, "rate_hz": 10.0,
          "rpy_rad": [-2.4, 0.0, -1.5708]}  # fmt: skip


def _rollout(sensors):
    overrides = {"scenario.duration_s": 0.3, **sensors}
    return simulate(load_scenario(ROOT / "scenarios" / "seabed_landing.toml", overrides),
                    progress=False)  # fmt: skip


def test_the_replay_holds_every_image_of_the_first_camera():
    page = replay_html(_rollout({"sensors.camera": [CAMERA]}), max_frames=5)
    assert '<img id="uvms-camera" alt="camera front">' in page
    assert page.count("data:image/jpeg;base64,") == 4  # t = 0, 0.1, 0.2, 0.3 s
    assert '"times": [0.0, 0.1' in page


def test_a_replay_without_a_camera_has_no_image():
    page = replay_html(_rollout({}), max_frames=5)
    assert 'uvms-camera"' not in page.split("<script>")[0]
    assert "const UVMS_CAMERA = null;" in page
