"""Coulomb friction of joints as a constraint (Pinocchio's `JointFrictionConstraintModel`),
solved implicitly by `step.constrained_velocity`: exact sticking, no smoothing.

A joint j with Coulomb friction c_j [N m or N] has one row, J = e_j, and the impulse
lambda_j [N m s or N s] in the box |lambda_j| <= c_j h over the period h:

    |lambda_j| <  c_j h   =>  v_j+ = 0                 (it sticks)
    |lambda_j| =  c_j h   =>  v_j+ opposes lambda_j     (it slips against the friction)

The explicit model (`uvms_pin.physics.joint_friction`) smooths the Coulomb term with
tanh(v / s) so that an integrator can take it; held by a torque below c, a joint there
creeps at v ~ s tau / c. Here it stands still. Viscous friction stays a smooth force.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.constraints.rows import JOINT_IMPULSE_UNIT, ConstraintRows, evaluated

__all__ = ["JointCoulombFriction"]


@dataclass(frozen=True)
class JointCoulombFriction:
    """Coulomb friction ``coulomb_Nm`` (n,) [N m or N] on the joints ``joint_ids`` (n,),
    one velocity coordinate each, in increasing order."""

    joint_ids: tuple[int, ...]
    coulomb_Nm: np.ndarray
    name: str = "joint_friction"

    def __post_init__(self) -> None:
        coulomb = np.asarray(self.coulomb_Nm, dtype=float).reshape(-1)
        if coulomb.shape != (len(self.joint_ids),):
            raise ParameterError(
                f"one Coulomb friction per joint: {len(self.joint_ids)} joints, "
                f"{coulomb.size} values"
            )
        if not np.all(np.isfinite(coulomb)) or np.any(coulomb < 0.0):
            raise ParameterError(f"Coulomb friction must be finite and >= 0, got {coulomb}")
        if list(self.joint_ids) != sorted(set(self.joint_ids)):
            raise ParameterError(
                f"the joints must be distinct and in increasing order, got {self.joint_ids}"
            )
        object.__setattr__(self, "coulomb_Nm", coulomb)

    @staticmethod
    def of_uvms(uvms: UVMS, coulomb_Nm: np.ndarray) -> JointCoulombFriction:
        """Coulomb friction ``coulomb_Nm`` (one per arm joint) on ``uvms``'s arm joints."""
        return JointCoulombFriction(tuple(range(2, uvms.model.njoints)), coulomb_Nm)

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """One row per joint, always (`ConstraintSet.rows`): friction acts at any speed."""
        for joint_id in self.joint_ids:
            if not 0 < joint_id < model.njoints or model.joints[joint_id].nv != 1:
                raise ParameterError(f"joint {joint_id} is not a joint with one velocity")
        # Pinocchio reads the bounds at each joint's velocity index: (nv,) vectors
        upper = np.zeros(model.nv)
        upper[[model.joints[j].idx_v for j in self.joint_ids]] = self.coulomb_Nm
        friction = pin.JointFrictionConstraintModel(
            model, pin.StdVec_Index(list(self.joint_ids)), -upper, upper
        )
        friction.setTimeStep(period_s)
        n = len(self.joint_ids)
        return ConstraintRows.single(
            self.name,
            JOINT_IMPULSE_UNIT,
            evaluated(model, data, friction),
            np.zeros(n),
            np.zeros(n, dtype=bool),
            tuple(model.names[j] for j in self.joint_ids),
        )
