"""The force/orientation task at the end-effector, the pieces the PPC and the baselines share:
the desired signals, the first-level error, the reference velocity through the (weighted)
pseudo-inverse of the analytical Jacobian, and the joint-limit pull in its null space.

Only kinematics of the model (frame placements and Jacobians): what uses these stays
model-free.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.checks import sized_vector
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.ppc_params import N_VEHICLE, PPCParams
from uvms_pin.control.pseudo_inverse import MinimumNormSolver, pseudo_inverse
from uvms_pin.errors import ParameterError
from uvms_pin.physics.kinematics import (
    analytical_jacobian,
    angular_velocity_world_from_euler_rates,
    frame_id_from_name,
)
from uvms_pin.results.components import VEHICLE_VELOCITY_NAMES

_TWO_PI = 2.0 * math.pi
#: Joint position limits at or beyond this magnitude are treated as absent (Pinocchio marks
#: "no limit" with +-max double).
_NO_LIMIT_THRESHOLD = 1e10


def require_free_flyer(model: pin.Model) -> None:
    """ParameterError unless joint 1 of ``model`` is the vehicle's free-flyer."""
    if model.njoints < 2 or model.joints[1].shortname() != "JointModelFreeFlyer":
        raise ParameterError(
            "the UVMS model must have a free-flyer root joint (joint 1); build it with "
            "pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())"
        )


def signal_of_time(value, name: str, size: int) -> Callable[[float], np.ndarray]:
    """A desired signal as a function of time [s]: a callable (its output checked when
    called: ``size`` finite values) or a constant."""
    if callable(value):

        def evaluate(time_s: float) -> np.ndarray:
            out = np.asarray(value(time_s), dtype=float)
            if out.shape == (size,) and math.isfinite(sum(out.tolist())):
                return out  # the exact check below also admits sums beyond 1e308
            if out.shape != (size,) or not np.all(np.isfinite(out)):
                raise ParameterError(
                    f"{name}({time_s}) must return {size} finite values, got {out!r}"
                )
            return out

        return evaluate
    constant = sized_vector(name, value, size)
    return lambda time_s: constant


def check_measurement(
    measurement: Measurement, nq: int, nv: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, v, wrench_world) of ``measurement`` as float arrays of the model's sizes, finite;
    ParameterError naming the bad one otherwise."""
    q = np.asarray(measurement.q, dtype=float)
    v = np.asarray(measurement.v, dtype=float)
    wrench = np.asarray(measurement.wrench_world, dtype=float)
    if (
        q.shape == (nq,)
        and v.shape == (nv,)
        and wrench.shape == (6,)
        # one finiteness test for all three: a sum is NaN or inf if any entry is (Python
        # floats: no overflow warning); the exact check below admits sums beyond 1e308
        and math.isfinite(sum(q.tolist()) + sum(v.tolist()) + sum(wrench.tolist()))
    ):
        return q, v, wrench
    for label, array, size in (("q", q, nq), ("v", v, nv), ("wrench_world", wrench, 6)):
        if array.shape != (size,):
            raise ParameterError(
                f"measurement.{label} must have shape ({size},), got {array.shape}"
            )
        if not np.all(np.isfinite(array)):
            raise ParameterError(f"measurement.{label} has non-finite entries: {array}")
    return q, v, wrench


def first_level_error(
    wrench_world: np.ndarray,
    force_desired: np.ndarray,
    rpy_ee: np.ndarray,
    rpy_desired: np.ndarray,
) -> list[float]:
    """e_x (6 floats) = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) (3) rad].

    e_f = f_e + Delta f_e - f_d; e_o = rpy - rpy_d as in the paper, wrapped to [-pi, pi) so
    that a roll or yaw crossing +-pi (where matrixToRpy jumps by 2 pi) is not read as a huge
    error. Scalar ``math`` on 3 + 3 floats (Python's float % is numpy's mod).
    """
    f, fd = wrench_world.tolist(), force_desired.tolist()
    r, rd = rpy_ee.tolist(), rpy_desired.tolist()
    return [
        f[0] - fd[0],
        f[1] - fd[1],
        f[2] - fd[2],
        (r[0] - rd[0] + math.pi) % _TWO_PI - math.pi,
        (r[1] - rd[1] + math.pi) % _TWO_PI - math.pi,
        (r[2] - rd[2] + math.pi) % _TWO_PI - math.pi,
    ]


def velocity_names(model: pin.Model) -> tuple[str, ...]:
    """The names of the generalized velocities: the vehicle's (u, v, w, p, q, r), the arm's."""
    return VEHICLE_VELOCITY_NAMES + tuple(arm_velocity_names(model))


def arm_velocity_names(model: pin.Model) -> list[str]:
    """The names of the arm's generalized velocities (a multi-DoF joint: ``name[k]``)."""
    names = []
    for joint_id in range(2, model.njoints):
        joint, name = model.joints[joint_id], model.names[joint_id]
        names += [name] if joint.nv == 1 else [f"{name}[{k}]" for k in range(joint.nv)]
    return names


