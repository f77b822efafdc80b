"""The force/orientation task the baseline controllers share with the PPC.

Task space (6 components, as the PPC's first level): the force the end-effector exerts on
the environment, f [N, world axes], and the end-effector's Euler angles (roll, pitch, yaw)
[rad]. `EndEffectorTask` evaluates, for one measured configuration q:

- e = [f_meas - f_d(t) (3) N; wrap(rpy_ee - rpy_d(t)) (3) rad] (the PPC's e_x);
- J^lwa (6 x nv): [p_dot (3) m/s; omega (3) rad/s] = J^lwa zeta, world axes;
- zeta_r = J^# xdot_r + (I - J^# J) zeta_0: the task velocity xdot_r = [p_dot (3) m/s;
  Euler rates (3) rad/s] through the same (weighted) minimum-norm pseudo-inverse as the PPC
  (J the analytical Jacobian, W the velocity weights) and its null-space pull of the arm
  toward a target pose, zeta_0,j = -k_0 (q_j - q_0,j) / h_j on the limited arm joints.

Only kinematics (frame placements and Jacobians of a private copy of the model) are used.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.checks import sized_vector
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.ppc_params import PPCParams
from uvms_pin.control.task_space import (
    ForceOrientationTask,
    check_measurement,
    first_level_error,
)
from uvms_pin.errors import ParameterError
from uvms_pin.physics.kinematics import check_euler_singularity, frame_rotation_and_jacobian

__all__ = [
    "EndEffectorTask",
    "ForceOrientationLoop",
    "ForceTaskOptions",
    "TaskState",
    "gain_vector",
]


def gain_vector(name: str, value: ArrayLike, size: int, *, positive: bool = False) -> np.ndarray:
    """A gain as a float array of ``size`` entries (a scalar broadcasts), finite, >= 0 (> 0).

    Raises:
        ParameterError: naming the gain: wrong size, non-finite, negative (or zero).
    """
    array = sized_vector(name, value, size)
    if np.any(~(array > 0.0) if positive else ~(array >= 0.0)):
        raise ParameterError(
            f"{name} must be {'> 0' if positive else '>= 0'}, got {array.tolist()}"
        )
    return array


class TaskState:
    """One evaluation of the task at a measurement (read-only arrays).

    Attributes:
        q, v: the measured configuration and generalized velocity.
        error: e (6,) [N (3); rad (3)]. force_desired_world_N (3,), rpy_desired (3,),
        rpy_ee (3,) [rad]. rotation: world_R_ee (3, 3). jacobian_lwa: J^lwa (6, nv).
    """

    __slots__ = (
        "error",
        "force_desired_world_N",
        "jacobian_lwa",
        "q",
        "rotation",
        "rpy_desired",
        "rpy_ee",
        "v",
    )

    def __init__(self, q, v, error, force_desired, rpy_desired, rpy_ee, rotation, jacobian):
        self.q, self.v, self.error = q, v, error
        self.force_desired_world_N, self.rpy_desired, self.rpy_ee = (
            force_desired,
            rpy_desired,
            rpy_ee,
        )
        self.rotation, self.jacobian_lwa = rotation, jacobian


class EndEffectorTask:
    """Task errors, Jacobian and the pseudo-inverse of the PPC for one end-effector.

    The checks of the measurement, the Euler singularity, J^#, its weights and the
    null-space term are the PPC's own pieces (`uvms_pin.control.task_space`): a baseline
    differs from the PPC only in its feedback law.

    Args:
        model: the UVMS kinematic model (free-flyer root).
        ee_frame_name: the end-effector frame.
        desired_force_world_N, desired_rpy: f_d(t) [N] and rpy_d(t) [rad], constants or
            functions of time.
        velocity_weights: W (nv,) of J^# (1 = Moore-Penrose).
        null_space_gain_per_s: k_0 >= 0 of the arm's null-space pull [rad/s].
        null_space_target: arm pose q_0 (n_joints,) [rad]; None = mid-range.
    """

    def __init__(
        self,
        model: pin.Model,
        ee_frame_name: str,
        desired_force_world_N: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0),
        desired_rpy: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0),
        *,
        velocity_weights: ArrayLike = 1.0,
        null_space_gain_per_s: float = 0.0,
        null_space_target: ArrayLike | None = None,
    ):
        params = PPCParams(
            velocity_weights=velocity_weights,
            null_space_gain_per_s=null_space_gain_per_s,
            null_space_target=null_space_target,
        )
        task = ForceOrientationTask(
            model, ee_frame_name, params, desired_force_world_N, desired_rpy
        )
        self.model, self.data, self.ee_frame_id = task.model, task.data, task.ee_frame_id
        #: the sized parameters of J^# and of the null-space pull (`PPCParams.sized`)
        self.params = task.params
        self.nv = self.model.nv
        self.velocity_names = task.velocity_names
        #: f_d(t) (3,) [N] and rpy_d(t) (3,) [rad], checked functions of time
        self.desired_force, self.desired_rpy = task.desired_force, task.desired_rpy
        #: zeta_r of a task velocity (`ReferenceVelocity`: its J^# weights, solver, pull)
        self.reference = task.reference

    def evaluate(self, time_s: float, measurement: Measurement) -> TaskState:
        """The task at ``measurement``: errors, rotation and J^lwa (checks the input).

        Raises:
            ParameterError: malformed measurement, or the end-effector at the Euler
                singularity (pitch = +-90 deg).
        """
        q, v, wrench = check_measurement(measurement, self.model.nq, self.nv)
        force_desired = self.desired_force(float(time_s))
        rpy_desired = self.desired_rpy(float(time_s))
        rotation, jacobian = frame_rotation_and_jacobian(self.model, self.data, q, self.ee_frame_id)
        rpy_ee = pin.rpy.matrixToRpy(rotation)
        check_euler_singularity(self.model, self.ee_frame_id, rpy_ee)
        error = np.array(first_level_error(wrench, force_desired, rpy_ee, rpy_desired))
        return TaskState(q, v, error, force_desired, rpy_desired, rpy_ee, rotation, jacobian)

    def reference_velocity(self, state: TaskState, xdot_r: np.ndarray) -> np.ndarray:
        """zeta_r (nv,) = J^# xdot_r + (I - J^# J) zeta_0 [m/s, rad/s], the PPC's eq. (9)."""
        return self.reference(state.q, state.rpy_ee, state.jacobian_lwa, [float(x) for x in xdot_r])


