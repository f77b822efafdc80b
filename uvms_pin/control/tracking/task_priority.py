"""The task-priority kinematic level: prioritized tasks -> a generalized velocity reference.

Tasks, highest priority first (Antonelli's null-space-based behavioural control; the
set-based activation of Simetti and Casalino for the inequality tasks):

1. joint limits (set-based): each joint's rate must stay within
   k_l (q_lo + m - q_j) <= q_dot_j <= k_l (q_hi - m - q_j), m = ``joint_limit_margin_rad``
   (a joint slows down as it nears the band of width m inside a limit, and is driven back
   out of it); a joint whose rate the other tasks would take past a bound gets the row
   q_dot_j = that bound, and the tasks are solved again (the active set grows until no
   rate is out of bounds); a joint within its bounds has no row;
2. the tracking task (`uvms_pin.control.tracking.task.TrackingTask`), 6 rows:
   x_dot_r = [p_dot_r + K_p (p_r - p); K_o e_o], e_o = log3(R_r R^T) [m/s; rad/s];
3. vehicle roll and pitch (an end-effector task only): the body angular rates
   w_x, w_y = k_a e_a, e_a the first two components of log3(R_v^T R_level), R_level the
   vehicle's yaw alone (the attitude a vehicle floats at);
4. manipulability (set-based: active while w(q) = sqrt(det(J_a J_a^T)) < w_min): the arm
   climbs k_m grad w [rad/s] (grad by central differences) in the null space of every task
   above (gradient projection, zeta += W^-1/2 N_K W^1/2 [0; k_m grad w]), J_a the arm's
   columns of the end-effector Jacobian.

Each task k with Jacobian J_k and desired rate x_k is solved in the null space of the
ones above (in the metric W of ``velocity_weights``, zeta = W^-1/2 u):

    u_k = u_{k-1} + (J_k N_{k-1})^+ (x_k - J_k u_{k-1}),  N_k = N_{k-1} - (J_k N_{k-1})^+ J_k N_{k-1}

with the damped inverse A^+ = A^T (A A^T + lambda^2 I)^-1 (lambda = ``damping``; the
directions the tasks above took away, singular values at rounding level, left out), so
that a lower task losing rank against the ones above does not ask for unbounded rates. The result
is zeta_r = W^-1/2 u_K (nv,) [m/s, rad/s body; joint rates], the reference a dynamic level
follows (`uvms_pin.control.tracking.dynamic_level`).

Velocities no actuator can drive (``passive_velocities``: an LBV150's roll and pitch rates,
left to its metacentric restoring moment) are not unknowns of the recursion: their
measured values zeta_P move the tasks, x_k - J_k,P zeta_P is what the others must give, and
zeta_r,P = zeta_P (the dynamic level has nothing to correct there). A task whose rows only
such velocities can move (the attitude task of such a vehicle) then asks nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector, nonnegative, positive
from uvms_pin.control.tracking.task import TrackingTask, orientation_error, vehicle_rotation
from uvms_pin.errors import ParameterError

__all__ = ["KinematicGains", "KinematicLevel", "prioritized_velocity"]


@dataclass(frozen=True)
class KinematicGains:
    """The kinematic level's gains (defaults: the LBV150 and Alpha 5 tracking scenarios).

    Attributes:
        position_gain_per_s: K_p [1/s]. orientation_gain_per_s: K_o [1/s].
        attitude_gain_per_s: k_a, vehicle roll/pitch [1/s] (0: no attitude task).
        joint_limit_margin_rad: the band inside each limit where the limit task acts [rad].
        joint_limit_gain_per_s: k_l [1/s].
        manipulability_threshold: w_min (0: no manipulability task).
        manipulability_gain: k_m [rad/s per unit of w].
        velocity_weights: W's diagonal (nv,) (a larger weight: that velocity is used less);
            None: all ones.
        damping: lambda of the damped inverse.
        passive_velocities: indices of the velocities no actuator drives (0-5: the
            vehicle's body velocities u, v, w, p, q, r).
    """

    position_gain_per_s: float = 1.0
    orientation_gain_per_s: float = 1.0
    attitude_gain_per_s: float = 1.0
    joint_limit_margin_rad: float = 0.1
    joint_limit_gain_per_s: float = 2.0
    manipulability_threshold: float = 0.0
    manipulability_gain: float = 1.0
    velocity_weights: np.ndarray | None = field(default=None)
    damping: float = 1e-3
    passive_velocities: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        for name in ("position_gain_per_s", "orientation_gain_per_s", "joint_limit_margin_rad",
                     "joint_limit_gain_per_s", "damping"):  # fmt: skip
            positive(name, getattr(self, name))
        for name in ("attitude_gain_per_s", "manipulability_threshold", "manipulability_gain"):
            nonnegative(name, getattr(self, name))


#: Singular values below this fraction of the largest are rounding (a direction the tasks
#: above took away): they are dropped, not damped.
RANK_CUTOFF = 1e-9


def _damped_inverse_and_rows(matrix: np.ndarray, damping: float) -> tuple[np.ndarray, np.ndarray]:
    """(A^T (A A^T + lambda^2 I)^-1, an orthonormal basis of A's row space (rows)) through
    the SVD: V diag(s / (s^2 + lambda^2)) U^T, the directions A has lost (s <=
    `RANK_CUTOFF` s_max) left out exactly."""
    u, s, vt = np.linalg.svd(matrix, full_matrices=False)
    if s.size == 0 or s[0] == 0.0:
        return np.zeros(matrix.shape[::-1]), np.zeros((0, matrix.shape[1]))
    keep = s > RANK_CUTOFF * s[0]
    inverse = (vt[keep].T * (s[keep] / (s[keep] ** 2 + damping * damping))) @ u[:, keep].T
    return inverse, vt[keep]


def prioritized_velocity(
    tasks: list[tuple[np.ndarray, np.ndarray]],
    weights: np.ndarray,
    damping: float,
    secondary: np.ndarray | None = None,
) -> np.ndarray:
    """zeta solving ``tasks`` [(J_k (m_k, n), x_k (m_k,)), ...] in priority order (the
    recursion of the module docstring, in the metric W = diag(weights)), plus the velocity
    ``secondary`` (n,) projected into the null space of them all (gradient projection:
    u += N_K W^1/2 secondary), if given.

    The null-space projector is updated with the exact projector on each task's row space,
    N_k = N_{k-1} - V_k V_k^T (V_k: the right singular vectors of J_k N_{k-1} kept), not
    with the damped inverse: a damped N would leave a small part of an upper task's
    directions free, which a lower task, inverting that small part, would use at full size.
    """
    scale = 1.0 / np.sqrt(weights)
    n = scale.size
    u, null = np.zeros(n), np.eye(n)
    for jacobian, rate in tasks:
        if jacobian.shape[0] == 0:
            continue
        scaled = jacobian * scale
        inverse, rows = _damped_inverse_and_rows(scaled @ null, damping)
        u = u + inverse @ (rate - scaled @ u)
        null = null - rows.T @ rows
    if secondary is not None:
        u = u + null @ (secondary / scale)
    return scale * u


class KinematicLevel:
    """zeta_r(t, q) for a tracking task on a model (kinematics only: frame placements and
    Jacobians).

    Args:
        model: the UVMS's Pinocchio model (a private Data is made). task: what to track.
        gains: `KinematicGains`.
    """

    def __init__(self, model: pin.Model, task: TrackingTask, gains: KinematicGains):
        self.model, self.data, self.task, self.gains = model, model.createData(), task, gains
        nv = model.nv
        weights = gains.velocity_weights
        self.weights = (
            np.ones(nv) if weights is None else finite_vector("velocity_weights", weights, nv)
        )
        if np.any(self.weights <= 0):
            raise ParameterError(f"velocity_weights must be positive, got {self.weights}")
        # the joints with limits (one configuration entry: revolute, prismatic); a
        # continuous joint (cos, sin) has none: (its q index, its v index)
        bounded = [(j.idx_q, j.idx_v) for j in list(model.joints)[2:] if j.nq == 1]
        self.bounded_q = np.array([i for i, _ in bounded], dtype=int)
        self.bounded_v = np.array([i for _, i in bounded], dtype=int)
        self.lower = np.asarray(model.lowerPositionLimit[self.bounded_q], dtype=float)
        self.upper = np.asarray(model.upperPositionLimit[self.bounded_q], dtype=float)
        passive = sorted(set(int(k) for k in gains.passive_velocities))
        if any(not 0 <= k < 6 for k in passive):
            raise ParameterError(f"passive_velocities must be in 0..5, got {passive}")
        self.passive = np.array(passive, dtype=int)
        self.active = np.setdiff1d(np.arange(nv), self.passive)
        self.task.frame_id(model)  # the frame exists
        self._ee_id = -1 if task.target == "vehicle" else task.frame_id(model)

    def _solve(self, tasks: list, v: np.ndarray, secondary: np.ndarray | None) -> np.ndarray:
        """The recursion over the driven velocities, the passive ones at their measured v."""
        damping = self.gains.damping
        if self.passive.size == 0:
            return prioritized_velocity(tasks, self.weights, damping, secondary)
        active, passive = self.active, self.passive
        moved = [(j[:, active], x - j[:, passive] @ v[passive]) for j, x in tasks]
        zeta_r = np.array(v, dtype=float)
        zeta_r[active] = prioritized_velocity(
            moved, self.weights[active], damping, None if secondary is None else secondary[active]
        )
        return zeta_r

    def reference(
        self, time_s: float, q: np.ndarray, v: np.ndarray
    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """(zeta_r (nv,) at the measured (q, v), the task's errors: ``position_error`` [m], ``orientation_error``
        [rad], ``active_limits`` (one 0/1 per arm joint with limits, in order))."""
        task, gains = self.task, self.gains
        position, rotation, jacobian = task.pose_and_jacobian(self.model, self.data, q)
        p_r, v_r, _ = task.path.at(time_s)
        e_p = p_r - position
        e_o = orientation_error(task.rotation_reference, rotation)
        rate = np.concatenate(
            [v_r + gains.position_gain_per_s * e_p, gains.orientation_gain_per_s * e_o]
        )
        tasks = [(jacobian[task.rows], rate[task.rows])]
        if task.target == "end_effector" and gains.attitude_gain_per_s > 0:
            tasks.append(self._attitude_task(q))
        secondary = None
        if task.target == "end_effector" and gains.manipulability_threshold > 0:
            secondary = self._manipulability_velocity(q)
        zeta_r, active = self._solve_within_limits(tasks, q, v, secondary)
        return zeta_r, {"position_error": e_p, "orientation_error": e_o, "active_limits": active}

    def _solve_within_limits(
        self, tasks: list, q: np.ndarray, v: np.ndarray, secondary: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """zeta_r with every joint rate inside its bounds (module docstring, task 1), and
        which joints' bound is a task (1.0) or not (0.0)."""
        margin, gain = self.gains.joint_limit_margin_rad, self.gains.joint_limit_gain_per_s
        joints = q[self.bounded_q]
        lowest = gain * (self.lower + margin - joints)  # q_dot_j >= this
        highest = gain * (self.upper - margin - joints)  # q_dot_j <= this
        bound = np.zeros(joints.size)  # the rate a bounded joint is held at
        held = np.zeros(joints.size, dtype=bool)
        for _ in range(joints.size + 1):
            rows = np.flatnonzero(held)
            limit_jacobian = np.zeros((rows.size, self.model.nv))
            limit_jacobian[np.arange(rows.size), self.bounded_v[rows]] = 1.0
            zeta_r = self._solve([(limit_jacobian, bound[rows]), *tasks], v, secondary)
            rates = zeta_r[self.bounded_v]
            over = ~held & ((rates > highest + 1e-12) | (rates < lowest - 1e-12))
            if not over.any():
                return zeta_r, held.astype(float)
            bound = np.where(over, np.clip(rates, lowest, highest), bound)
            held |= over
        return zeta_r, held.astype(float)

    def _attitude_task(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rotation = vehicle_rotation(q)
        yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        level = pin.utils.rpyToMatrix(0.0, 0.0, yaw)
        error = np.asarray(pin.log3(rotation.T @ level))[:2]  # body axes
        jacobian = np.zeros((2, self.model.nv))
        jacobian[0, 3] = jacobian[1, 4] = 1.0
        return jacobian, self.gains.attitude_gain_per_s * error

    def manipulability(self, q: np.ndarray) -> float:
        """w(q) = sqrt(det(J_a J_a^T)), J_a the arm's columns of the frame Jacobian."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        jac = pin.getFrameJacobian(self.model, self.data, self._ee_id, pin.LOCAL_WORLD_ALIGNED)
        arm = jac[:, 6:]
        rows = min(arm.shape)
        gram = arm @ arm.T if arm.shape[0] <= arm.shape[1] else arm.T @ arm
        return math.sqrt(max(np.linalg.det(gram), 0.0)) if rows else 0.0

    def _manipulability_velocity(self, q: np.ndarray) -> np.ndarray | None:
        """[0 (6); k_m grad w] while w(q) < w_min (grad by central differences), else None."""
        if self.manipulability(q) >= self.gains.manipulability_threshold:
            return None
        nv, step = self.model.nv, 1e-6
        gradient = np.zeros(nv - 6)
        for j in range(nv - 6):  # along each joint's velocity (continuous joints too)
            direction = np.zeros(nv)
            direction[6 + j] = step
            plus = pin.integrate(self.model, q, direction)
            minus = pin.integrate(self.model, q, -direction)
            gradient[j] = (self.manipulability(plus) - self.manipulability(minus)) / (2 * step)
        return np.concatenate([np.zeros(6), self.gains.manipulability_gain * gradient])