def _as_slice(index: np.ndarray) -> slice | np.ndarray:
    """``index`` as a slice if it is a contiguous increasing range (cheaper to index)."""
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index


class JointLimitPull:
    """The secondary task zeta_0 (nv,): each arm joint with finite position limits pulled
    toward a target (mid-range by default), zero on the vehicle.

    zeta_0 = -k_0 grad H(q) with H(q) = sum_j (q_j - q_0j)^2 / (2 h_j), h_j the half-range
    of arm joint j, so zeta_0_j = -k_0 (q_j - q_0j) / h_j [rad/s]. Projected on the null space
    of J it moves the vehicle and the arm together without moving the end-effector: the
    vehicle slowly takes over what the arm is holding.

    Args:
        model: the UVMS model. gain_per_s: k_0 >= 0 (0: no task).
        target: arm joint positions (n_joints,) [rad]; None = mid-range.
    """

    def __init__(self, model: pin.Model, gain_per_s: float, target: np.ndarray | None):
        q_index, v_index, mid, half_range = [], [], [], []
        for joint_id in range(2, model.njoints):
            joint = model.joints[joint_id]
            if joint.nq != 1 or joint.nv != 1:
                continue  # e.g. continuous joints (cos, sin): no position limits
            lower = float(model.lowerPositionLimit[joint.idx_q])
            upper = float(model.upperPositionLimit[joint.idx_q])
            if max(abs(lower), abs(upper)) >= _NO_LIMIT_THRESHOLD or not upper > lower:
                continue
            q_index.append(joint.idx_q)
            v_index.append(joint.idx_v)
            mid.append(0.5 * (upper + lower))
            half_range.append(0.5 * (upper - lower))
        self.nv = model.nv
        self.limited_q_index = np.array(q_index, int)
        self.limited_v_index = np.array(v_index, int)
        self.half_range = np.array(half_range)
        self.target = np.array(mid) if target is None else target[self.limited_v_index - N_VEHICLE]
        gain = float(gain_per_s)
        # (q - q_0) (-k_0 / h) on the limited joints, indexed by slices when they are
        # contiguous (the usual arm); None when there is no task
        self.scale = -gain / self.half_range if gain > 0.0 and q_index else None
        self._q = _as_slice(self.limited_q_index)
        self._v = _as_slice(self.limited_v_index)

    def velocity(self, q: np.ndarray) -> np.ndarray:
        """zeta_0 (nv,) [m/s, rad/s] at q."""
        zeta_0 = np.zeros(self.nv)
        if self.scale is not None:
            zeta_0[self._v] = (np.asarray(q)[self._q] - self.target) * self.scale
        return zeta_0


