"""``uvms_pin/StationKeeping-v0``: hold the vehicle's initial pose against current."""

from __future__ import annotations

from uvms_pin.apps.gym.env import PoseEnv
from uvms_pin.apps.gym.tasks import StationKeepingTask
from uvms_pin.sim.run import Scenario

DEFAULT_SCENARIO = "gym_station_keeping"


class StationKeepingEnv(PoseEnv):
    """Hold p_d, R_d = the scenario's initial vehicle pose (before the reset perturbation).

    Args (besides `UvmsEnv`'s):
        max_position_error_m: the episode ends when |p - p_d| exceeds it [m] (default
            ``default_max_position_error_m``).
    """

    initial_noise = (0.1, 0.05)
    default_scenario = DEFAULT_SCENARIO
    default_max_position_error_m = 1.0

    def _make_task(self, scenario: Scenario) -> StationKeepingTask:
        return StationKeepingTask(scenario.q0, self._max_position_error_m, self.effort_weight)
