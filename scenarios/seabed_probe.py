"""The controller of scenarios/seabed_landing.toml: the vehicle pushes itself down with a
constant heave force (body axes) and holds its heading, the arm moves its joints to a
probing posture with a PD law (a joint-space target, reached in ``ramp_s`` seconds).

    tau_vehicle = [0, 0, -heave_force_N, 0, 0, -k_yaw r]
    tau_arm     = K_p (q_target(t) - q) - K_d qdot,  q_target ramps from q(0)

It is a scenario's own controller (``type = "seabed_probe:SeabedProbe"``), the example of
uvms_pin.scenario.custom_controller."""

from __future__ import annotations

import numpy as np
from object_push import arm_pd

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller


class SeabedProbe(Controller):
    def __init__(
        self,
        uvms,
        heave_force_N: float,
        arm_target_rad: list[float],
        kp_Nm_rad: list[float],
        kd_Nm_s_rad: list[float],
        ramp_s: float = 5.0,
        yaw_damping_Nm_s_rad: float = 2.0,
        start_s: float = 0.0,
    ):
        finite_parameters("seabed_probe", locals())  # inf or nan: refused now, by name
        self.nv = uvms.nv
        self.heave_force_N = float(heave_force_N)
        self.target, self.kp, self.kd = arm_pd(self.nv, arm_target_rad, kp_Nm_rad, kd_Nm_s_rad)
        self.ramp_s, self.start_s = float(ramp_s), float(start_s)
        self.yaw_damping = float(yaw_damping_Nm_s_rad)
        self.q0: np.ndarray | None = None

    def reset(self) -> None:
        self.q0 = None

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        if self.q0 is None:
            self.q0 = q[7:].copy()
        s = np.clip((time_s - self.start_s) / self.ramp_s, 0.0, 1.0)
        target = self.q0 + (3 * s**2 - 2 * s**3) * (self.target - self.q0)
        tau = np.zeros(self.nv)
        tau[2] = -self.heave_force_N
        tau[5] = -self.yaw_damping * v[5]
        tau[6:] = self.kp * (target - q[7:]) - self.kd * v[6:]
        return tau
