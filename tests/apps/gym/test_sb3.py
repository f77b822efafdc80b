"""The stable-baselines3 adapter of the vector environment (the ``rl`` extra): SB3's own
checks of a VecEnv's outputs, terminal observations, and a few PPO updates that run."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import uvms_pin.apps.gym  # noqa: F401 - registers the environments
from uvms_pin.errors import ParameterError

pytest.importorskip("stable_baselines3")
pytest.importorskip("torch")

STATION = "uvms_pin/StationKeeping-v0"
SHORT = {"scenario.duration_s": 0.05}  # episodes of 5 steps


def _vector(mode=AutoresetMode.SAME_STEP):
    return gym.make_vec(
        STATION, num_envs=2, vectorization_mode="vector_entry_point", num_threads=2,
        autoreset_mode=mode, overrides=SHORT,
    )  # fmt: skip


def test_terminal_observations_are_the_ended_episodes_last():
    from uvms_pin.apps.gym.sb3 import Sb3VecEnv

    venv = Sb3VecEnv(_vector())
    reference = _vector(AutoresetMode.NEXT_STEP)
    venv.seed(3)
    observations = venv.reset()
    first, _ = reference.reset(seed=3)
    np.testing.assert_array_equal(observations, first)
    actions = np.zeros((2, 10))
    for _ in range(5):
        venv.step_async(actions)
        observations, rewards, dones, infos = venv.step_wait()
        ended = reference.step(actions)
    assert dones.all() and all(info["TimeLimit.truncated"] for info in infos)
    for i in range(2):
        np.testing.assert_array_equal(infos[i]["terminal_observation"], ended[0][i])
    np.testing.assert_allclose(rewards, ended[1], rtol=1e-6)  # SB3's float32 rewards
    restarted = reference.step(actions)[0]  # NEXT_STEP: the new episode one step later
    np.testing.assert_array_equal(observations, restarted)


def test_ppo_learns_a_few_updates_on_it():
    from stable_baselines3 import PPO

    from uvms_pin.apps.gym.sb3 import Sb3VecEnv

    model = PPO("MlpPolicy", Sb3VecEnv(_vector()), n_steps=16, batch_size=16, n_epochs=1,
                seed=0, device="cpu")  # fmt: skip
    model.learn(total_timesteps=64)
    assert model.num_timesteps >= 64


def test_the_adapter_needs_same_step_autoreset():
    from uvms_pin.apps.gym.sb3 import Sb3VecEnv

    with pytest.raises(ParameterError, match="SAME_STEP"):
        Sb3VecEnv(_vector(AutoresetMode.NEXT_STEP))
