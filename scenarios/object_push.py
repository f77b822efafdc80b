"""The controller of scenarios/push_object.toml: the vehicle holds a depth and its attitude
(PD laws, body axes of a near-level vehicle), the arm moves to a pushing posture (a joint
PD law, ramped in ``ramp_s`` seconds), then the vehicle surges forward with a ramped force
so that the arm's jaws push the box ahead of it.

    tau_surge   = F s(t)                                   s: a smooth 0 -> 1 ramp
    tau_heave   = k_z (z_target - z) - d_z w
    tau_roll/pitch/yaw = -k_a (angle) - d_a (rate)
    tau_arm     = K_p (q_target(t) - q) - K_d qdot

A scenario's own controller (``type = "object_push:ObjectPush"``)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller


def arm_pd(nv: int, arm_target_rad, kp_Nm_rad, kd_Nm_s_rad):
    """(q_target, K_p, K_d) of an arm joint PD law as arrays; ValueError unless each has one
    entry per arm joint (nv - 6): these controllers move an arm (a UVMS model)."""
    arm = nv - 6
    out = []
    for name, values in (("arm_target_rad", arm_target_rad), ("kp_Nm_rad", kp_Nm_rad),
                         ("kd_Nm_s_rad", kd_Nm_s_rad)):  # fmt: skip
        values = np.asarray(values, dtype=float)
        if values.shape != (arm,):
            raise ValueError(
                f"{name} has {values.size} entries, the model's arm has {arm} joints "
                "(this controller moves an arm: a UVMS model)"
            )
        out.append(values)
    return tuple(out)


def _smooth(x: float) -> float:
    s = min(max(x, 0.0), 1.0)
    return 3 * s**2 - 2 * s**3


class ObjectPush(Controller):
    def __init__(
        self,
        uvms,
        depth_m: float,
        surge_force_N: float,
        push_start_s: float,
        arm_target_rad: list[float],
        kp_Nm_rad: list[float],
        kd_Nm_s_rad: list[float],
        ramp_s: float = 3.0,
        depth_gains: list[float] = (200.0, 150.0),
        attitude_gains: list[float] = (40.0, 20.0),
    ):
        finite_parameters("object_push", locals())  # inf or nan: refused now, by name
        self.nv = uvms.nv
        self.depth_m, self.surge_force_N = float(depth_m), float(surge_force_N)
        self.push_start_s, self.ramp_s = float(push_start_s), float(ramp_s)
        self.target, self.kp, self.kd = arm_pd(self.nv, arm_target_rad, kp_Nm_rad, kd_Nm_s_rad)
        self.kz, self.dz = (float(g) for g in depth_gains)
        self.ka, self.da = (float(g) for g in attitude_gains)
        self.q0: np.ndarray | None = None

    def reset(self) -> None:
        self.q0 = None

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        if self.q0 is None:
            self.q0 = q[7:].copy()
        rotation = pin.Quaternion(q[3:7]).matrix()
        tau = np.zeros(self.nv)
        # depth: a world force, in body axes
        heave_world = self.kz * (self.depth_m - q[2]) - self.dz * (rotation @ v[:3])[2]
        force_world = np.array([0.0, 0.0, heave_world])
        tau[:3] = rotation.T @ force_world
        tau[0] += self.surge_force_N * _smooth((time_s - self.push_start_s) / self.ramp_s)
        tau[3:6] = -self.ka * pin.log3(rotation) - self.da * v[3:6]
        s = _smooth(time_s / self.ramp_s)
        target = self.q0 + s * (self.target - self.q0)
        tau[6:] = self.kp * (target - q[7:]) - self.kd * v[6:]
        return tau
