"""A tracking task: which frame follows which reference pose, expressed in which frame.

Targets: the end-effector (in the world frame, or in the vehicle's body frame, where only
the arm moves it) or the vehicle (world frame: station keeping and vehicle paths). The
reference is a position path (`uvms_pin.control.tracking.trajectory`) and a constant
orientation R_r. The task's velocity is [p_dot (3) m/s; omega (3) rad/s], both in the
task frame's axes, and ``pose_and_jacobian`` gives x and the 6 x nv Jacobian J with
x_dot = J zeta (zeta: Pinocchio's v):

- end-effector, world:  J = J_e^{LWA} (Pinocchio's LOCAL_WORLD_ALIGNED frame Jacobian);
- end-effector, vehicle: J = [0 | R_v^T J_e,arm^{LWA}]: the vehicle's own motion moves
  the frame it is measured in with it, so only the joints appear;
- vehicle, world: J = [[R_v, 0, 0], [0, R_v, 0]] (body velocities to world axes).

The pose error is e_p = p_r - p [m] and e_o = log3(R_r R^T) [rad] (the rotation taking
the frame to its reference, in the task frame's axes; |e_o| is the angle between them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.control.tracking.trajectory import Path
from uvms_pin.errors import ParameterError
from uvms_pin.physics.kinematics import frame_id_from_name

__all__ = ["TARGETS", "TrackingTask", "orientation_error"]

#: (target, frame) pairs a task can have.
TARGETS = {("end_effector", "world"), ("end_effector", "vehicle"), ("vehicle", "world")}


def vehicle_rotation(q: np.ndarray) -> np.ndarray:
    """R_v, body to world, of the free flyer's quaternion (xyzw) q[3:7]."""
    x, y, z, w = q[3:7]
    return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()


def orientation_error(rotation_reference: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """e_o = log3(R_r R^T) [rad] (axis times angle, in the axes both are expressed in)."""
    return np.asarray(pin.log3(rotation_reference @ rotation.T), dtype=float)


@dataclass(frozen=True)
class TrackingTask:
    """What follows which reference.

    Attributes:
        kind: the path's name ("circle", "hold", ...). target: "end_effector" | "vehicle".
        frame: "world" | "vehicle" (the end-effector's only). frame_name: the end-effector
            frame ("" for the vehicle). path: the reference position p_r(t) [m] in the task
            frame. rotation_reference: R_r (3, 3), task frame.
        transient_s: the metrics "after the transient" start here [s].
        settle_tolerance_m: the position error the settling time waits for [m].
        record: the task as written (what rollouts keep).
        track_orientation: False: the controllers follow the position alone (an arm with
            fewer than 6 joints in the vehicle frame); the orientation error is still
            measured against R_r.
    """

    kind: str
    target: str
    frame: str
    frame_name: str
    path: Path
    rotation_reference: np.ndarray
    transient_s: float = 0.0
    settle_tolerance_m: float = 0.01
    record: dict[str, Any] = field(default_factory=dict)
    track_orientation: bool = True

    @property
    def rows(self) -> slice:
        """The rows of [p_dot; omega] the controllers follow (all 6, or the position's)."""
        return slice(0, 6 if self.track_orientation else 3)

    def __post_init__(self) -> None:
        if (self.target, self.frame) not in TARGETS:
            raise ParameterError(
                f"a task of the {self.target} in the {self.frame} frame is not one of "
                f"{sorted(TARGETS)}"
            )
        rotation = np.asarray(self.rotation_reference, dtype=float)
        if rotation.shape != (3, 3) or not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9):
            raise ParameterError("rotation_reference must be a 3x3 rotation matrix")
        if not (math.isfinite(self.transient_s) and self.transient_s >= 0):
            raise ParameterError(f"transient_s must be >= 0, got {self.transient_s}")
        if not (math.isfinite(self.settle_tolerance_m) and self.settle_tolerance_m > 0):
            raise ParameterError(
                f"settle_tolerance_m must be positive, got {self.settle_tolerance_m}"
            )

    def frame_id(self, model: pin.Model) -> int:
        """The tracked frame's index (-1 for the vehicle)."""
        if self.target == "vehicle":
            return -1
        return frame_id_from_name(model, self.frame_name, "task frame")

    def pose(
        self, model: pin.Model, data: pin.Data, q: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(position [m], rotation (3, 3)) of the tracked frame in the task frame."""
        return self.pose_and_jacobian(model, data, q, jacobian=False)[:2]

    def pose_and_jacobian(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, *, jacobian: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(position, rotation, J (6, nv) or None) of the tracked frame, task frame."""
        rotation_v = vehicle_rotation(q)
        if self.target == "vehicle":
            jac = None
            if jacobian:
                jac = np.zeros((6, model.nv))
                jac[:3, :3] = rotation_v
                jac[3:, 3:6] = rotation_v
            return np.array(q[:3], dtype=float), rotation_v, jac
        fid = self.frame_id(model)
        pin.framesForwardKinematics(model, data, q)
        placement = data.oMf[fid]
        position, rotation = placement.translation.copy(), placement.rotation.copy()
        jac = None
        if jacobian:
            pin.computeJointJacobians(model, data, q)
            jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED).copy()
        if self.frame == "vehicle":
            position = rotation_v.T @ (position - q[:3])
            rotation = rotation_v.T @ rotation
            if jac is not None:
                jac[:, :6] = 0.0
                jac[:3] = rotation_v.T @ jac[:3]
                jac[3:] = rotation_v.T @ jac[3:]
        return position, rotation, jac
