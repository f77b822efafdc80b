"""Model-based inverse-dynamics (computed-torque) control, for force/orientation or motion.

It cancels the dynamics of the UVMS it is given, M(q) zeta_dot + h(q, zeta) = tau + J^T
(-w_meas) (`uvms_pin.physics.dynamics`: added mass inside M; Coriolis, damping and restoring in h):

    tau = M(q) a + h(q, zeta) + J^lwa^T w_meas

with w_meas the measured contact wrench and a the commanded acceleration:

- force/orientation task: the outer loop of the PI force controller gives zeta_r (the
  same J^# as the PPC), and a = K_v (zeta_r - zeta) [1/s];
- motion task (``reference`` given, a function t -> (q_r, zeta_r, zeta_dot_r)):
  a = zeta_dot_r + K_v (zeta_r - zeta) + K_q (q_r (-) q), with (-) = `pin.difference`.

With the plant's exact model, no noise and the controller evaluated at every integrator
stage, the closed loop is e_ddot + K_v e_dot + K_q e = 0: a reference started on is
tracked to the integrator's precision. The model it is given can be wrong on purpose
(`uvms_pin.model.scaled.scaled_uvms`): what model knowledge buys and what its error costs.
It does not know the current or the waves (h is evaluated in still water).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.baselines.task import ForceTaskOptions, gain_vector
from uvms_pin.control.measurement import Measurement
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces, mass_matrix

__all__ = ["ComputedTorqueController", "InnerLoopGains", "MotionReference"]

#: t [s] -> (q_r (nq,), zeta_r (nv,), zeta_dot_r (nv,)).
MotionReference = Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class InnerLoopGains:
    """The inner loop's gains: velocity_gain_per_s K_v (nv,) > 0 [1/s];
    position_gain_per_s2 K_q (nv,) >= 0 [1/s^2] (motion task only). Scalars broadcast."""

    velocity_gain_per_s: ArrayLike = 5.0
    position_gain_per_s2: ArrayLike = 25.0


_GAIN_NAMES = tuple(f.name for f in fields(InnerLoopGains))


class ComputedTorqueController(Controller):
    """Inverse dynamics of a given (possibly perturbed) UVMS model.

    Args:
        uvms: the model the controller believes in (a private copy of its Pinocchio model
            is used: the plant's work buffers are never touched).
        ee_frame_name: end-effector frame (the force task and the contact Jacobian).
        reference: a `MotionReference` for a motion task; None = force/orientation task.
        **options: the inner loop's gains, keywords of `InnerLoopGains`
            (velocity_gain_per_s, position_gain_per_s2), and the force task, keywords of
            `ForceTaskOptions` as for `PIForceController` (kp_force_m_s_per_N, ki_force_m_s2_per_N,
            k_orientation_per_s, integral_limit_Ns, desired_force_world_N, desired_rpy,
            velocity_weights, null_space_gain_per_s, null_space_target).
    """

    def __init__(
        self,
        uvms: UVMS,
        ee_frame_name: str,
        *,
        reference: MotionReference | None = None,
        **options: Any,
    ):
        gains = InnerLoopGains(**{k: options.pop(k) for k in _GAIN_NAMES if k in options})
        force_task = ForceTaskOptions(**options)
        self.uvms = uvms.with_model(pin.Model(uvms.model))
        self.task = force_task.task(self.uvms.model, ee_frame_name)
        nv = self.task.nv
        self.k_v = gain_vector("velocity_gain_per_s", gains.velocity_gain_per_s, nv, positive=True)
        self.k_q = gain_vector("position_gain_per_s2", gains.position_gain_per_s2, nv)
        self.reference = reference
        self.loop = force_task.loop()
        self._signals: dict[str, np.ndarray] = {}

    def reset(self) -> None:
        self.loop.reset()
        self._signals = {}

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        time_s = float(time_s)
        state = self.task.evaluate(time_s, measurement)
        q, v = state.q, state.v
        if self.reference is None:
            zeta_r = self.task.reference_velocity(state, self.loop.velocity(time_s, state.error))
            acceleration = self.k_v * (zeta_r - v)
        else:
            q_r, zeta_r, zeta_dot_r = self.reference(time_s)
            position_error = pin.difference(self.uvms.model, q, q_r)
            acceleration = zeta_dot_r + self.k_v * (zeta_r - v) + self.k_q * position_error
        wrench = np.asarray(measurement.wrench_world, dtype=float)
        tau = (
            mass_matrix(self.uvms, q) @ acceleration
            + bias_forces(self.uvms, q, v)
            + state.jacobian_lwa.T @ wrench
        )
        self._signals = {
            "force_desired_world_N": state.force_desired_world_N,
            "e_x": state.error,
            "zeta_r": np.asarray(zeta_r, dtype=float),
        }
        return tau

    def signals(self) -> dict[str, np.ndarray]:
        return self._signals
