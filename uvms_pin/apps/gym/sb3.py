"""A uvms-pin vector environment as a stable-baselines3 ``VecEnv`` (``pip install
uvms-pin[rl]``), so that SB3's algorithms (PPO, SAC, ...) train on the compiled batch.

    from uvms_pin.apps.gym.sb3 import Sb3VecEnv
    venv = Sb3VecEnv(gym.make_vec("uvms_pin/StationKeeping-v0", num_envs=8,
                                  vectorization_mode="vector_entry_point", num_threads=2))

SB3 resets an ended episode in the step that ends it: the vector environment runs with
``AutoresetMode.SAME_STEP`` (it is created so if it is not), and each ended episode's last
observation is ``infos[i]["terminal_observation"]``, a truncation flagged by
``infos[i]["TimeLimit.truncated"]``, as SB3's own vector environments do.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecEnv

from uvms_pin.apps.gym.vector import UvmsVectorEnv
from uvms_pin.errors import ParameterError


class Sb3VecEnv(VecEnv):
    """SB3's view of a `UvmsVectorEnv` (whose autoreset mode must be SAME_STEP)."""

    def __init__(self, vector_env: UvmsVectorEnv):
        env = getattr(vector_env, "unwrapped", vector_env)
        if not isinstance(env, UvmsVectorEnv):
            raise ParameterError(f"expected a UvmsVectorEnv, got {type(env).__name__}")
        if env.metadata["autoreset_mode"] != AutoresetMode.SAME_STEP:
            raise ParameterError(
                "SB3 needs autoreset_mode=AutoresetMode.SAME_STEP in gym.make_vec(...)"
            )
        self.vector_env = env
        super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        self._actions: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        seeds = [s for s in self._seeds] if any(s is not None for s in self._seeds) else None
        observations, infos = self.vector_env.reset(seed=seeds)
        self._reset_seeds()
        self.reset_infos = [{"seed": int(s)} for s in infos["seed"]]
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions, dtype=float)

    def step_wait(self):
        observations, reward, terminated, truncated, infos = self.vector_env.step(self._actions)
        dones = terminated | truncated
        names = [k for k in infos if not k.startswith("_") and k not in ("final_obs", "final_info")]
        per_env: list[dict[str, Any]] = [
            {name: infos[name][i] for name in names} for i in range(self.num_envs)
        ]
        for i in np.flatnonzero(dones):
            per_env[i]["terminal_observation"] = infos["final_obs"][i]
            per_env[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return observations, reward.astype(np.float32), dones, per_env

    def close(self) -> None:
        self.vector_env.close()

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return [getattr(self.vector_env.single_env, attr_name)] * len(self._indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        raise ParameterError("the environments of a batch share their settings: not settable")

    def env_method(self, method_name: str, *args, indices=None, **kwargs) -> list[Any]:
        raise ParameterError("the environments of a batch run in one compiled call: no methods")

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(self._indices(indices))

    def _indices(self, indices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        return [indices] if isinstance(indices, int) else list(indices)
