"""The replay draws a tracking task's reference path, in the world frame."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from conftest import ROOT

from uvms_pin.apps.viz.replay import reference_path_world, replay_html
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate


def _rollout(frame: str) -> Rollout:
    r = Rollout.allocate(2, 11, 10, {"task": {"frame": frame}})
    quat = pin.Quaternion(pin.utils.rpyToMatrix(0.0, 0.0, np.pi / 2)).coeffs()  # x y z w
    r.q[:] = np.r_[[1.0, 2.0, 3.0], quat, np.zeros(4)]
    r.signals["task_reference_position"] = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    return r


def test_reference_in_the_vehicle_frame_moves_with_the_vehicle():
    np.testing.assert_allclose(
        reference_path_world(_rollout("vehicle")), [[1.0, 3.0, 3.0], [1.0, 2.0, 4.0]], atol=1e-12
    )
    np.testing.assert_allclose(reference_path_world(_rollout("world")), [[1, 0, 0], [0, 0, 1]])
    assert reference_path_world(Rollout.allocate(2, 11, 10)) is None


def test_the_replay_of_a_tracking_run_names_its_reference():
    scenario = load_scenario(
        ROOT / "scenarios" / "lbv150_ee_circle.toml", {"scenario.duration_s": 0.5}
    )
    page = replay_html(simulate(scenario, progress=False), max_frames=5)
    assert "the task&#x27;s reference path (magenta)" in page or "reference path (magenta)" in page
