"""Dynamic levels: joint torques and the vehicle's body wrench that make the generalized
velocity zeta follow a reference zeta_r (nv,) [m/s, rad/s body; joint rates].

- `InverseDynamicsLevel` (model-based): with e = zeta_r - zeta,

      tau = M(q) (K_v e + K_i int e dt) + h(q, zeta)

  M with the added mass, h the Coriolis, damping and restoring terms of the model it is
  given (still water: it does not know a current; the integral, clamped to
  ``integral_limit``, takes up what the model misses, such as the current's drag).
  zeta_r's own derivative is not fed forward (it would differentiate the measurement
  noise); on the slow tracking tasks it is small (0.01 m/s^2 on the 0.2 m circle in 20 s).
- `PpcVelocityLevel` (model-free): the paper's second level on e = zeta - zeta_r,
  xi = e / rho(t), tau = -K P^-1 R(xi) eps(xi) (`uvms_pin.control.performance`); the
  velocity error never leaves its funnel (else FunnelViolation).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.control.baselines.task import gain_vector
from uvms_pin.control.performance import (
    PerformanceFunction,
    check_funnel,
    transformation_gain,
    transformed_error,
)
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces, mass_matrix

__all__ = ["InverseDynamicsLevel", "PpcVelocityLevel"]


class InverseDynamicsLevel:
    """Inverse dynamics of a given UVMS model with PI velocity feedback.

    Args:
        uvms: the model believed in (a private copy of its Pinocchio model is used).
        velocity_gain_per_s: K_v (nv,) > 0 [1/s]. integral_gain_per_s2: K_i (nv,) >= 0
        [1/s^2]. integral_limit: |int e dt| per component [m, rad] (anti-windup).
    """

    def __init__(
        self, uvms: UVMS, velocity_gain_per_s=4.0, integral_gain_per_s2=4.0, integral_limit=0.5
    ):
        self.uvms = uvms.with_model(pin.Model(uvms.model))
        nv = self.uvms.nv
        self.k_v = gain_vector("velocity_gain_per_s", velocity_gain_per_s, nv, positive=True)
        self.k_i = gain_vector("integral_gain_per_s2", integral_gain_per_s2, nv)
        self.limit = gain_vector("integral_limit", integral_limit, nv, positive=True)
        self.reset()

    def reset(self) -> None:
        self.integral = np.zeros(self.uvms.nv)
        self.last_time_s: float | None = None

    def torque(self, time_s: float, q: np.ndarray, v: np.ndarray, zeta_r: np.ndarray) -> np.ndarray:
        """tau (nv,) [N, N m body; joint efforts]."""
        error = zeta_r - v
        if self.last_time_s is not None and time_s > self.last_time_s:
            step = time_s - self.last_time_s
            self.integral = np.clip(self.integral + step * error, -self.limit, self.limit)
        self.last_time_s = time_s
        acceleration = self.k_v * error + self.k_i * self.integral
        return mass_matrix(self.uvms, q) @ acceleration + bias_forces(self.uvms, q, v)


class PpcVelocityLevel:
    """The PPC's velocity level on a given reference (model-free).

    Args:
        nv: the number of velocities.
        gain: K (nv,) > 0 [N or N m].
        funnel: rho(t) of e = zeta - zeta_r (`PerformanceFunction` with nv components).
        names: the components' names (messages of a FunnelViolation).
    """

    def __init__(self, nv: int, gain, funnel: PerformanceFunction, names: list[str]):
        self.k = gain_vector("k_zeta", gain, nv, positive=True)
        if funnel.size != nv:
            raise ParameterError(f"the velocity funnel needs {nv} components, got {funnel.size}")
        self.funnel, self.names = funnel, names

    def reset(self) -> None:
        """Stateless."""

    def torque(self, time_s: float, q: np.ndarray, v: np.ndarray, zeta_r: np.ndarray) -> np.ndarray:
        bound = self.funnel.value(time_s)
        xi = check_funnel(
            level="second", names=self.names, time_s=time_s, error=v - zeta_r, bound=bound
        )
        return -self.k / bound * transformation_gain(xi) * transformed_error(xi)
