"""A uvms-pin `Controller` as a policy of the environments: observation -> action.

The controller gets the `Measurement` rebuilt from the observation (its q, v and wrench
slices) at the time ``info['time_s']``, and its tau is returned as a normalized action,
tau[action_index] / action_scale: the entries the action drives (a servoed jaw's are the
environment's own), not clipped (create the environment with ``clip_actions=False`` to pass
a command beyond the box to the actuation unchanged, as ``uvms-pin run`` does).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.apps.gym.env import UvmsEnv
from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement


def measurement_from_observation(
    observation: np.ndarray, time_s: float, layout: dict[str, slice]
) -> Measurement:
    """The controller's view: the q, v and wrench slices of an observation at ``time_s``."""
    return Measurement(
        time_s,
        observation[layout["q"]].copy(),
        observation[layout["v"]].copy(),
        observation[layout["wrench"]].copy(),
    )


class ControllerPolicy:
    """``policy(observation, info) -> action`` from a controller (e.g. the PPC)."""

    def __init__(self, controller: Controller, env: UvmsEnv):
        self.controller = controller
        self.layout = env.observation_layout
        self.action_scale = env.action_scale
        self.action_index = env.action_index

    def __call__(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        measurement = measurement_from_observation(observation, info["time_s"], self.layout)
        tau = np.asarray(self.controller.compute(info["time_s"], measurement), dtype=float)
        return tau[self.action_index] / self.action_scale
