"""``uvms_pin/ForceTracking-v0``: track a desired contact force at the end-effector."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.apps.gym.env import UvmsEnv
from uvms_pin.apps.gym.tasks import ForceTrackingTask
from uvms_pin.control.jaw_servo import WithJaw
from uvms_pin.control.performance import PerformanceFunction
from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.errors import ParameterError
from uvms_pin.sim.run import Scenario

DEFAULT_SCENARIO = "realistic_force_tracking"
# (rho0 [N], rho_inf [N], l [1/s]) when the scenario has no PPC to take the funnel from
DEFAULT_FUNNEL = (2.0, 0.5, 0.5)


class ForceTrackingEnv(UvmsEnv):
    """Force tracking on a scenario with a contact [environment] (docs/gym.md).

    Args (besides `UvmsEnv`'s):
        desired_force_N: f_d: 3 numbers [N] or a function t [s] -> (3,); default: the
            scenario's PPC desired force.
        funnel: (rho0, rho_inf, l_per_s), each a number or 3 numbers, of the force-error
            funnel that ends an episode; default: the scenario's PPC first-level funnel
            (else `DEFAULT_FUNNEL`); False: no funnel termination.
    """

    initial_noise = (0.02, 0.02)

    def __init__(
        self,
        scenario: str | Path = DEFAULT_SCENARIO,
        *,
        desired_force_N: Any = None,
        funnel: Any = None,
        **kwargs: Any,
    ):
        self._desired_force_option = desired_force_N
        self._funnel_option = funnel
        super().__init__(scenario, **kwargs)

    def _make_task(self, scenario: Scenario) -> ForceTrackingTask:
        if scenario.plant.contact is None:
            raise ParameterError(
                f"{scenario.path}: ForceTracking needs a contact [environment] in the scenario"
            )
        ppc = None
        if getattr(scenario.controller_factory, "type", None) == "ppc":
            ppc = scenario.controller_factory(scenario.uvms)
            if isinstance(ppc, WithJaw):  # the PPC beside a jaw's servo: the PPC's own
                ppc = ppc.arm
        return ForceTrackingTask(
            _desired_force(self._desired_force_option, ppc),
            _funnel(self._funnel_option, ppc),
            self.effort_weight,
        )


def _desired_force(
    option: Any, ppc: PrescribedPerformanceController | None
) -> Callable[[float], np.ndarray]:
    if callable(option):
        return option
    if option is not None:
        force = np.asarray(option, dtype=float).reshape(-1)
        if force.shape != (3,) or not np.all(np.isfinite(force)):
            raise ParameterError(f"desired_force_N must be 3 finite numbers [N], got {option}")
        return lambda time_s: force
    if ppc is None:
        raise ParameterError(
            "the scenario has no PPC [controller] to take the desired force from: "
            "pass desired_force_N=[fx, fy, fz] (or a function of t)"
        )
    return ppc.desired_force_world_N


def _funnel(option: Any, ppc: PrescribedPerformanceController | None) -> PerformanceFunction | None:
    if option is False:
        return None
    names = ("f_x", "f_y", "f_z")
    if option is None:
        if ppc is None:
            rho0, rho_inf, rate = DEFAULT_FUNNEL
        else:
            p = ppc.params
            rho0, rho_inf, rate = p.rho0_x[:3], p.rho_inf_x[:3], p.l_x_per_s[:3]
    else:
        try:
            rho0, rho_inf, rate = option
        except (TypeError, ValueError):
            raise ParameterError(
                f"funnel must be (rho0, rho_inf, l_per_s) or False, got {option!r}"
            ) from None
    broadcast = [np.broadcast_to(np.asarray(x, dtype=float), (3,)) for x in (rho0, rho_inf, rate)]
    return PerformanceFunction(*broadcast, names=names)
