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


def effort_penalties(actions: np.ndarray, weight: float) -> np.ndarray:
    """w mean(a^2) of each row of ``actions`` (N, nv)."""
    return weight * np.einsum("ij,ij->i", actions, actions) / actions.shape[1]


@dataclass(frozen=True)
class BatchOutcome:
    """rewards (N,), terminated (N,) and the terms that made them, (N,) each."""

    reward: np.ndarray
    terminated: np.ndarray
    terms: dict[str, np.ndarray]

    def row(self, i: int) -> StepOutcome:
        terms = {name: float(values[i]) for name, values in self.terms.items()}
        return StepOutcome(float(self.reward[i]), bool(self.terminated[i]), terms)


def rotation_angle_from(target_xyzw: np.ndarray, quaternions_xyzw: np.ndarray) -> np.ndarray:
    """|log(R_d^T R)| [rad] of each row (N, 4) of quaternions xyzw against the target's:
    the angle of q_d^* q, 2 atan2(|vec|, |w|), in [0, pi] (as |pin.log3| of the matrices)."""
    x, y, z, w = (-target_xyzw[0], -target_xyzw[1], -target_xyzw[2], target_xyzw[3])
    qx, qy, qz, qw = quaternions_xyzw.T
    rel_w = w * qw - x * qx - y * qy - z * qz
    rel_x = w * qx + qw * x + y * qz - z * qy
    rel_y = w * qy + qw * y + z * qx - x * qz
    rel_z = w * qz + qw * z + x * qy - y * qx
    return 2.0 * np.arctan2(np.sqrt(rel_x**2 + rel_y**2 + rel_z**2), np.abs(rel_w))


def _checked_bound(max_position_error_m: float) -> float:
    """``max_position_error_m`` [m] if it is positive and finite, else ParameterError."""
    if not (max_position_error_m > 0.0 and np.isfinite(max_position_error_m)):
        raise ParameterError(f"max_position_error_m must be positive, got {max_position_error_m}")
    return max_position_error_m


def _pose_outcome(position_error, angle_error, effort, max_position_error_m: float):
    """(reward, terminated, terms) of a pose task from the position error [m], the angle
    error [rad] and the effort penalty (floats, or (N,) arrays alike):
    r = -(e_p / 0.1 m)^2 - (e_R / 0.1 rad)^2 - effort, terminated when e_p exceeds the bound."""
    reward = -((position_error / POSITION_SCALE_M) ** 2) - (angle_error / ANGLE_SCALE_RAD) ** 2
    terms = {
        "position_error_m": position_error,
        "angle_error_rad": angle_error,
        "effort_penalty": effort,
    }
    return reward - effort, position_error > max_position_error_m, terms


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

    def bound(self, time_s: float) -> np.ndarray:
        """rho(t) (3,) [N] of the funnel, inf without one."""
        return np.full(3, np.inf) if self.funnel is None else self.funnel.value(time_s)

    def outcome(
        self, time_s: float, q: np.ndarray, contact_world: np.ndarray, action: np.ndarray
    ) -> StepOutcome:
        return self.outcomes(
            self.goal(time_s)[None], self.bound(time_s)[None], q[None], contact_world[None],
            action[None],
        ).row(0)  # fmt: skip

    def outcomes(
        self,
        goal: np.ndarray,
        bound: np.ndarray,
        q: np.ndarray,
        contact_world: np.ndarray,
        action: np.ndarray,
    ) -> BatchOutcome:
        """Per row: goal f_d (N, 3) [N], funnel bound rho (N, 3), true state q, true
        contact (N, 6) and normalized action (N, nv)."""
        error = contact_world[:, :3] - goal
        tracking = np.einsum("ij,ij->i", error, error)
        effort = effort_penalties(action, self.effort_weight)
        outside = np.any(np.abs(error) >= bound, axis=1)
        terms = {"force_error_N": np.sqrt(tracking), "effort_penalty": effort}
        return BatchOutcome(-tracking - effort, outside, terms)


class StationKeepingTask:
    """Hold the vehicle at a pose (p_d [m], R_d) against current and disturbances."""

    name = "station_keeping"
    goal_size = 7
    goal_names = ("p_d_x_m", "p_d_y_m", "p_d_z_m", "quat_d_x", "quat_d_y", "quat_d_z", "quat_d_w")

    def __init__(self, target_q: np.ndarray, max_position_error_m: float, effort_weight: float):
        self.target_position_m = np.asarray(target_q[:3], dtype=float).copy()
        self.target_quaternion = np.asarray(target_q[3:7], dtype=float).copy()
        self.max_position_error_m = _checked_bound(max_position_error_m)
        self.effort_weight = effort_weight

    def goal(self, time_s: float) -> np.ndarray:
        return np.concatenate([self.target_position_m, self.target_quaternion])

    def bound(self, time_s: float) -> np.ndarray:
        """No time-varying bound: the position bound is ``max_position_error_m``."""
        return np.zeros(0)

    def outcome(
        self, time_s: float, q: np.ndarray, contact_world: np.ndarray, action: np.ndarray
    ) -> StepOutcome:
        return self.outcomes(None, None, q[None], contact_world[None], action[None]).row(0)

    def outcomes(
        self,
        goal: np.ndarray | None,
        bound: np.ndarray | None,
        q: np.ndarray,
        contact_world: np.ndarray,
        action: np.ndarray,
    ) -> BatchOutcome:
        """Per row of the true states q (N, nq) and normalized actions (N, nv) (the goal
        is constant; goal, bound and contact unused)."""
        offset = q[:, :3] - self.target_position_m
        position_error = np.sqrt(np.einsum("ij,ij->i", offset, offset))
        angle_error = rotation_angle_from(self.target_quaternion, q[:, 3:7])
        effort = effort_penalties(action, self.effort_weight)
        return BatchOutcome(
            *_pose_outcome(position_error, angle_error, effort, self.max_position_error_m)
        )


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
        self.task, self.model, self.data = task, model, model.createData()
        self._quaternion = pin.Quaternion(task.rotation_reference).coeffs().copy()
        self.max_position_error_m = _checked_bound(max_position_error_m)
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
        return StepOutcome(
            *_pose_outcome(position_error, angle_error, effort, self.max_position_error_m)
        )
