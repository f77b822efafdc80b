"""The arm joints' position limits as unilateral constraints (Pinocchio's
`JointLimitConstraintModel`), solved implicitly by `step.constrained_velocity`.

A joint j with limits q_min <= q_j <= q_max has two rows, each with an impulse lambda >= 0
[N m s for a revolute joint, N s for a prismatic one]:

    lower: gap r = q_j - q_min, J = +e_j        upper: gap r = q_max - q_j, J = -e_j

(e_j the unit row on the joint's velocity coordinate), so J v = r_dot. A continuous joint
has no limit and no row. Unlike the compliant stops (`uvms_pin.physics.joint_stops`), whose
stiffness k and damping c make an explicit integrator diverge once h^2 k / I or h c / I is
large, the constraint has no stiffness: the joint stops at its limit in one period
whatever its inertia.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.constraints.rows import JOINT_IMPULSE_UNIT, ConstraintRows, evaluated

__all__ = ["JointLimits"]


@dataclass(frozen=True)
class JointLimits:
    """The position limits of some joints of a model, as constraints.

    Attributes:
        joint_ids: the Pinocchio joints (one coordinate each, finite limits in the model's
            ``lowerPositionLimit`` / ``upperPositionLimit``).
        margin: a row is solved when its gap is at most h |v_j| + margin [rad or m]: the
            reach of the period plus this allowance for the solver's tolerance.
        name: the key of the impulses in the step's result.
    """

    joint_ids: tuple[int, ...]
    margin: float = 1.0e-3
    name: str = "joint_limits"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.margin) and self.margin >= 0.0):
            raise ParameterError(f"the joint limits' margin must be >= 0 [rad], got {self.margin}")

    @staticmethod
    def of_uvms(uvms: UVMS, margin: float = 1.0e-3) -> JointLimits:
        """The URDF limits of ``uvms``'s arm joints (`UVMS.arm_joints`); a continuous joint
        (or one without limits) has none."""
        limited = np.flatnonzero(uvms.arm_joints.limited)
        return JointLimits(tuple(int(2 + k) for k in limited), float(margin))

    def record(self) -> dict[str, object]:
        """The limits as plain data (a rollout's world record)."""
        return {
            "joint_ids": list(self.joint_ids),
            "margin_rad": self.margin,
            "solved": "implicitly",
        }

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """The limits at q that the joints can reach within ``period_s`` at ``speed``
        (`ConstraintSet.rows`): lower rows first, then upper rows."""
        reach = np.zeros(model.nq)
        for joint_id in self.joint_ids:
            joint = model.joints[joint_id]
            _check_joint(model, joint_id)
            reach[joint.idx_q] = period_s * speed[joint.idx_v] + self.margin
        limit = pin.JointLimitConstraintModel(
            model,
            pin.StdVec_Index(list(self.joint_ids)),
            model.lowerPositionLimit,
            model.upperPositionLimit,
            reach,
        )
        limit.makeSelectionFilteredByLimitProximity(q)
        if limit.residualSize() == 0:
            return ConstraintRows.empty(self.name, JOINT_IMPULSE_UNIT, model.nv)
        constraint = evaluated(model, data, limit)
        _, constraint_data, jacobian = constraint
        gap = np.array(constraint_data.extract().constraint_residual, dtype=float)
        labels = tuple(
            _label(model, row, k < limit.lowerResidualSize()) for k, row in enumerate(jacobian)
        )
        positional = np.ones(gap.shape[0], dtype=bool)
        return ConstraintRows.single(
            self.name, JOINT_IMPULSE_UNIT, constraint, gap, positional, labels
        )


def _check_joint(model: pin.Model, joint_id: int) -> None:
    if not 0 < joint_id < model.njoints or model.joints[joint_id].nq != 1:
        raise ParameterError(f"joint {joint_id} is not a joint with one coordinate of the model")
    idx_q = model.joints[joint_id].idx_q
    low, high = model.lowerPositionLimit[idx_q], model.upperPositionLimit[idx_q]
    if not (np.isfinite(low) and np.isfinite(high) and max(-low, high) < 1e300):
        raise ParameterError(f"joint '{model.names[joint_id]}' has no finite position limits")


def _label(model: pin.Model, jacobian_row: np.ndarray, lower: bool) -> str:
    """'<joint> lower' or '<joint> upper' for a row of the limits' Jacobian."""
    idx_v = int(np.argmax(np.abs(jacobian_row)))
    joint_id = next(j for j in range(1, model.njoints) if model.joints[j].idx_v == idx_v)
    return f"{model.names[joint_id]} {'lower' if lower else 'upper'}"
