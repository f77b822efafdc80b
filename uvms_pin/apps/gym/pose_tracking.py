"""``uvms_pin/PoseTracking-v0``: follow the reference pose of a scenario's ``[task]``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvms_pin.apps.gym.env import UvmsEnv
from uvms_pin.apps.gym.tasks import PoseTrackingTask
from uvms_pin.errors import ParameterError
from uvms_pin.sim.run import Scenario

DEFAULT_SCENARIO = "lbv150_ee_circle"


class PoseTrackingEnv(UvmsEnv):
    """Track the reference pose of the scenario's ``[task]`` (an end-effector or vehicle
    path; docs/gym.md). The scenario's own controller is not used.

    Args (besides `UvmsEnv`'s):
        max_position_error_m: the episode ends when |p_r(t) - p| exceeds it [m].
    """

    initial_noise = (0.01, 0.01)

    def __init__(
        self,
        scenario: str | Path = DEFAULT_SCENARIO,
        *,
        max_position_error_m: float = 0.5,
        **kwargs: Any,
    ):
        self._max_position_error_m = max_position_error_m
        super().__init__(scenario, **kwargs)

    def _make_task(self, scenario: Scenario) -> PoseTrackingTask:
        if scenario.task is None:
            raise ParameterError(f"{scenario.path}: PoseTracking needs a [task] in the scenario")
        return PoseTrackingTask(
            scenario.task, scenario.uvms.model, self._max_position_error_m, self.effort_weight
        )
