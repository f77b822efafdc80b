"""The error-state Kalman filter of the vehicle's navigation state: its nominal state, the
IMU propagation and the corrections, as pure functions of (state, covariance).

Nominal state x = (p, v, R, b_g, b_a): origin position p and velocity v in the world [m,
m/s], attitude R (world <- body), gyroscope and accelerometer biases [rad/s, m/s^2]. The
error state (15,) is dx = (dp, dv, dtheta, db_g, db_a) with the attitude error on the
manifold, local (body) side: R_true = R Exp(dtheta). Its covariance P is 15 x 15.

Propagation over a control period dt with the gyro readings of the two ticks (w_k-1, w_k)
and the accelerometer's reading f_k of the mean specific force over the period
(`uvms_pin.sim.navigation.suite`), bias-corrected (w = (w_k-1 + w_k)/2 - b_g, f = f_k -
b_a), g = (0, 0, -9.81) m/s^2:

    R+ = R Exp(w dt),   v+ = v + (R+ f + g) dt,   p+ = p + (v + v+) dt / 2,

and dx+ = F dx + noise, to first order (T = Exp(-w dt), [.]x the cross-product matrix):

    dtheta+ = T dtheta - dt db_g
    dv+     = dv - R+ [f]x dt dtheta+ - R+ dt db_a
    dp+     = dp + dt dv + dt/2 (dv+ - dv)

The noise is that of the IMU model (`uvms_pin.sim.navigation.imu`): over a period the
gyro's white noise N_g adds N_g^2 dt to each attitude-error variance, the accelerometer's
N_a adds N_a^2 dt to each velocity variance (and (dt/2) of it to the position), the bias
walks K_g, K_a add K^2 dt to the bias variances.

A correction with a measurement z = h(x) + n, n ~ N(0, R_n), residual r = z - h(x),
Jacobian H = dh/d(dx): K = P H^T (H P H^T + R_n)^-1, dx = K r, P = (I - K H) P (I - K H)^T
+ K R_n K^T (Joseph form: symmetric positive definite whatever the rounding), then dx is
injected into the nominal state and P is moved to the new attitude's tangent space by the
reset Jacobian G = blockdiag(I, I, I - [dtheta/2]x, I, I): P = G P G^T.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.sim.navigation.imu import GRAVITY_WORLD_M_S2

__all__ = [
    "ERROR_STATE_SIZE",
    "ImuNoise",
    "NavState",
    "correct",
    "depth_model",
    "dvl_model",
    "position_model",
    "process_noise",
    "propagate",
    "skew",
    "transition",
]

ERROR_STATE_SIZE = 15
P_, V_, TH, BG, BA = (slice(3 * i, 3 * i + 3) for i in range(5))
_I3 = np.eye(3)
_I15 = np.eye(ERROR_STATE_SIZE)


@dataclass(frozen=True)
class NavState:
    """The filter's nominal state (see the module's docstring)."""

    position_world_m: np.ndarray
    velocity_world_m_s: np.ndarray
    rotation_world_body: np.ndarray
    gyro_bias_rad_s: np.ndarray
    accel_bias_m_s2: np.ndarray

    def injected(self, dx: np.ndarray) -> NavState:
        """The state corrected by the error ``dx`` (15,): R Exp(dtheta), the rest added."""
        return NavState(
            self.position_world_m + dx[P_],
            self.velocity_world_m_s + dx[V_],
            self.rotation_world_body @ pin.exp3(dx[TH]),
            self.gyro_bias_rad_s + dx[BG],
            self.accel_bias_m_s2 + dx[BA],
        )

    def error_to(self, truth: NavState) -> np.ndarray:
        """The error state dx (15,) that takes this estimate to ``truth``."""
        return np.concatenate(
            [
                truth.position_world_m - self.position_world_m,
                truth.velocity_world_m_s - self.velocity_world_m_s,
                pin.log3(self.rotation_world_body.T @ truth.rotation_world_body),
                truth.gyro_bias_rad_s - self.gyro_bias_rad_s,
                truth.accel_bias_m_s2 - self.accel_bias_m_s2,
            ]
        )


@dataclass(frozen=True)
class ImuNoise:
    """The IMU's noise densities and bias walks as the filter models them (`ImuSpec`'s
    units: rad/s/sqrt(Hz), rad/s^2/sqrt(Hz), m/s^2/sqrt(Hz), m/s^3/sqrt(Hz))."""

    gyro_noise: float
    gyro_bias_walk: float
    accel_noise: float
    accel_bias_walk: float


def skew(a: np.ndarray) -> np.ndarray:
    """[a]x, the matrix of a x . (3, 3)."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def transition(
    state: NavState,
    gyro_previous_rad_s: np.ndarray,
    gyro_rad_s: np.ndarray,
    accel_m_s2: np.ndarray,
    dt_s: float,
) -> tuple[NavState, np.ndarray]:
    """(the nominal state one control period on, the error's transition F (15, 15)) with the
    IMU readings of the period's two ticks."""
    w = 0.5 * (gyro_previous_rad_s + gyro_rad_s) - state.gyro_bias_rad_s
    f = accel_m_s2 - state.accel_bias_m_s2
    step = pin.exp3(w * dt_s)
    rotation = state.rotation_world_body @ step
    velocity = state.velocity_world_m_s + (rotation @ f + GRAVITY_WORLD_M_S2) * dt_s
    position = state.position_world_m + 0.5 * (state.velocity_world_m_s + velocity) * dt_s
    new = NavState(position, velocity, rotation, state.gyro_bias_rad_s, state.accel_bias_m_s2)
    F = _I15.copy()
    F[TH, TH] = step.T
    F[TH, BG] = -dt_s * _I3
    rf = -rotation @ skew(f) * dt_s  # d(dv+)/d(dtheta+)
    F[V_, TH] = rf @ F[TH, TH]
    F[V_, BG] = rf @ F[TH, BG]
    F[V_, BA] = -rotation * dt_s
    F[P_, V_] = dt_s * _I3
    F[P_, 6:] = 0.5 * dt_s * F[V_, 6:]  # dt/2 (dv+ - dv): the columns past dv
    return new, F


