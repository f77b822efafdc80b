"""The Gym environments tick the navigation sensors and the estimator once per step."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

import uvms_pin.apps.gym  # noqa: F401 - registers the environments

NAVIGATION = {
    "scenario.duration_s": 0.2,
    "sensors.imu": {"gyro_noise_rad_s_rthz": 1e-3},
    "sensors.depth": {"noise_Pa": 50.0},
    "estimator": {"type": "eskf", "draw_initial_error": False},
}


def test_each_step_reads_the_sensors_and_filters_them():
    env = gym.make("uvms_pin/StationKeeping-v0", overrides=NAVIGATION)
    env.reset(seed=3)
    for _ in range(10):
        env.step(np.zeros(env.action_space.shape))
    rollout = env.unwrapped.episode_rollout()
    depth = rollout.signals["depth"][:, 0]
    assert depth.size == len(rollout) == 11
    assert np.all(np.abs(depth + rollout.q[:, 2]) < 0.05)  # read at each step, with noise
    assert np.unique(depth).size == depth.size
    estimate = rollout.signals["estimate"]
    np.testing.assert_allclose(estimate[:, 2], rollout.q[:, 2], atol=0.02)  # depth-corrected
