"""How each joint body moves with the state: its velocity and acceleration Jacobians.

For joint i (LOCAL frame), with the state perturbed along the tangent, q (+) dq and v + dv
(Pinocchio's convention, `pin.integrate`):

    d nu_i    = (dnu/dq) dq + J_i dv              (J_i: the LOCAL joint Jacobian)
    d a_i     = (da/dq) dq + (da/dv) dv + J_i dqdd
    d theta_i = J_i^w dq                           (R_i -> R_i exp([theta_i]x))
    d p_world = R_i (J_i^v - [r]x J_i^w) dq        (a point r fixed in the joint frame)

Pinocchio computes the first two (`computeForwardKinematicsDerivatives`, then
`getJointVelocityDerivatives` and `getJointAccelerationDerivatives`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.hydro.vector import skew


@dataclass(frozen=True)
class JointMotion:
    """One joint body's state and its Jacobians (LOCAL frame, columns along the tangent).

    Attributes:
        rotation: R (3, 3), world <- joint. translation: the joint origin (3,) [m].
        velocity: nu (6,) [m/s; rad/s]. acceleration: a (6,) with the joint accelerations.
        jacobian: J = d nu / dv = d a / d qdd (6, nv).
        velocity_dq: d nu / dq (6, nv). acceleration_dq, acceleration_dv: d a / dq, d a / dv.
    """

    rotation: np.ndarray
    translation: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jacobian: np.ndarray
    velocity_dq: np.ndarray
    acceleration_dq: np.ndarray
    acceleration_dv: np.ndarray

    @property
    def rotation_dq(self) -> np.ndarray:
        """d theta / dq (3, nv): the body's rotation perturbation, in its own axes."""
        return self.jacobian[3:]

    def point(self, point_in_joint_m: np.ndarray) -> np.ndarray:
        """The world position (3,) [m] of a point fixed in the joint frame."""
        return self.rotation @ point_in_joint_m + self.translation

    def point_dq(self, point_in_joint_m: np.ndarray) -> np.ndarray:
        """d p_world / dq (3, nv) of a point r fixed in the joint frame: R (J^v - [r]x J^w)."""
        return self.rotation @ (self.jacobian[:3] - skew(point_in_joint_m) @ self.jacobian[3:])


def joint_motions(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, a: np.ndarray, joints
) -> dict[int, JointMotion]:
    """The `JointMotion` of each joint in ``joints`` at (q, v, a)."""
    pin.computeForwardKinematicsDerivatives(model, data, q, v, a)
    out = {}
    for j in joints:
        velocity_dq, jacobian = pin.getJointVelocityDerivatives(model, data, j, pin.LOCAL)
        _, acceleration_dq, acceleration_dv, _ = pin.getJointAccelerationDerivatives(
            model, data, j, pin.LOCAL
        )
        out[j] = JointMotion(
            rotation=data.oMi[j].rotation.copy(),
            translation=data.oMi[j].translation.copy(),
            velocity=data.v[j].vector.copy(),
            acceleration=data.a[j].vector.copy(),
            jacobian=jacobian.copy(),
            velocity_dq=velocity_dq.copy(),
            acceleration_dq=acceleration_dq.copy(),
            acceleration_dv=acceleration_dv.copy(),
        )
    return out
