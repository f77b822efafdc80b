"""Gymnasium environments (``pip install uvms-pin[gym]``), registered on import:

- ``uvms_pin/ForceTracking-v0`` (`ForceTrackingEnv`): track a contact force;
- ``uvms_pin/StationKeeping-v0`` (`StationKeepingEnv`): hold the vehicle's pose;
- ``uvms_pin/PoseTracking-v0`` (`PoseTrackingEnv`): follow a scenario's ``[task]``.

ForceTracking and StationKeeping have a native vector environment (`UvmsVectorEnv`: the
plants of N environments in one compiled call on T threads):

    envs = gym.make_vec("uvms_pin/StationKeeping-v0", num_envs=16,
                        vectorization_mode="vector_entry_point", num_threads=2)

    import gymnasium as gym
    import uvms_pin.apps.gym
    env = gym.make("uvms_pin/ForceTracking-v0", scenario="my_task.toml")

Observations, actions, rewards and termination: docs/gym.md.
"""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

from uvms_pin.apps.gym.env import UvmsEnv
from uvms_pin.apps.gym.force_tracking import ForceTrackingEnv
from uvms_pin.apps.gym.pose_tracking import PoseTrackingEnv
from uvms_pin.apps.gym.station_keeping import StationKeepingEnv
from uvms_pin.apps.gym.vector import UvmsVectorEnv

__all__ = ["ForceTrackingEnv", "PoseTrackingEnv", "StationKeepingEnv", "UvmsEnv", "UvmsVectorEnv"]

_VECTOR = "uvms_pin.apps.gym.vector:"
for _id, _entry, _vector in (
    ("uvms_pin/ForceTracking-v0", "uvms_pin.apps.gym.force_tracking:ForceTrackingEnv",
     _VECTOR + "force_tracking_vector"),
    ("uvms_pin/StationKeeping-v0", "uvms_pin.apps.gym.station_keeping:StationKeepingEnv",
     _VECTOR + "station_keeping_vector"),
    ("uvms_pin/PoseTracking-v0", "uvms_pin.apps.gym.pose_tracking:PoseTrackingEnv", None),
):  # fmt: skip
    if _id not in registry:
        # the episode length is the scenario's duration (truncation inside the env)
        register(id=_id, entry_point=_entry, vector_entry_point=_vector, disable_env_checker=False)
