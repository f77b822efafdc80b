"""A free vehicle under an arm whose joint motion is imposed (prescribed-motion dynamics).

With the arm joints given as functions of time, q_a(t), qdot_a(t), qddot_a(t), only the
vehicle's 6 DoF are free. The rows of M(q) zeta_dot + h(q, zeta) = tau that belong to the
vehicle carry no input (thrusters off), so, partitioning M into vehicle (v) and arm (a)
blocks,

    M_vv(q) a_v = -h_v(q, zeta) - M_va(q) qddot_a(t),     q = [q_v; q_a(t)],
                                                         zeta = [nu_v; qdot_a(t)],

and (q_v, nu_v) is integrated on SE(3) (free-flyer chart, `uvms_pin.sim.integrators.RK4`).
The arm rows would give the joint torques that impose the motion; they are not needed.
M and h come from the public `uvms_pin.mass_matrix` / `uvms_pin.bias_forces`, so the added
mass, buoyancy and damping of every body are those of the full model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.interpolate import CubicSpline
from scipy.linalg import cho_factor, cho_solve
from scipy.signal import butter, sosfiltfilt

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces, mass_matrix
from uvms_pin.sim.integrators import RK4

__all__ = ["JointTrajectory", "free_flyer_model", "low_pass", "simulate_prescribed_arm"]


def low_pass(time_s: np.ndarray, values: np.ndarray, cutoff_hz: float, grid_step_s: float):
    """Resample (linearly) onto a uniform grid and low-pass with zero phase.

    A 2nd-order Butterworth filter run forwards and backwards (``sosfiltfilt``): no delay,
    gain 1/2 (-6 dB) at ``cutoff_hz``.

    Returns:
        (grid_s, filtered): the uniform grid from time_s[0] and the filtered values on it.
    """
    grid = np.arange(time_s[0], time_s[-1] + 0.5 * grid_step_s, grid_step_s)
    grid = grid[grid <= time_s[-1]]
    values = np.asarray(values, dtype=float)
    columns = values.reshape(len(time_s), -1)
    resampled = np.column_stack([np.interp(grid, time_s, c) for c in columns.T])
    nyquist_hz = 0.5 / grid_step_s
    if not 0.0 < cutoff_hz < nyquist_hz:
        raise ParameterError(f"cutoff {cutoff_hz} Hz must be in (0, {nyquist_hz}) Hz")
    sos = butter(2, cutoff_hz / nyquist_hz, output="sos")
    filtered = sosfiltfilt(sos, resampled, axis=0)
    return grid, filtered.reshape((len(grid), *values.shape[1:]))


@dataclass(frozen=True)
class JointTrajectory:
    """Arm joint angles as a C2 cubic spline of time: q, qdot, qddot at any t in its span."""

    spline: CubicSpline

    @classmethod
    def from_samples(
        cls,
        time_s: np.ndarray,
        q_rad: np.ndarray,
        cutoff_hz: float = 2.0,
        grid_step_s: float = 0.01,
    ) -> JointTrajectory:
        """Filter measured angles (`low_pass`) and fit the spline through the filtered grid."""
        grid, filtered = low_pass(time_s, q_rad, cutoff_hz, grid_step_s)
        return cls(CubicSpline(grid, filtered, axis=0))

    @property
    def span_s(self) -> tuple[float, float]:
        return float(self.spline.x[0]), float(self.spline.x[-1])

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q [rad], qdot [rad/s], qddot [rad/s^2]) at time t [s]."""
        return self.spline(t), self.spline(t, 1), self.spline(t, 2)


def free_flyer_model() -> pin.Model:
    """A Pinocchio model with one free-flyer joint: the vehicle's configuration space."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "vehicle")
    return model


def vehicle_acceleration(
    uvms: UVMS, q_vehicle: np.ndarray, nu_vehicle: np.ndarray, arm: tuple[np.ndarray, ...]
) -> np.ndarray:
    """a_v (6,) from M_vv a_v = -h_v - M_va qddot_a, at arm state (q_a, qdot_a, qddot_a)."""
    q_arm, qd_arm, qdd_arm = arm
    q = np.concatenate([q_vehicle, q_arm])
    v = np.concatenate([nu_vehicle, qd_arm])
    mass = mass_matrix(uvms, q)
    h = bias_forces(uvms, q, v)
    rhs = -h[:6] - mass[:6, 6:] @ qdd_arm
    return cho_solve(cho_factor(mass[:6, :6]), rhs)


def simulate_prescribed_arm(
    uvms: UVMS,
    arm: JointTrajectory,
    q_vehicle0: np.ndarray,
    nu_vehicle0: np.ndarray,
    times_s: np.ndarray,
    step_s: float = 0.02,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the free vehicle from times_s[0] with the arm following ``arm``.

    Args:
        q_vehicle0: free-flyer configuration (7,): position [m], quaternion xyzw.
        nu_vehicle0: body velocity (6,): linear [m/s], angular [rad/s].
        times_s: increasing output times [s] inside the trajectory's span.
        step_s: RK4 step [s].

    Returns:
        (q_vehicle (n, 7), nu_vehicle (n, 6)) at times_s.
    """
    times_s = np.asarray(times_s, dtype=float)
    start, end = arm.span_s
    if times_s[0] < start - 1e-9 or times_s[-1] > end + 1e-9:
        raise ParameterError(
            f"times [{times_s[0]}, {times_s[-1]}] s leave the arm trajectory's span [{start}, {end}] s"
        )
    if uvms.n_arm_joints != arm.spline.c.shape[-1]:
        raise ParameterError(
            f"the model has {uvms.n_arm_joints} arm joints, the trajectory {arm.spline.c.shape[-1]}"
        )
    model = free_flyer_model()

    def rhs(t, q_vehicle, nu_vehicle):
        return vehicle_acceleration(uvms, q_vehicle, nu_vehicle, arm(min(max(t, start), end)))

    qs = [np.asarray(q_vehicle0, dtype=float)]
    nus = [np.asarray(nu_vehicle0, dtype=float)]
    states = RK4(step_s).advance_through(model, rhs, times_s[0], qs[0], nus[0], times_s[1:])
    for _, q, nu in states:
        qs.append(q)
        nus.append(nu)
    return np.array(qs), np.array(nus)