class ReferenceVelocity:
    """zeta_r = J^# xdot_r + (I - J^# J) zeta_0 (nv,) [m/s, rad/s]: the task-space reference
    xdot_r (linear [m/s] and Euler rates [rad/s] of the end-effector) in generalized
    velocities, J = diag(I, E^-1) J^lwa the analytical Jacobian, J^# = W^-1 J^T (J W^-1 J^T)^-1.

    With J of full row rank, J^# xdot_r = (J^lwa)^# b with b = [xdot_p; E xdot_o] (E applied
    in closed form, never inverted), and zeta_0 + J^# (xdot_r - J zeta_0) = zeta_0 +
    (J^lwa)^# (b - J^lwa zeta_0), by a Cholesky solve (`MinimumNormSolver`); the exact SVD
    route on J itself when the solver declines.
    """

    def __init__(
        self,
        model: pin.Model,
        data: pin.Data,
        ee_frame_id: int,
        velocity_weights: ArrayLike,
        pinv_relative_cutoff: float,
        pull: JointLimitPull,
    ):
        self.model, self.data, self.ee_frame_id = model, data, ee_frame_id
        weights = np.asarray(velocity_weights, dtype=float)
        self.weights = weights if np.any(weights != 1.0) else None
        self.cutoff = pinv_relative_cutoff
        self.solver = MinimumNormSolver(self.weights, pinv_relative_cutoff)
        self.pull = pull

    def __call__(
        self, q: np.ndarray, rpy_ee: np.ndarray, jacobian_lwa: np.ndarray, xdot_r: list[float]
    ) -> np.ndarray:
        b = np.array([*xdot_r[:3], *angular_velocity_world_from_euler_rates(rpy_ee, xdot_r[3:])])
        zeta_0 = None if self.pull.scale is None else self.pull.velocity(q)
        if zeta_0 is None:
            solution = self.solver.solve(jacobian_lwa, b)
            if solution is not None:
                return solution
        else:
            solution = self.solver.solve(jacobian_lwa, b - np.dot(jacobian_lwa, zeta_0))
            if solution is not None:
                return solution + zeta_0
        jacobian = analytical_jacobian(self.model, self.data, q, self.ee_frame_id)
        jacobian_pinv = pseudo_inverse(jacobian, self.cutoff, self.weights)
        zeta_r = jacobian_pinv @ np.array(xdot_r)
        if zeta_0 is not None:
            zeta_r = zeta_r + zeta_0 - jacobian_pinv @ (jacobian @ zeta_0)
        return zeta_r


class ForceOrientationTask:
    """The force/orientation task of one end-effector: a private copy of the model, the
    frame, the (sized) parameters, the desired signals f_d(t) [N] and rpy_d(t) [rad], the
    names of the generalized velocities, the null-space pull and the reference velocity.

    Args:
        model: the UVMS kinematic model (free-flyer root; copied: later edits do not leak in).
        ee_frame_name: the end-effector frame.
        params: the PPC's parameters (the baselines use its J^# and null-space ones).
        desired_force_world_N, desired_rpy: constants or functions of time; ``desired_rpy``
            None: ``params.desired_rpy``.

    Raises:
        ParameterError: not a free-flyer root, an unknown frame, invalid parameters.
    """

    def __init__(
        self,
        model: pin.Model,
        ee_frame_name: str,
        params: PPCParams,
        desired_force_world_N: Callable[[float], ArrayLike] | ArrayLike,
        desired_rpy: Callable[[float], ArrayLike] | ArrayLike | None,
    ):
        require_free_flyer(model)
        self.model = pin.Model(model)
        self.data = self.model.createData()
        self.ee_frame_id = frame_id_from_name(self.model, ee_frame_name)
        self.velocity_names = velocity_names(self.model)
        self.params = params.sized(self.model.nv, self.velocity_names)
        self.desired_force = signal_of_time(desired_force_world_N, "desired_force_world_N", 3)
        rpy = self.params.desired_rpy if desired_rpy is None else desired_rpy
        self.desired_rpy = signal_of_time(rpy, "desired_rpy", 3)
        p = self.params
        self.pull = JointLimitPull(self.model, p.null_space_gain_per_s, p.null_space_target)
        self.reference = ReferenceVelocity(
            self.model,
            self.data,
            self.ee_frame_id,
            p.velocity_weights,
            p.pinv_relative_cutoff,
            self.pull,
        )