class ForceOrientationLoop:
    """The outer loop of the explicit force controllers: PI on force, P on orientation.

        xdot_r = -[kp_f e_f + ki_f I_f (3) m/s;  k_o e_o (3) rad/s Euler rates]
        I_f    = integral of e_f dt [N s], each component clipped to +-integral_limit_Ns

    A force above the desired one (e_f > 0) asks the end-effector to back off, as in the
    PPC. The integral advances by rectangles between increasing call times (exact for a
    sampled controller, ``[control] period_s``; with a continuous-time integrator it follows
    the latest stage time seen).

    Args:
        kp_force_m_s_per_N, ki_force_m_s2_per_N: PI gains (3,) [m/s per N, m/s per N s].
        k_orientation_per_s: orientation gain (3,) [1/s].
        integral_limit_Ns: anti-windup bound of I_f (3,) [N s].
    """

    def __init__(
        self, kp_force_m_s_per_N, ki_force_m_s2_per_N, k_orientation_per_s, integral_limit_Ns
    ):
        self.kp = gain_vector("kp_force_m_s_per_N", kp_force_m_s_per_N, 3)
        self.ki = gain_vector("ki_force_m_s2_per_N", ki_force_m_s2_per_N, 3)
        self.k_o = gain_vector("k_orientation_per_s", k_orientation_per_s, 3)
        self.limit = gain_vector("integral_limit_Ns", integral_limit_Ns, 3)
        self.reset()

    def reset(self) -> None:
        self.integral_Ns = np.zeros(3)
        #: (time [s], e_f (3,) [N]) of the latest call, the next rectangle's; None: no call yet
        self.last_sample: tuple[float, np.ndarray] | None = None

    def velocity(self, time_s: float, error: np.ndarray) -> np.ndarray:
        """xdot_r (6,) [m/s (3); rad/s Euler rates (3)] for the task error e (6,)."""
        last = self.last_sample
        if last is not None and time_s > last[0]:
            step = (time_s - last[0]) * last[1]
            self.integral_Ns = np.clip(self.integral_Ns + step, -self.limit, self.limit)
        if last is None or time_s > last[0]:
            self.last_sample = (time_s, error[:3].copy())
        force_rate = -(self.kp * error[:3] + self.ki * self.integral_Ns)
        return np.r_[force_rate, -self.k_o * error[3:]]


@dataclass(frozen=True)
class ForceTaskOptions:
    """The tuning of the explicit force task the PI force and the computed-torque
    controllers share: the task (`EndEffectorTask`) and its outer loop
    (`ForceOrientationLoop`). The controllers take these as keywords (``**force_task``);
    an unknown keyword is a TypeError here, before anything is built.

    Attributes:
        kp_force_m_s_per_N, ki_force_m_s2_per_N, k_orientation_per_s, integral_limit_Ns:
            the outer loop's gains (3,) [m/s per N, m/s per N s, 1/s, N s], per component
            (a scalar broadcasts).
        desired_force_world_N, desired_rpy, velocity_weights, null_space_gain_per_s, null_space_target:
            the task's, as `EndEffectorTask`.
    """

    kp_force_m_s_per_N: ArrayLike = 0.1
    ki_force_m_s2_per_N: ArrayLike = 0.05
    k_orientation_per_s: ArrayLike = 1.0
    integral_limit_Ns: ArrayLike = 5.0
    desired_force_world_N: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0)
    desired_rpy: Callable[[float], ArrayLike] | ArrayLike = (0.0, 0.0, 0.0)
    velocity_weights: ArrayLike = 1.0
    null_space_gain_per_s: float = 0.0
    null_space_target: ArrayLike | None = None

    def task(self, model: pin.Model, ee_frame_name: str) -> EndEffectorTask:
        """The task on ``model`` for ``ee_frame_name`` (checks the task's options)."""
        return EndEffectorTask(
            model,
            ee_frame_name,
            self.desired_force_world_N,
            self.desired_rpy,
            velocity_weights=self.velocity_weights,
            null_space_gain_per_s=self.null_space_gain_per_s,
            null_space_target=self.null_space_target,
        )

    def loop(self) -> ForceOrientationLoop:
        """The outer loop (checks its gains)."""
        return ForceOrientationLoop(
            self.kp_force_m_s_per_N,
            self.ki_force_m_s2_per_N,
            self.k_orientation_per_s,
            self.integral_limit_Ns,
        )
