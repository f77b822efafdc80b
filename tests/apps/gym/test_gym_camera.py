"""A camera's image in an environment's observation."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import uvms_pin.apps.gym  # noqa: F401 (registers the environments)
from uvms_pin.apps.gym.camera import CameraObservation
from uvms_pin.errors import ParameterError

CAMERA = {"name": "front", "width": 32, "height": 24, "noise_counts": 2.0,
          "rpy_rad": [-2.4, 0.0, -1.5708]}  # fmt: skip


def _env(**kw):
    return CameraObservation(gym.make("uvms_pin/StationKeeping-v0"), CAMERA, **kw)


def test_the_observation_carries_the_image_of_the_true_state():
    env = _env(depth=True)
    observation, _ = env.reset(seed=3)
    assert env.observation_space.contains(observation)
    assert observation["image"].shape == (24, 32, 3) and observation["image"].dtype == np.uint8
    assert observation["state"].shape == env.env.observation_space.shape
    nothing = np.isinf(observation["depth"])
    assert nothing.any()  # open water ahead and below
    observation, *_ = env.step(np.zeros(env.action_space.shape))
    assert env.observation_space.contains(observation)


def test_the_same_episode_seed_gives_the_same_images():
    def images(seed):
        env = _env()
        first, _ = env.reset(seed=seed)
        after, *_ = env.step(np.full(env.action_space.shape, 0.3))
        return first["image"], after["image"]

    a, b = images(5), images(5)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert not np.array_equal(images(6)[0], a[0])


def test_a_bad_camera_is_refused_naming_the_key():
    with pytest.raises(ParameterError, match="width"):
        CameraObservation(gym.make("uvms_pin/StationKeeping-v0"), {**CAMERA, "width": 0})
