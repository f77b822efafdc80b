"""The prescribed-arm simulation with its sensitivity to hydrodynamic parameters.

The free vehicle's state x = (q_v, nu_v) moves by M_vv a_v = -h_v - M_va qddot_a
(`uvms_pin.apps.validation.prescribed`). Its sensitivity S = dx/dp (12 x n_p, the
configuration part along the tangent, q_v (+) dq = q_v exp(dq)) obeys the variational
equation

    d(dq)/dt = dnu - ad(nu) dq,          d(dnu)/dt = A_q dq + A_nu dnu + B_p,

with A = da_v/dx at the prescribed arm motion and B_p = da_v/dp. Both come from the exact
derivatives of the forward dynamics (`uvms_pin.forward_dynamics_derivatives`): at
tau = M a + h (the torque that makes the arm follow), ID(q, v, a) = tau gives
dID/dx = -M da/dx, and the vehicle rows, which carry no input, give

    A = M_vv^-1 (M da/dx)_v,        B_p = M_vv^-1 dF_v/dp

(F the fluid's generalized force, `parameters.generalized_force_sensitivity`; for added mass
and the arm's delay, central differences of a_v). S is integrated with the same classical Runge-Kutta stages as
the state (a 4th-order approximation of the exact flow's sensitivity), from S(t0) = 0: the
initial state is measured, not fitted (except where a parameter moves it, e.g. the IMU's
mounting yaw: then the caller gives S(t0)).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg import cho_factor, cho_solve

from uvms_pin.apps.validation.parameters import (
    ARM_DELAY,
    IMU_YAW,
    HydroParameter,
    generalized_force_sensitivity,
    parameter_values,
    with_parameters,
)
from uvms_pin.apps.validation.prescribed import JointTrajectory, free_flyer_model
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces, forward_dynamics_derivatives, mass_matrix
from uvms_pin.sim.integrators import interval_substeps, python_chart

__all__ = ["SensitiveModel", "Trajectory", "roll_pitch_tangent", "simulate_with_sensitivity"]

#: relative central-difference step for the added-mass sensitivities
ADDED_MASS_STEP = 1e-5
#: central-difference step of the arm delay [s] (the arm spline's grid is 0.01 s)
DELAY_STEP_S = 1e-3


@dataclass(frozen=True)
class Trajectory:
    """States at the output times and their sensitivities to the parameters."""

    q_vehicle: np.ndarray  # (n, 7) position [m], quaternion xyzw
    nu_vehicle: np.ndarray  # (n, 6) body twist [m/s; rad/s]
    sensitivity: np.ndarray  # (n, 12, n_p) d(dq_v, dnu_v)/dp, dq_v along the tangent


class SensitiveModel:
    """The system at parameter values ``values`` of ``link``, with the perturbed models the
    added-mass differences need."""

    def __init__(
        self,
        uvms: UVMS,
        parameters: Sequence[HydroParameter],
        link: str,
        values: np.ndarray | None = None,
    ) -> None:
        self.parameters = tuple(parameters)
        self.link = link
        self.values = (
            parameter_values(uvms, parameters, link) if values is None else np.asarray(values)
        )
        self.uvms = with_parameters(uvms, parameters, self.values, link)
        self.differenced = []  # (column, step, uvms at +step, uvms at -step)
        for k, p in enumerate(self.parameters):
            if p.force_linear or not p.hydrodynamic:
                continue
            step = ADDED_MASS_STEP * max(1.0, abs(self.values[k]))
            shifted = [self.values.copy(), self.values.copy()]
            shifted[0][k] += step
            shifted[1][k] -= step
            models = [with_parameters(uvms, parameters, s, link) for s in shifted]
            self.differenced.append((k, step, *models))
        self.force_columns = [k for k, p in enumerate(self.parameters) if p.force_linear]
        self.delay_column = self._column(ARM_DELAY)
        self.arm_delay_s = (
            0.0 if self.delay_column is None else float(self.values[self.delay_column])
        )
        # the IMU's mounting yaw leaves the dynamics alone (its column of B stays 0): it moves
        # the start and the reading (`uvms_pin.apps.validation.imu_mount`)
        self.imu_yaw_column = self._column(IMU_YAW)
        self.imu_yaw_rad = (
            0.0 if self.imu_yaw_column is None else float(self.values[self.imu_yaw_column])
        )

    def _column(self, kind: str) -> int | None:
        found = [k for k, p in enumerate(self.parameters) if p.kind == kind]
        return found[0] if found else None

    def acceleration(self, q: np.ndarray, v: np.ndarray, qdd_arm: np.ndarray, uvms=None):
        """(a_v, M, chol(M_vv)) at the full state (q, v), arm acceleration qdd_arm."""
        uvms = self.uvms if uvms is None else uvms
        mass = mass_matrix(uvms, q)
        h = bias_forces(uvms, q, v)
        factor = cho_factor(mass[:6, :6])
        return cho_solve(factor, -h[:6] - mass[:6, 6:] @ qdd_arm), mass, h, factor

    def jacobians(self, q_v: np.ndarray, nu_v: np.ndarray, arm_at: Callable, t: float):
        """(a_v (6,), A (6, 12) = da_v/d(dq_v, dnu_v), B (6, n_p) = da_v/dp) at time t, the
        arm at ``arm_at(t + arm delay)`` ((q, qdot, qddot))."""
        q_arm, qd_arm, qdd_arm = arm_at(t + self.arm_delay_s)
        q, v = np.concatenate([q_v, q_arm]), np.concatenate([nu_v, qd_arm])
        a_v, mass, h, factor = self.acceleration(q, v, qdd_arm)
        tau = mass @ np.concatenate([a_v, qdd_arm]) + h
        da_dq, da_dv, _ = forward_dynamics_derivatives(self.uvms, q, v, tau)
        state = np.hstack([mass @ da_dq[:, :6], mass @ da_dv[:, :6]])[:6]
        jac_state = cho_solve(factor, state)
        jac_params = np.zeros((6, len(self.parameters)))
        force = generalized_force_sensitivity(self.uvms, q, v, self.parameters, self.link)
        jac_params[:, self.force_columns] = cho_solve(factor, force[:6])
        for k, step, plus, minus in self.differenced:
            a_plus = self.acceleration(q, v, qdd_arm, plus)[0]
            a_minus = self.acceleration(q, v, qdd_arm, minus)[0]
            jac_params[:, k] = (a_plus - a_minus) / (2.0 * step)
        if self.delay_column is not None:
            ends = []
            for shift in (DELAY_STEP_S, -DELAY_STEP_S):
                arm = arm_at(t + self.arm_delay_s + shift)
                q, v = np.concatenate([q_v, arm[0]]), np.concatenate([nu_v, arm[1]])
                ends.append(self.acceleration(q, v, arm[2])[0])
            jac_params[:, self.delay_column] = (ends[0] - ends[1]) / (2.0 * DELAY_STEP_S)
        return a_v, jac_state, jac_params


def _rk4_step(model, chart, rhs, t, q0, v0, s0, h):
    """One RKMK4 step of the state (as `uvms_pin.sim.integrators.RK4`) and RK4 of S."""
    a1, ds1 = rhs(t, q0, v0, s0)
    d1 = v0
    stages = [(a1, d1, ds1)]
    for c in (0.5, 0.5, 1.0):
        a_prev, d_prev, ds_prev = stages[-1]
        delta = c * h * d_prev
        v = v0 + c * h * a_prev
        q, d = chart(q0, delta, v)
        a, ds = rhs(t + c * h, q, v, s0 + c * h * ds_prev)
        stages.append((a, d, ds))
    weights = (1.0, 2.0, 2.0, 1.0)
    delta = (h / 6.0) * sum(w * st[1] for w, st in zip(weights, stages, strict=True))
    v = v0 + (h / 6.0) * sum(w * st[0] for w, st in zip(weights, stages, strict=True))
    s = s0 + (h / 6.0) * sum(w * st[2] for w, st in zip(weights, stages, strict=True))
    return pin.integrate(model, q0, delta), v, s


def simulate_with_sensitivity(
    model: SensitiveModel,
    arm: JointTrajectory,
    q_vehicle0: np.ndarray,
    nu_vehicle0: np.ndarray,
    times_s: np.ndarray,
    step_s: float,
    sensitivity0: np.ndarray | None = None,
) -> Trajectory:
    """`simulate_prescribed_arm` (the same states, the arm at t + the model's arm delay)
    with S = dx/dp at ``times_s``, from S(t0) = ``sensitivity0`` (12, n_p) (default 0)."""
    times_s = np.asarray(times_s, dtype=float)
    start, end = arm.span_s
    if times_s[0] < start - 1e-9 or times_s[-1] > end + 1e-9:
        raise ParameterError(
            f"times [{times_s[0]}, {times_s[-1]}] s leave the arm trajectory's span [{start}, {end}] s"
        )
    flyer = free_flyer_model()
    chart = python_chart(flyer)
    n_p = len(model.parameters)

    def arm_at(t):
        return arm(min(max(t, start), end))

    def rhs(t, q_v, nu_v, s):
        a_v, jac_state, jac_params = model.jacobians(q_v, nu_v, arm_at, t)
        ds = np.empty_like(s)
        ds[:6] = s[6:] - pin.Motion(nu_v).action @ s[:6]
        ds[6:] = jac_state @ s + jac_params
        return a_v, ds

    s = np.zeros((12, n_p)) if sensitivity0 is None else np.array(sensitivity0, dtype=float)
    if s.shape != (12, n_p):
        raise ParameterError(f"sensitivity0 has shape {s.shape}, expected (12, {n_p})")
    q, v = np.asarray(q_vehicle0, float), np.asarray(nu_vehicle0, float)
    qs, vs, ss = [q], [v], [s]
    for t0, t1 in itertools.pairwise(times_s):
        n, h = interval_substeps(float(t0), float(t1), step_s)
        for i in range(n):
            q, v, s = _rk4_step(flyer, chart, rhs, t0 + i * h, q, v, s, h)
        qs.append(q)
        vs.append(v)
        ss.append(s)
    return Trajectory(np.array(qs), np.array(vs), np.array(ss))


def roll_pitch_tangent(roll_pitch_rad: np.ndarray) -> np.ndarray:
    """(n, 2, 6): d(roll, pitch)/d(dq_v) for Z-Y-X angles, R -> R exp([dtheta]x).

    d roll = dtheta_x + sin(roll) tan(pitch) dtheta_y + cos(roll) tan(pitch) dtheta_z,
    d pitch = cos(roll) dtheta_y - sin(roll) dtheta_z (the Euler-rate map of body rates).
    """
    roll, pitch = roll_pitch_rad[:, 0], roll_pitch_rad[:, 1]
    out = np.zeros((len(roll), 2, 6))
    out[:, 0, 3] = 1.0
    out[:, 0, 4] = np.sin(roll) * np.tan(pitch)
    out[:, 0, 5] = np.cos(roll) * np.tan(pitch)
    out[:, 1, 4] = np.cos(roll)
    out[:, 1, 5] = -np.sin(roll)
    return out
