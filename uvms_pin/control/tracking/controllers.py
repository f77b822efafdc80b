"""The controllers of tracking tasks: task-priority (a kinematic level and a dynamic level)
and resolved-acceleration computed torque.

`TaskPriorityController`: zeta_r from the prioritized tasks
(`uvms_pin.control.tracking.task_priority`), followed by inverse dynamics or the PPC's
velocity level (`uvms_pin.control.tracking.dynamic_level`).

`ResolvedAccelerationController` (computed torque in task space): with x_dot = J zeta,

    a_x  = p_ddot_r + K_d (p_dot_r - p_dot) + K_p e_p;   a_o = -K_d omega + K_p e_o
    a    = J^#_W (a_task - J_dot zeta) - (I - J^#_W J) K_n zeta
    tau  = M(q) a + h(q, zeta)

(J_dot zeta from Pinocchio's classical frame acceleration at zero joint acceleration);
with the exact model, in still water and without noise, e_ddot + K_d e_dot + K_p e = 0.
It has no integral action: a current it does not model leaves a steady error.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.baselines.task import gain_vector
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.pseudo_inverse import pseudo_inverse
from uvms_pin.control.tracking.task import TrackingTask, orientation_error, vehicle_rotation
from uvms_pin.control.tracking.task_priority import KinematicGains, KinematicLevel
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces, mass_matrix
from uvms_pin.results.signal import Signal

__all__ = [
    "ResolvedAccelerationController",
    "ResolvedAccelerationGains",
    "TaskPriorityController",
    "task_signals",
]

_XYZ = ("x", "y", "z")
_ROT = ("rx", "ry", "rz")


def task_signals(task: TrackingTask, e_p: np.ndarray, e_o: np.ndarray) -> dict[str, Signal]:
    """The tracking errors as named signals (task frame axes)."""
    return {
        "task_position_error": Signal(e_p, _XYZ, "m"),
        "task_orientation_error": Signal(e_o, _ROT, "rad"),
    }


class TaskPriorityController(Controller):
    """Task-priority control: kinematic level -> zeta_r -> dynamic level -> tau.

    Args:
        uvms: the plant's model (kinematics; the inverse-dynamics level uses a copy of it).
        task: the tracking task. gains: the kinematic level's `KinematicGains`.
        dynamic: an `InverseDynamicsLevel` or a `PpcVelocityLevel`.
    """

    def __init__(self, uvms: UVMS, task: TrackingTask, gains: KinematicGains, dynamic):
        self.kinematics = KinematicLevel(pin.Model(uvms.model), task, gains)
        self.dynamic = dynamic
        self.task = task
        self._signals: dict = {}

    def reset(self) -> None:
        self.dynamic.reset()
        self._signals = {}

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        q, v = measurement.q, measurement.v
        zeta_r, errors = self.kinematics.reference(time_s, q, v)
        tau = self.dynamic.torque(time_s, q, v, zeta_r)
        self._signals = {
            **task_signals(self.task, errors["position_error"], errors["orientation_error"]),
            "zeta_r": zeta_r,
            "e_zeta": v - zeta_r,
        }
        if errors["active_limits"].size:
            names = [f"joint_{k + 1}" for k in range(errors["active_limits"].size)]
            self._signals["joint_limit_active"] = Signal(errors["active_limits"], names, "")
        return tau

    def signals(self) -> dict:
        return self._signals


@dataclass(frozen=True)
class ResolvedAccelerationGains:
    """The gains of `ResolvedAccelerationController` (scalars broadcast).

    Attributes:
        position_gain_per_s2: K_p (6,) > 0 [1/s^2]. velocity_gain_per_s: K_d (6,) > 0 [1/s].
        null_space_damping_per_s: K_n >= 0 [1/s]. velocity_weights: W (nv,) > 0 of J^#_W
        (None: ones).
    """

    position_gain_per_s2: ArrayLike = 4.0
    velocity_gain_per_s: ArrayLike = 4.0
    null_space_damping_per_s: float = 2.0
    velocity_weights: ArrayLike | None = None


class ResolvedAccelerationController(Controller):
    """Computed torque in task space (module docstring).

    Args:
        uvms: the model believed in (a private copy). task: an end-effector task in the world
            frame or a vehicle task. **gains: keywords of `ResolvedAccelerationGains`
            (position_gain_per_s2, velocity_gain_per_s, null_space_damping_per_s,
            velocity_weights); an unknown one is a TypeError.
    """

    def __init__(self, uvms: UVMS, task: TrackingTask, **gains: Any):
        options = ResolvedAccelerationGains(**gains)
        if task.target == "end_effector" and task.frame != "world":
            raise ParameterError(
                "computed torque tracks end-effector tasks in the world frame only "
                f"(this task is in the {task.frame} frame)"
            )
        self.uvms = uvms.with_model(pin.Model(uvms.model))
        self.model = self.uvms.model
        self.data = self.model.createData()
        self.task = task
        self.k_p = gain_vector(
            "position_gain_per_s2", options.position_gain_per_s2, 6, positive=True
        )
        self.k_d = gain_vector("velocity_gain_per_s", options.velocity_gain_per_s, 6, positive=True)
        damping = options.null_space_damping_per_s
        self.k_n = float(gain_vector("null_space_damping_per_s", damping, 1)[0])
        nv = self.model.nv
        weights = options.velocity_weights
        self.weights = (
            np.ones(nv)
            if weights is None
            else gain_vector("velocity_weights", weights, nv, positive=True)
        )
        self._frame_id = task.frame_id(self.model)
        self._signals: dict = {}

    def reset(self) -> None:
        self._signals = {}

    def _bias_acceleration(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """J_dot zeta (6,) in the task's axes."""
        if self.task.target == "vehicle":
            rotation = vehicle_rotation(q)
            return np.concatenate([rotation @ np.cross(v[3:6], v[:3]), np.zeros(3)])
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        acc = pin.getFrameClassicalAcceleration(
            model, data, self._frame_id, pin.LOCAL_WORLD_ALIGNED
        )
        return np.concatenate([acc.linear, acc.angular])

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        q, v = measurement.q, measurement.v
        task = self.task
        position, rotation, jacobian = task.pose_and_jacobian(self.model, self.data, q)
        p_r, v_r, a_r = task.path.at(time_s)
        e_p = p_r - position
        e_o = orientation_error(task.rotation_reference, rotation)
        rate = jacobian @ v
        a_task = (
            np.concatenate([a_r, np.zeros(3)])
            + self.k_d * (np.concatenate([v_r, np.zeros(3)]) - rate)
            + self.k_p * np.concatenate([e_p, e_o])
        )
        rows = task.rows
        jacobian = jacobian[rows]
        inverse = pseudo_inverse(jacobian, 1e-9, self.weights)
        null = np.eye(self.model.nv) - inverse @ jacobian
        wanted = (a_task - self._bias_acceleration(q, v))[rows]
        acceleration = inverse @ wanted - self.k_n * (null @ v)
        self._signals = task_signals(task, e_p, e_o)
        return mass_matrix(self.uvms, q) @ acceleration + bias_forces(self.uvms, q, v)

    def signals(self) -> dict:
        return self._signals
