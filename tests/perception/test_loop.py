"""Cameras in the loop: a controller reads their images from its measurement; the visual
approach brings the arm onto the marked ball."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.pipeline import Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.run import simulate
from uvms_pin.sim.system import System

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
CAMERA = {"name": "front", "width": 32, "height": 24, "rate_hz": 10.0, "in_loop": True}


class Spy(Controller):
    """Zero tau; remembers the time of the image each tick's measurement carried."""

    def __init__(self, nv: int):
        self.nv, self.seen = nv, []

    def reset(self) -> None:
        self.seen = []

    def compute(self, time_s, measurement):
        image = measurement.images.get("front")
        self.seen.append((time_s, None if image is None else image.time_s))
        if image is not None:
            assert image.rgb.shape == (24, 32, 3) and not image.rgb.flags.writeable
        return np.zeros(self.nv)


def _seabed(**overrides):
    return load_scenario(SCENARIOS / "seabed_landing.toml", overrides)


def test_a_controller_reads_the_latest_image_of_a_camera_in_the_loop():
    scenario = _seabed(**{"scenario.duration_s": 0.3, "sensors.camera": [CAMERA]})
    spy = Spy(scenario.uvms.nv)
    rollout = simulate(scenario, progress=False, controller=spy)
    taken = dict(spy.seen)
    assert taken[0.0] == 0.0 and taken[0.098] == 0.0 and taken[0.1] == pytest.approx(0.1)
    assert taken[0.3] == pytest.approx(0.3)
    # the images fired over the log are the same sensor's (their own noise stream)
    assert rollout.camera("front").rgb.shape == (4, 24, 32, 3)


def test_cameras_in_the_loop_keep_the_run_in_python():
    path = SCENARIOS / "realistic_force_tracking.toml"
    plain = load_scenario(path)
    seeing = load_scenario(path, {"sensors.camera": [CAMERA]})
    reasons = [
        why_not_compiled(RunParts(System(s.plant), s.settings, s.sensor_config), Pipeline.BOTH)
        for s in (plain, seeing)
    ]
    assert reasons[0] != "cameras in the loop" and reasons[1] == "cameras in the loop"


def test_a_camera_in_the_loop_needs_a_control_period():
    scenario = load_scenario(
        SCENARIOS / "paper_force_tracking.toml",
        {"scenario.duration_s": 0.01, "sensors.camera": [CAMERA]},
    )
    with pytest.raises(ParameterError, match="control ticks"):
        simulate(scenario, progress=False)


def test_the_visual_approach_presses_the_jaw_on_the_ball():
    scenario = load_scenario(SCENARIOS / "visual_approach.toml")
    rollout = simulate(scenario, progress=False)
    assert rollout.status.ok
    error = rollout.signals["visual_error"]
    assert np.abs(error[0]).max() > 1.0  # it starts far: 1.5 m from the ball
    assert np.all(np.abs(error[-1]) < 0.03)
    pairs = rollout.metadata["world"]["world"]["pairs"]
    forces = rollout.signals["world_contact"][-1].reshape(len(pairs), 9)[:, :3]
    touching = [p for p, f in zip(pairs, forces, strict=True) if np.linalg.norm(f) > 0.1]
    assert touching == ["alpha_jaw_link|target"]
