"""``uvms_pin/PoseTracking-v0``: follow the reference pose of a scenario's ``[task]``."""

from __future__ import annotations

from uvms_pin.apps.gym.env import PoseEnv
from uvms_pin.apps.gym.tasks import PoseTrackingTask
from uvms_pin.errors import ParameterError
from uvms_pin.sim.run import Scenario

DEFAULT_SCENARIO = "lbv150_ee_circle"


class PoseTrackingEnv(PoseEnv):
    """Track the reference pose of the scenario's ``[task]`` (an end-effector or vehicle
    path; docs/gym.md). The scenario's own controller is not used.

    Args (besides `UvmsEnv`'s):
        max_position_error_m: the episode ends when |p_r(t) - p| exceeds it [m] (default
            ``default_max_position_error_m``).
    """

    initial_noise = (0.01, 0.01)
    default_scenario = DEFAULT_SCENARIO
    default_max_position_error_m = 0.5

    def _make_task(self, scenario: Scenario) -> PoseTrackingTask:
        if scenario.task is None:
            raise ParameterError(f"{scenario.path}: PoseTracking needs a [task] in the scenario")
        return PoseTrackingTask(
            scenario.task, scenario.uvms.model, self._max_position_error_m, self.effort_weight
        )
