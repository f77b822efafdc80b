"""What an environment asks of the policy: its goal signal, reward and termination.

Rewards use the TRUE state (the policy sees only the noisy measurement), so a policy is
not rewarded for sensor noise. Per step, with a = the normalized action (nv,):

- force tracking:  r = -|f - f_d(t)|^2 / (1 N)^2 - w_effort mean(a^2), f the true contact
  force [N]; terminated when a force component leaves its funnel |f_i - f_d,i| < rho_i(t),
  rho(t) = (rho0 - rho_inf) exp(-l t) + rho_inf (the PPC's first-level funnel of the
  scenario, or ``funnel`` given to the environment).
- station keeping: r = -|p - p_d|^2 / (0.1 m)^2 - |log(R_d^T R)|^2 / (0.1 rad)^2
  - w_effort mean(a^2), p, R the true vehicle position and attitude; terminated when
  |p - p_d| > ``max_position_error_m``.
- pose tracking (a scenario's ``[task]``): r = -|p_r(t) - p|^2 / (0.1 m)^2
  - |log3(R_r R^T)|^2 / (0.1 rad)^2 - w_effort mean(a^2), p, R the tracked frame's true
  pose in the task frame; terminated when |p_r(t) - p| > ``max_position_error_m``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.control.performance import PerformanceFunction
from uvms_pin.control.tracking.task import TrackingTask, orientation_error
from uvms_pin.errors import ParameterError

POSITION_SCALE_M = 0.1
ANGLE_SCALE_RAD = 0.1


@dataclass(frozen=True)
class StepOutcome:
    """reward, terminated and the terms that made them (for ``info``)."""

    reward: float
    terminated: bool
    terms: dict[str, float]


def effort_penalty(action: np.ndarray, weight: float) -> float:
    return weight * float(action @ action) / action.size  # w mean(a^2)


class ForceTrackingTask:
    """Track f_d(t) at the end-effector inside a funnel.

    Args:
        desired_force: t [s] -> f_d (3,) [N], world axes.
        funnel: the funnel of the three force errors (None: no funnel termination).
        effort_weight: w_effort (dimensionless).
    """

    name = "force_tracking"
    goal_size = 3
    goal_names = ("f_d_x_N", "f_d_y_N", "f_d_z_N")

    def __init__(
        self,
        desired_force: Callable[[float], np.ndarray],
        funnel: PerformanceFunction | None,
        effort_weight: float,
    ):
        if funnel is not None and funnel.size != 3:
            raise ParameterError(f"the force funnel needs 3 components, got {funnel.size}")
        self.desired_force = desired_force
        self.funnel = funnel
        self.effort_weight = effort_weight

    def goal(self, time_s: float) -> np.ndarray:
        return np.asarray(self.desired_force(time_s), dtype=float)

    def outcome(
        self, time_s: float, q: np.ndarray, contact_world: np.ndarray, action: np.ndarray
    ) -> StepOutcome:
        error = contact_world[:3] - self.goal(time_s)
        tracking = float(error @ error)
        effort = effort_penalty(action, self.effort_weight)
        outside = self.funnel is not None and bool(
            np.any(np.abs(error) >= self.funnel.value(time_s))
        )
        terms = {"force_error_N": float(np.sqrt(tracking)), "effort_penalty": effort}
        return StepOutcome(-tracking - effort, outside, terms)


class StationKeepingTask:
    """Hold the vehicle at a pose (p_d [m], R_d) against current and disturbances."""

    name = "station_keeping"
    goal_size = 7
    goal_names = ("p_d_x_m", "p_d_y_m", "p_d_z_m", "quat_d_x", "quat_d_y", "quat_d_z", "quat_d_w")

    def __init__(self, target_q: np.ndarray, max_position_error_m: float, effort_weight: float):
        if not (max_position_error_m > 0.0 and np.isfinite(max_position_error_m)):
            raise ParameterError(
                f"max_position_error_m must be positive, got {max_position_error_m}"
            )
        self.target_position_m = np.asarray(target_q[:3], dtype=float).copy()
        self.target_quaternion = np.asarray(target_q[3:7], dtype=float).copy()
        self._target_rotation = pin.Quaternion(self.target_quaternion).toRotationMatrix()
        self.max_position_error_m = max_position_error_m
        self.effort_weight = effort_weight

    def goal(self, time_s: float) -> np.ndarray:
        return np.concatenate([self.target_position_m, self.target_quaternion])

    def outcome(
        self, time_s: float, q: np.ndarray, contact_world: np.ndarray, action: np.ndarray
    ) -> StepOutcome:
        position_error = float(np.linalg.norm(q[:3] - self.target_position_m))
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        angle_error = float(np.linalg.norm(pin.log3(self._target_rotation.T @ rotation)))
        effort = effort_penalty(action, self.effort_weight)
        reward = -((position_error / POSITION_SCALE_M) ** 2) - (angle_error / ANGLE_SCALE_RAD) ** 2
        terms = {
            "position_error_m": position_error,
            "angle_error_rad": angle_error,
            "effort_penalty": effort,
        }
        return StepOutcome(reward - effort, position_error > self.max_position_error_m, terms)


class PoseTrackingTask:
    """Follow a tracking task's reference pose (`uvms_pin.control.tracking.task`).

    The goal is [p_r(t) [m] (3), p_dot_r(t) [m/s] (3), quaternion of R_r xyzw (4)], task
    frame.
    """

    name = "pose_tracking"
    goal_size = 10
    goal_names = ("p_r_x_m", "p_r_y_m", "p_r_z_m", "v_r_x_m_s", "v_r_y_m_s", "v_r_z_m_s",
                  "quat_r_x", "quat_r_y", "quat_r_z", "quat_r_w")  # fmt: skip

    def __init__(
        self,
        task: TrackingTask,
        model: pin.Model,
        max_position_error_m: float,
        effort_weight: float,
    ):
        if not (max_position_error_m > 0.0 and np.isfinite(max_position_error_m)):
            raise ParameterError(
                f"max_position_error_m must be positive, got {max_position_error_m}"
            )
        self.task, self.model, self.data = task, model, model.createData()
        self._quaternion = pin.Quaternion(task.rotation_reference).coeffs().copy()
        self.max_position_error_m = max_position_error_m
        self.effort_weight = effort_weight

    def goal(self, time_s: float) -> np.ndarray:
        position, velocity, _ = self.task.path.at(time_s)
        return np.concatenate([position, velocity, self._quaternion])

    def outcome(
        self, time_s: float, q: np.ndarray, contact_world: np.ndarray, action: np.ndarray
    ) -> StepOutcome:
        position, rotation = self.task.pose(self.model, self.data, q)
        position_error = float(np.linalg.norm(self.task.path.at(time_s)[0] - position))
        angle_error = float(
            np.linalg.norm(orientation_error(self.task.rotation_reference, rotation))
        )
        effort = effort_penalty(action, self.effort_weight)
        reward = -((position_error / POSITION_SCALE_M) ** 2) - (angle_error / ANGLE_SCALE_RAD) ** 2
        terms = {
            "position_error_m": position_error,
            "angle_error_rad": angle_error,
            "effort_penalty": effort,
        }
        return StepOutcome(reward - effort, position_error > self.max_position_error_m, terms)
