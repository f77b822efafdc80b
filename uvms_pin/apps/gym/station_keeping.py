"""``uvms_pin/StationKeeping-v0``: hold the vehicle's initial pose against current."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvms_pin.apps.gym.env import UvmsEnv
from uvms_pin.apps.gym.tasks import StationKeepingTask
from uvms_pin.sim.run import Scenario

DEFAULT_SCENARIO = "gym_station_keeping"


class StationKeepingEnv(UvmsEnv):
    """Hold p_d, R_d = the scenario's initial vehicle pose (before the reset perturbation).

    Args (besides `UvmsEnv`'s):
        max_position_error_m: the episode ends when |p - p_d| exceeds it [m].
    """

    initial_noise = (0.1, 0.05)

    def __init__(
        self,
        scenario: str | Path = DEFAULT_SCENARIO,
        *,
        max_position_error_m: float = 1.0,
        **kwargs: Any,
    ):
        self._max_position_error_m = max_position_error_m
        super().__init__(scenario, **kwargs)

    def _make_task(self, scenario: Scenario) -> StationKeepingTask:
        return StationKeepingTask(scenario.q0, self._max_position_error_m, self.effort_weight)
