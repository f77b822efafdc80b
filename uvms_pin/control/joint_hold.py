"""Joints held at set angles and a constant push on the vehicle: how a fin-steered vehicle
is driven (gz-sim drives its fins by a ``JointPositionController`` on each fin joint and
pushes with its propeller).

    tau_vehicle = w_body (6,)                                  [N, N m], body frame
    tau_j = k_p (q_ref,j - q_j) - k_d qdot_j   for each held joint j     [N m]

and zero on the arm's other joints. With fins on the held joints (`uvms_pin.physics.fins`)
and the push allocated to the thrusters, the vehicle turns as its fins are set.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector, nonnegative, positive
from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError

__all__ = ["JointHoldController"]


class JointHoldController(Controller):
    """The module's law.

    Args:
        model: the UVMS's Pinocchio model (free-flyer root).
        positions_rad: joint name -> the angle q_ref it is held at [rad] (a revolute joint).
        stiffness_Nm_rad: k_p > 0. damping_Nms_rad: k_d >= 0.
        vehicle_wrench_body: w_body (6,), the constant push on the vehicle [N, N m].
    """

    def __init__(
        self,
        model: pin.Model,
        positions_rad: Mapping[str, float],
        stiffness_Nm_rad: float,
        damping_Nms_rad: float = 0.0,
        vehicle_wrench_body=(0.0,) * 6,
    ):
        if not positions_rad:
            raise ParameterError("joint_hold: positions_rad names no joint to hold")
        self._kp = positive("stiffness_Nm_rad", stiffness_Nm_rad)
        self._kd = nonnegative("damping_Nms_rad", damping_Nms_rad)
        self._wrench = finite_vector("vehicle_wrench_body", vehicle_wrench_body, 6)
        arm = list(model.names[2:])
        q_index, v_index, targets = [], [], []
        for name, angle in positions_rad.items():
            if name not in arm:
                raise ParameterError(
                    f"joint_hold: '{name}' is not an arm joint (the arm's: {', '.join(arm)})"
                )
            joint = model.joints[model.getJointId(name)]
            if joint.nq != 1 or joint.nv != 1:
                raise ParameterError(f"joint_hold: joint '{name}' is not a one-angle joint")
            q_index.append(joint.idx_q)
            v_index.append(joint.idx_v)
            targets.append(angle)
        self._q_index, self._v_index = np.array(q_index), np.array(v_index)
        self._targets = finite_vector("positions_rad", targets, len(targets))
        self._nv = model.nv

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        tau = np.zeros(self._nv)
        tau[:6] = self._wrench
        q, v = measurement.q[self._q_index], measurement.v[self._v_index]
        tau[self._v_index] = self._kp * (self._targets - q) - self._kd * v
        return tau
