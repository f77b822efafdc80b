"""Joint stops: the URDF's position limits as compliant stops.

Past a limit by e = q - q_max > 0 (or e = q_min - q > 0) a joint gets the torque

    tau_stop = -max(0, k_s e + c_s e_dot)     (at q_max; mirrored at q_min)    [N m or N]

a spring-damper that, like the contact's normal force, never pulls the joint back into its
range faster than the spring alone would (the max(0, .)): it acts only past the limit and
only pushes. Held by an effort tau, a joint rests at e = tau / k_s past its limit.
The spring stores U_stop = 1/2 k_s e^2 [J] (`JointStops.energy_J`): a part of the potential
energy, so that an undamped stop conserves kinetic + potential energy (the damper and the
max(0, .) only take energy out).
Joints with an infinite limit (continuous) have no stop there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError

__all__ = ["JointStops"]


@dataclass(frozen=True)
class JointStops:
    """Compliant stops at the arm joints' limits.

    Attributes:
        lower_rad, upper_rad: each stopped joint's limits (n,) [rad or m] (+-inf: no stop).
        stiffness_Nm_rad: k_s [N m/rad] (> 0). damping_Nm_s_rad: c_s [N m s/rad] (>= 0).
        names: the joints, for messages and metrics.
        q_index, v_index: each joint's coordinate in q and in zeta (n,); None: the arm's
            joints in order, one coordinate each (q[7:], zeta[6:]).
    """

    lower_rad: np.ndarray
    upper_rad: np.ndarray
    stiffness_Nm_rad: float = 1.0e3
    damping_Nm_s_rad: float = 5.0
    names: tuple[str, ...] = ()
    q_index: np.ndarray | None = None
    v_index: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.stiffness_Nm_rad) and self.stiffness_Nm_rad > 0.0):
            raise ParameterError(f"stop stiffness must be > 0, got {self.stiffness_Nm_rad}")
        if not (math.isfinite(self.damping_Nm_s_rad) and self.damping_Nm_s_rad >= 0.0):
            raise ParameterError(f"stop damping must be >= 0, got {self.damping_Nm_s_rad}")
        if np.any(self.lower_rad > self.upper_rad):
            raise ParameterError("a joint's lower limit is above its upper limit")
        n = len(self.lower_rad)
        if self.q_index is None:
            object.__setattr__(self, "q_index", 7 + np.arange(n))
        if self.v_index is None:
            object.__setattr__(self, "v_index", 6 + np.arange(n))

    @staticmethod
    def of_model(model: pin.Model, stiffness_Nm_rad: float = 1.0e3, damping_Nm_s_rad: float = 5.0):
        """The stops of a UVMS model's arm joints with one coordinate (revolute,
        prismatic), from its position limits; a continuous joint has none."""
        joints = [j for j in range(2, model.njoints) if model.joints[j].nq == 1]
        q_index = np.array([model.joints[j].idx_q for j in joints], dtype=int)
        return JointStops(
            np.array(model.lowerPositionLimit[q_index], dtype=float),
            np.array(model.upperPositionLimit[q_index], dtype=float),
            float(stiffness_Nm_rad),
            float(damping_Nm_s_rad),
            tuple(model.names[j] for j in joints),
            q_index,
            np.array([model.joints[j].idx_v for j in joints], dtype=int),
        )

    def torque(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """tau_stop (nv,): zero on the vehicle and on every joint inside its range."""
        out = np.zeros(v.shape[0])
        joints, rates = q[self.q_index], v[self.v_index]
        k, c = self.stiffness_Nm_rad, self.damping_Nm_s_rad
        over = np.maximum(joints - self.upper_rad, 0.0)
        under = np.maximum(self.lower_rad - joints, 0.0)
        push_down = np.where(over > 0.0, np.maximum(0.0, k * over + c * rates), 0.0)
        push_up = np.where(under > 0.0, np.maximum(0.0, k * under - c * rates), 0.0)
        out[self.v_index] = push_up - push_down
        return out

    def energy_J(self, q: np.ndarray) -> float:
        """U_stop = sum 1/2 k_s e^2 [J] over the joints past a limit at q (nq,): the
        potential whose negative gradient is the spring part of `torque`."""
        joints = np.asarray(q)[self.q_index]
        over = np.maximum(joints - self.upper_rad, 0.0) + np.maximum(self.lower_rad - joints, 0.0)
        return float(0.5 * self.stiffness_Nm_rad * over @ over)

    def at_stop(self, q: np.ndarray) -> np.ndarray:
        """Which joints are past a limit (n,) bool, at q (nq,) or a trajectory (T, nq)."""
        joints = np.asarray(q)[..., self.q_index]
        return (joints > self.upper_rad) | (joints < self.lower_rad)

    def record(self) -> dict[str, Any]:
        return {
            "stiffness_Nm_rad": float(self.stiffness_Nm_rad),
            "damping_Nm_s_rad": float(self.damping_Nm_s_rad),
            "lower_rad": [float(x) if math.isfinite(x) else None for x in self.lower_rad],
            "upper_rad": [float(x) if math.isfinite(x) else None for x in self.upper_rad],
        }
