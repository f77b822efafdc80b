"""A smooth vehicle trajectory known in closed form, read by the navigation sensors and
filtered by the estimator, with the true biases recorded at every tick."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.sim.estimation.eskf import NavState
from uvms_pin.sim.estimation.estimator import NavigationEstimator
from uvms_pin.sim.estimation.spec import EstimatorSpec
from uvms_pin.sim.navigation.dvl import DvlSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.suite import NavigationSpec, NavigationSuite
from uvms_pin.sim.navigation.usbl import UsblSpec

IMU = ImuSpec(3e-4, 3e-5, 2e-3, 3e-4)
NAVIGATION = NavigationSpec(
    imu=IMU,
    depth_noise_Pa=100.0,
    dvl=DvlSpec(noise_m_s=0.01, dropout_probability=0.1),
    usbl=UsblSpec(noise_m=0.1, period_s=1.0, latency_s=0.5, dropout_probability=0.1),
    seabed_depth_m=30.0,
)


def moving(t: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) of a vehicle weaving and turning at ~10 m depth."""
    phi = np.array([0.2 * np.sin(0.5 * t), 0.15 * np.sin(0.7 * t + 1.0), 0.8 * np.sin(0.3 * t)])
    phi_dot = np.array(
        [0.1 * np.cos(0.5 * t), 0.105 * np.cos(0.7 * t + 1.0), 0.24 * np.cos(0.3 * t)]
    )
    p = np.array(
        [2.0 * np.sin(0.2 * t), 1.5 * (1.0 - np.cos(0.25 * t)), -10.0 + 0.5 * np.sin(0.3 * t)]
    )
    p_dot = np.array([0.4 * np.cos(0.2 * t), 0.375 * np.sin(0.25 * t), 0.15 * np.cos(0.3 * t)])
    rotation = pin.exp3(phi)
    q = np.r_[p, pin.Quaternion(rotation).coeffs()]
    v = np.r_[rotation.T @ p_dot, pin.Jexp3(phi) @ phi_dot]
    return q, v


def still(t: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) of a vehicle at rest, tilted a little, at 5 m depth."""
    rotation = pin.rpy.rpyToMatrix(0.05, -0.03, 0.4)
    return np.r_[1.0, -2.0, -5.0, pin.Quaternion(rotation).coeffs()], np.zeros(6)


@dataclass
class Run:
    time_s: np.ndarray
    errors: np.ndarray  # (n, 15): truth minus estimate, in the filter's error coordinates
    covariances: np.ndarray  # (n, 15, 15)
    estimator: NavigationEstimator


def run(
    seed: int,
    spec: EstimatorSpec,
    navigation: NavigationSpec = NAVIGATION,
    path=moving,
    duration_s: float = 30.0,
    dt_s: float = 0.02,
    initial_biases: tuple[np.ndarray, np.ndarray] | None = None,
) -> Run:
    """The estimator along ``path``, its error to the truth at every tick (the IMU's
    biases starting at ``initial_biases`` (gyro, accelerometer), else zero)."""
    suite = NavigationSuite(navigation, seed)
    suite.start(dt_s)
    if initial_biases is not None:
        suite.imu.gyro.bias, suite.imu.accel.bias = (np.array(b, float) for b in initial_biases)
    estimator = NavigationEstimator(spec, navigation, seed)
    times = np.arange(round(duration_s / dt_s) + 1) * dt_s
    errors, covariances = [], []
    for k, t in enumerate(times):
        q, v = path(t)
        if k == 0:
            estimator.start(dt_s, q, v)
        biases = suite.imu.gyro.bias.copy(), suite.imu.accel.bias.copy()  # sample k's
        suite.update(t, q, v)
        estimator.update(t, suite.signals())
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        truth = NavState(q[:3], rotation @ v[:3], rotation, *biases)
        errors.append(estimator.state.error_to(truth))
        covariances.append(estimator.covariance)
    return Run(times, np.array(errors), np.array(covariances), estimator)


def nees(r: Run, components: slice | np.ndarray = slice(None)) -> np.ndarray:
    """e^T P^-1 e at every tick, over the error components ``components``."""
    e = r.errors[:, components]
    P = r.covariances[:, components][:, :, components]
    return np.einsum("ni,ni->n", e, np.linalg.solve(P, e[..., None])[..., 0])
