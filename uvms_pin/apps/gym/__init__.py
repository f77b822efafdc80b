"""Gymnasium environments (``pip install uvms-pin[gym]``), registered on import:

- ``uvms_pin/ForceTracking-v0`` (`ForceTrackingEnv`): track a contact force;
- ``uvms_pin/StationKeeping-v0`` (`StationKeepingEnv`): hold the vehicle's pose;
- ``uvms_pin/PoseTracking-v0`` (`PoseTrackingEnv`): follow a scenario's ``[task]``.

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

__all__ = ["ForceTrackingEnv", "PoseTrackingEnv", "StationKeepingEnv", "UvmsEnv"]

for _id, _entry in (
    ("uvms_pin/ForceTracking-v0", "uvms_pin.apps.gym.force_tracking:ForceTrackingEnv"),
    ("uvms_pin/StationKeeping-v0", "uvms_pin.apps.gym.station_keeping:StationKeepingEnv"),
    ("uvms_pin/PoseTracking-v0", "uvms_pin.apps.gym.pose_tracking:PoseTrackingEnv"),
):
    if _id not in registry:
        # the episode length is the scenario's duration (truncation inside the env)
        register(id=_id, entry_point=_entry, disable_env_checker=False)
