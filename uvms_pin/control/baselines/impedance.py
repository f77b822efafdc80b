"""Task-space impedance control with a force feedforward (model-free baseline).

The end-effector is made to behave like a spring-damper about an anchor p_a (its position
at the first call after a reset) that pushes with the desired force:

    w_f = f_d(t) + K_p (p_a - p) - D_p p_dot                  [N, world axes]
    w_o = K_o log(R_d R^T) - D_o omega                         [N m, world axes]
    tau = J^lwa^T [w_f; w_o] - D_zeta zeta - K_q (q_arm - q_arm,0)

J^lwa^T maps the wrench the end-effector exerts on the environment to generalized forces
(at rest the contact force then equals w_f minus what the plant's own loads take: buoyancy
imbalance, restoring moments, disturbances). There is no force feedback: the force error
is whatever the compliance leaves, K_p times the displacement plus the uncompensated
loads; the measured force is not used. The posture term holds the arm near its first
pose (q_arm,0). Model-free: kinematics and the measurement only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.baselines.task import EndEffectorTask, gain_vector
from uvms_pin.control.measurement import Measurement

__all__ = ["ImpedanceController"]


class ImpedanceController(Controller):
    """Cartesian impedance of the end-effector plus joint damping and posture.

    Args:
        model, ee_frame_name, desired_force_world_N, desired_rpy: as `EndEffectorTask`.
        stiffness_N_m: K_p (3,) >= 0 [N/m]. damping_N_s_m: D_p (3,) >= 0 [N s/m].
        stiffness_Nm_rad: K_o (3,) >= 0 [N m/rad]. damping_Nm_s_rad: D_o (3,) >= 0.
        velocity_damping: D_zeta (nv,) >= 0 [N s/m (3); N m s/rad (3 + n_joints)].
        posture_stiffness_Nm_rad: K_q (n_joints,) >= 0 [N m/rad].
    """

    def __init__(
        self,
        model: pin.Model,
        ee_frame_name: str,
        *,
        stiffness_N_m: ArrayLike = 5.0,
        damping_N_s_m: ArrayLike = 10.0,
        stiffness_Nm_rad: ArrayLike = 2.0,
        damping_Nm_s_rad: ArrayLike = 0.5,
        velocity_damping: ArrayLike = 5.0,
        posture_stiffness_Nm_rad: ArrayLike = 0.5,
        desired_force_world_N: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0),
        desired_rpy: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0),
    ):
        self.task = EndEffectorTask(model, ee_frame_name, desired_force_world_N, desired_rpy)
        nv = self.task.nv
        self.k_p = gain_vector("stiffness_N_m", stiffness_N_m, 3)
        self.d_p = gain_vector("damping_N_s_m", damping_N_s_m, 3)
        self.k_o = gain_vector("stiffness_Nm_rad", stiffness_Nm_rad, 3)
        self.d_o = gain_vector("damping_Nm_s_rad", damping_Nm_s_rad, 3)
        self.d_zeta = gain_vector("velocity_damping", velocity_damping, nv)
        self.k_q = gain_vector("posture_stiffness_Nm_rad", posture_stiffness_Nm_rad, nv - 6)
        self.reset()

    def reset(self) -> None:
        #: p_a (3,) [m] and the q (nq,) whose arm part is held, taken at the first call
        self.anchor_world_m: np.ndarray | None = None
        self.posture_q: np.ndarray | None = None
        self._signals: dict[str, np.ndarray] = {}

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        state = self.task.evaluate(time_s, measurement)
        position = self.task.data.oMf[self.task.ee_frame_id].translation.copy()
        if self.anchor_world_m is None:
            self.anchor_world_m = position
            self.posture_q = np.array(state.q)  # the whole q: held by its arm part
        twist = state.jacobian_lwa @ state.v  # [p_dot; omega] world axes
        rotation_desired = pin.rpy.rpyToMatrix(*state.rpy_desired)
        rotation_error = pin.log3(rotation_desired @ state.rotation.T)  # world axes [rad]
        wrench = np.r_[
            state.force_desired_world_N
            + self.k_p * (self.anchor_world_m - position)
            - self.d_p * twist[:3],
            self.k_o * rotation_error - self.d_o * twist[3:],
        ]
        tau = state.jacobian_lwa.T @ wrench - self.d_zeta * state.v
        # the arm's posture error on the joints' own manifold (a continuous joint's q is
        # (cos, sin)): pin.difference gives one angle or length per joint
        posture_error = pin.difference(self.task.model, self.posture_q, state.q)[6:]
        tau[6:] -= self.k_q * posture_error
        self._signals = {
            "force_desired_world_N": state.force_desired_world_N,
            "e_x": state.error,
            "wrench_command_world": wrench,
        }
        return tau

    def signals(self) -> dict[str, np.ndarray]:
        return self._signals
