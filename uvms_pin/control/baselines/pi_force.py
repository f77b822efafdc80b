"""Explicit force control: PI on the force error, velocity damping (model-free baseline).

The same two levels as the PPC (`uvms_pin.control.ppc`), with linear laws instead of
funnels, so that a comparison isolates what the prescribed-performance transformation buys:

    xdot_r = -[kp_f e_f + ki_f int e_f dt (3) m/s;  k_o e_o (3) rad/s]   (first level)
    zeta_r = J^# xdot_r + (I - J^# J) zeta_0                             (the PPC's J^#)
    tau    = -K_d (zeta - zeta_r)                                         (damping)

with e = [f_meas - f_d; rpy_ee - rpy_d] the PPC's task error and K_d = diag(k_d) [N per
m/s, N m per rad/s] a damping about the reference velocity. Model-free: it reads only the
`Measurement` and the model's kinematics. No funnel, so nothing stops the run: a loss of
tracking shows in the metrics.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.baselines.task import ForceTaskOptions, gain_vector
from uvms_pin.control.measurement import Measurement

__all__ = ["PIForceController"]


class PIForceController(Controller):
    """Explicit PI force / P orientation control through J^# and velocity damping.

    Args:
        model: the UVMS kinematic model (free-flyer root).
        ee_frame_name: the end-effector frame.
        damping: k_d (nv,) > 0 [N per m/s (3); N m per rad/s (3 + n_joints)].
        **force_task: the task and its outer loop, keywords of `ForceTaskOptions`
            (kp_force_m_s_per_N, ki_force_m_s2_per_N, k_orientation_per_s,
            integral_limit_Ns, desired_force_world_N, desired_rpy, velocity_weights,
            null_space_gain_per_s, null_space_target; defaults there).
    """

    def __init__(
        self, model: pin.Model, ee_frame_name: str, *, damping: ArrayLike = 20.0, **force_task: Any
    ):
        options = ForceTaskOptions(**force_task)
        self.task = options.task(model, ee_frame_name)
        self.loop = options.loop()
        self.damping = gain_vector("damping", damping, self.task.nv, positive=True)
        self._signals: dict[str, np.ndarray] = {}

    def reset(self) -> None:
        self.loop.reset()
        self._signals = {}

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        state = self.task.evaluate(time_s, measurement)
        xdot_r = self.loop.velocity(float(time_s), state.error)
        zeta_r = self.task.reference_velocity(state, xdot_r)
        tau = -self.damping * (state.v - zeta_r)
        self._signals = {
            "force_desired_world_N": state.force_desired_world_N,
            "e_x": state.error,
            "xdot_r": xdot_r,
            "zeta_r": zeta_r,
            "force_integral_Ns": self.loop.integral_Ns.copy(),
        }
        return tau

    def signals(self) -> dict[str, np.ndarray]:
        return self._signals
