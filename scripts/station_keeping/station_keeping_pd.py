"""A vehicle station-keeping PD on the measured pose: a worked example of your own controller.

The scenario next to this file (``station_keeping.toml``) names it as

    [controller]
    type = "station_keeping_pd:StationKeepingPD"
    kp_position_N_m = 200.0
    ...

and uvms-pin imports this module from the scenario's directory and builds the controller
as ``StationKeepingPD(uvms, **params)`` (the other keys of [controller]). A controller
subclasses `uvms_pin.control.base.Controller` and sees only a `Measurement`.

The law, with p and R the measured vehicle position (world) and attitude, nu = (v, w) the
measured body velocity and (p_d, R_d) the pose held:

    f_body   = R^T K_p (p_d - p) - K_d v            [N]
    tau_body = K_R log(R^T R_d)  - K_w w            [N m]

and joint damping -K_q qdot for any arm joints. Without an integral term it holds station
with a steady offset |f_ext| / K_p against a constant push (net buoyancy, a current).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS


class StationKeepingPD(Controller):
    """Hold the vehicle at a pose (default: the first measured pose) with a PD law.

    Args:
        uvms: the loaded model (only its size is used: the law is model-free).
        kp_position_N_m, kd_position_N_s_m: translational gains [N/m, N s/m].
        kp_orientation_Nm_rad, kd_orientation_Nm_s_rad: rotational gains [N m/rad, N m s/rad].
        kd_joints_Nm_s_rad: damping on arm joint rates [N m s/rad] (0 for a vehicle alone).
        target_position_world_m: p_d (3,) [m]; None holds the first measured position.
        target_rpy_rad: R_d as roll, pitch, yaw [rad]; None holds the first measured attitude.
    """

    def __init__(
        self,
        uvms: UVMS,
        kp_position_N_m: float,
        kd_position_N_s_m: float,
        kp_orientation_Nm_rad: float,
        kd_orientation_Nm_s_rad: float,
        kd_joints_Nm_s_rad: float = 0.0,
        target_position_world_m: list[float] | None = None,
        target_rpy_rad: list[float] | None = None,
    ):
        gains = {
            "kp_position_N_m": kp_position_N_m,
            "kd_position_N_s_m": kd_position_N_s_m,
            "kp_orientation_Nm_rad": kp_orientation_Nm_rad,
            "kd_orientation_Nm_s_rad": kd_orientation_Nm_s_rad,
            "kd_joints_Nm_s_rad": kd_joints_Nm_s_rad,
        }
        for name, value in gains.items():
            if not (np.isfinite(value) and value >= 0.0):
                raise ParameterError(
                    f"StationKeepingPD: {name} must be finite and >= 0, got {value}"
                )
        self.gains = gains
        self.nv = uvms.nv
        self._fixed_position = _optional_vector(target_position_world_m, "target_position_world_m")
        rpy = _optional_vector(target_rpy_rad, "target_rpy_rad")
        self._fixed_rotation = None if rpy is None else pin.rpy.rpyToMatrix(*rpy)
        self.reset()

    def reset(self) -> None:
        self.position_target = self._fixed_position
        self.rotation_target = self._fixed_rotation
        self._error = np.zeros(6)

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        q, v = measurement.q, measurement.v
        position = q[:3]
        rotation = pin.Quaternion(q[3:7]).normalized().toRotationMatrix()
        if self.position_target is None:
            self.position_target = position.copy()
        if self.rotation_target is None:
            self.rotation_target = rotation.copy()
        g = self.gains
        position_error_body = rotation.T @ (self.position_target - position)
        attitude_error_body = pin.log3(rotation.T @ self.rotation_target)
        tau = np.zeros(self.nv)
        tau[:3] = g["kp_position_N_m"] * position_error_body - g["kd_position_N_s_m"] * v[:3]
        tau[3:6] = (
            g["kp_orientation_Nm_rad"] * attitude_error_body - g["kd_orientation_Nm_s_rad"] * v[3:6]
        )
        tau[6:] = -g["kd_joints_Nm_s_rad"] * v[6:]
        self._error = np.concatenate([position_error_body, attitude_error_body])
        return tau

    def signals(self) -> dict[str, np.ndarray]:
        return {"station_error_body": self._error.copy()}


def _optional_vector(value, name: str) -> np.ndarray | None:
    if value is None:
        return None
    out = np.asarray(value, dtype=float).reshape(-1)
    if out.shape != (3,) or not np.all(np.isfinite(out)):
        raise ParameterError(f"StationKeepingPD: {name} needs 3 finite numbers, got {value!r}")
    return out