@functools.lru_cache(maxsize=16)
def process_noise(noise: ImuNoise, dt_s: float) -> np.ndarray:
    """Q (15, 15): what the IMU's noise adds to the error's covariance over ``dt_s``
    (cached: one per period; read-only)."""
    Q = np.zeros((ERROR_STATE_SIZE, ERROR_STATE_SIZE))
    qv = noise.accel_noise**2 * dt_s
    Q[V_, V_] = qv * np.eye(3)
    Q[P_, P_] = 0.25 * dt_s**2 * qv * np.eye(3)
    Q[P_, V_] = Q[V_, P_] = 0.5 * dt_s * qv * np.eye(3)
    Q[TH, TH] = noise.gyro_noise**2 * dt_s * np.eye(3)
    Q[BG, BG] = noise.gyro_bias_walk**2 * dt_s * np.eye(3)
    Q[BA, BA] = noise.accel_bias_walk**2 * dt_s * np.eye(3)
    Q.setflags(write=False)
    return Q


def propagate(
    state: NavState,
    covariance: np.ndarray,
    gyro_previous_rad_s: np.ndarray,
    gyro_rad_s: np.ndarray,
    accel_m_s2: np.ndarray,
    dt_s: float,
    noise: ImuNoise,
) -> tuple[NavState, np.ndarray]:
    """(state, P) one control period on: P+ = F P F^T + Q (`transition`, `process_noise`)."""
    new, F = transition(state, gyro_previous_rad_s, gyro_rad_s, accel_m_s2, dt_s)
    covariance = F @ covariance @ F.T + process_noise(noise, dt_s)
    return new, 0.5 * (covariance + covariance.T)


def correct(
    state: NavState,
    covariance: np.ndarray,
    residual: np.ndarray,
    jacobian: np.ndarray,
    noise_variance: np.ndarray,
) -> tuple[NavState, np.ndarray]:
    """(state, P) corrected by a measurement's ``residual`` (m,) z - h(x), with its
    ``jacobian`` H (m, 15) and noise variances (m,) (Joseph form, then the reset)."""
    PHt = covariance @ jacobian.T
    innovation = jacobian @ PHt
    innovation.flat[:: len(residual) + 1] += noise_variance
    gain = np.linalg.solve(innovation, PHt.T).T  # innovation is symmetric
    dx = gain @ residual
    A = _I15 - gain @ jacobian
    covariance = A @ covariance @ A.T + (gain * noise_variance) @ gain.T
    reset = _I15.copy()
    reset[TH, TH] -= 0.5 * skew(dx[TH])
    covariance = reset @ covariance @ reset.T
    return state.injected(dx), 0.5 * (covariance + covariance.T)


def dvl_model(state: NavState) -> tuple[np.ndarray, np.ndarray]:
    """(h, H) of a DVL: the velocity in body axes, R^T v (= Exp(-dtheta) R^T v to first
    order: H = [0, R^T, [R^T v]x, 0, 0])."""
    rotation = state.rotation_world_body
    velocity_body = rotation.T @ state.velocity_world_m_s
    H = np.zeros((3, ERROR_STATE_SIZE))
    H[:, V_] = rotation.T
    H[:, TH] = skew(velocity_body)
    return velocity_body, H


def depth_model(state: NavState) -> tuple[np.ndarray, np.ndarray]:
    """(h, H) of a depth sensor: -p_z (z up, the surface at 0)."""
    H = np.zeros((1, ERROR_STATE_SIZE))
    H[0, 2] = -1.0
    return np.array([-state.position_world_m[2]]), H


def position_model(state: NavState) -> tuple[np.ndarray, np.ndarray]:
    """(h, H) of a position fix (USBL): p."""
    H = np.zeros((3, ERROR_STATE_SIZE))
    H[:, P_] = np.eye(3)
    return state.position_world_m.copy(), H
