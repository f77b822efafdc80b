"""Friction of the arm's joint drives: viscous and regularized Coulomb, per joint.

    tau_f,j(v_j) = -(b_j v_j + c_j tanh(v_j / s_j))

b [N m s/rad] viscous, c [N m] Coulomb, s [rad/s] the velocity over which the Coulomb term
rises to c (tanh keeps it smooth for the integrators). Its power tau_f . v <= 0 for every v
(dissipative). A generalized force on the joints, added to tau inside the plant's dynamics
(compiled: src/uvms_core/joint_friction.hpp). A scenario gives b and c in ``[joints]``, or
takes a URDF's ``<dynamics damping="b" friction="c"/>`` (Pinocchio's ``model.damping``,
``model.friction``) with ``joints.use_model_friction``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError

__all__ = ["DEFAULT_COULOMB_VELOCITY_RAD_S", "JointFriction"]

#: s when the model or scenario does not give one [rad/s].
DEFAULT_COULOMB_VELOCITY_RAD_S = 0.01


@dataclass(frozen=True)
class JointFriction:
    """b, c, s per arm joint (n,) each; see the module."""

    viscous_Nms: np.ndarray
    coulomb_Nm: np.ndarray
    velocity_scale_rad_s: np.ndarray

    def __post_init__(self) -> None:
        b = np.asarray(self.viscous_Nms, dtype=float).reshape(-1)
        c = np.asarray(self.coulomb_Nm, dtype=float).reshape(-1)
        s = np.asarray(self.velocity_scale_rad_s, dtype=float).reshape(-1)
        if not (b.shape == c.shape == s.shape):
            raise ParameterError(
                f"joint friction needs one b, c, s per joint, got {b.size}, {c.size}, {s.size}"
            )
        for name, values in (("viscous_Nms", b), ("coulomb_Nm", c)):
            if not np.all(np.isfinite(values)) or np.any(values < 0.0):
                raise ParameterError(
                    f"joint friction {name} must be finite and >= 0, got {values.tolist()}"
                )
        if not np.all(np.isfinite(s)) or np.any(s <= 0.0):
            raise ParameterError(f"joint friction velocity scale must be > 0, got {s.tolist()}")
        object.__setattr__(self, "viscous_Nms", b)
        object.__setattr__(self, "coulomb_Nm", c)
        object.__setattr__(self, "velocity_scale_rad_s", s)

    @property
    def active(self) -> bool:
        return bool(np.any(self.viscous_Nms) or np.any(self.coulomb_Nm))

    def torque_Nm(self, joint_velocity: np.ndarray) -> np.ndarray:
        """tau_f (n,) [N m] at the joint velocities (n,) [rad/s]."""
        v = np.asarray(joint_velocity, dtype=float)
        return -(self.viscous_Nms * v + self.coulomb_Nm * np.tanh(v / self.velocity_scale_rad_s))
