"""The navigation estimator in the loop: at every control tick it takes the navigation
sensors' readings (`uvms_pin.sim.navigation.suite`), propagates the error-state filter
(`uvms_pin.sim.estimation.eskf`) with the IMU and corrects it with the DVL (when it has
bottom lock), the depth and the USBL fixes; it gives the controller its estimate in place of
the measured vehicle state when asked to, and logs the estimate and its covariance diagonal.

Latency. A USBL fix arrives ``latency`` after the position it measures. The estimator keeps
the ticks of the last ceil(latency / dt) + 2 control periods (their readings and the
filter's state before and after their corrections); a fix is applied at the tick it was
taken (t - age), and the ticks after it are filtered again with their own readings. The
estimate is then the one a filter would have had if the fix had come without delay at its
time of measurement, at the cost of re-running (latency / dt) ticks per fix. A fix older
than the kept ticks is not applied (counted in ``late_fixes``).

Seeding. The initial estimate is the true state at t = 0 with an error drawn from the prior
N(0, P0) (P0 diagonal, the configured sigmas) by the estimator's own stream: child
`ESTIMATOR_SEED_INDEX` of the run's seed.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.control.measurement import Measurement, read_only
from uvms_pin.results.signal import Signal
from uvms_pin.sim.estimation.eskf import (
    ERROR_STATE_SIZE,
    NavState,
    correct,
    depth_model,
    dvl_model,
    position_model,
    propagate,
)
from uvms_pin.sim.estimation.spec import EstimatorSpec
from uvms_pin.sim.navigation.suite import NAVIGATION_SEED_INDEX, NavigationSpec

__all__ = ["ESTIMATE_COLUMNS", "ESTIMATOR_SEED_INDEX", "NavigationEstimator", "true_nav_state"]

#: the child of the run's SeedSequence the estimator's initial error is drawn from
ESTIMATOR_SEED_INDEX = NAVIGATION_SEED_INDEX + 1

#: (component, unit) of the ``estimate`` signal: position and velocity in the world,
#: attitude quaternion (world <- body, x y z w), gyro and accelerometer biases
ESTIMATE_COLUMNS = [
    *[(c, "m") for c in ("x", "y", "z")],
    *[(c, "") for c in ("qx", "qy", "qz", "qw")],
    *[(c, "m/s") for c in ("vx", "vy", "vz")],
    *[(f"gyro_bias_{c}", "rad/s") for c in "xyz"],
    *[(f"accel_bias_{c}", "m/s^2") for c in "xyz"],
]
#: (component, unit) of ``estimate_variance``, the covariance diagonal of the error state
#: (attitude: the body-axes rotation vector of the error)
VARIANCE_COLUMNS = [
    *[(c, "m^2") for c in ("x", "y", "z")],
    *[(c, "m^2/s^2") for c in ("vx", "vy", "vz")],
    *[(f"attitude_{c}", "rad^2") for c in "xyz"],
    *[(f"gyro_bias_{c}", "rad^2/s^2") for c in "xyz"],
    *[(f"accel_bias_{c}", "m^2/s^4") for c in "xyz"],
]


@dataclass
class _Tick:
    """One control tick: its readings and the filter before and after its corrections."""

    time_s: float
    gyro: np.ndarray
    accel: np.ndarray
    dvl: np.ndarray | None  # body velocity with bottom lock, else None
    depth: float | None
    fixes: list[np.ndarray] = field(default_factory=list)  # USBL fixes taken at this tick
    prior: tuple[NavState, np.ndarray] | None = None
    posterior: tuple[NavState, np.ndarray] | None = None


def true_nav_state(q: np.ndarray, v: np.ndarray) -> NavState:
    """The filter's state of the true (q, v), with zero biases."""
    rotation = pin.Quaternion(np.asarray(q[3:7])).normalized().toRotationMatrix()
    return NavState(
        np.array(q[:3], dtype=float), rotation @ v[:3], rotation, np.zeros(3), np.zeros(3)
    )


class NavigationEstimator:
    """The `EstimatorSpec`'s filter on the sensors of ``navigation``, seeded from ``seed``.

    Raises:
        ParameterError: the vehicle has no IMU.
    """

    def __init__(self, spec: EstimatorSpec, navigation: NavigationSpec, seed: int):
        spec.checked_against(navigation)
        self.spec = spec
        self.imu_noise = spec.imu_noise_of(navigation)
        self.noise = spec.measurement_noise_of(navigation)
        self._latency_s = 0.0 if navigation.usbl is None else navigation.usbl.latency_s
        self._seed = seed
        self._history: deque[_Tick] = deque()
        self.late_fixes = 0

    @property
    def feeds_controller(self) -> bool:
        return self.spec.controller_input == "estimate"

    def start(self, period_s: float, q0: np.ndarray, v0: np.ndarray) -> None:
        """A run starts at the true (q0, v0): the prior is drawn around it."""
        child = np.random.SeedSequence(self._seed).spawn(ESTIMATOR_SEED_INDEX + 1)[-1]
        sigma = np.repeat(np.asarray(self.spec.initial_sigma, dtype=float), 3)
        draw = np.random.default_rng(child).standard_normal(ERROR_STATE_SIZE)
        truth = true_nav_state(q0, v0)
        estimate = truth.injected(sigma * draw) if self.spec.draw_initial_error else truth
        self._prior0 = (estimate, np.diag(sigma**2))
        self._history = deque(maxlen=math.ceil(self._latency_s / period_s) + 2)
        self.late_fixes = 0

    def update(self, time_s: float, readings: dict[str, np.ndarray]) -> None:
        """Filter the readings of the tick at ``time_s`` (`NavigationSuite.signals`)."""
        dvl, depth = readings.get("dvl"), readings.get("depth")
        tick = _Tick(
            time_s,
            readings["imu_gyro"],
            readings["imu_accel"],
            dvl[:3] if dvl is not None and dvl[4] == 1.0 else None,
            None if depth is None else float(depth[0]),
        )
        self._settle(self._history[-1] if self._history else None, tick)
        self._history.append(tick)
        usbl = readings.get("usbl")
        if usbl is not None and usbl[4] == 1.0:
            self._fix(time_s - usbl[3], usbl[:3])

    def _settle(self, previous: _Tick | None, tick: _Tick) -> None:
        """The tick's prior (propagated from ``previous``) and its corrected posterior."""
        if previous is None:
            tick.prior = self._prior0
        else:
            dt = tick.time_s - previous.time_s
            tick.prior = propagate(
                *previous.posterior, previous.gyro, tick.gyro, tick.accel, dt, self.imu_noise
            )
        self._correct(tick)

    def _correct(self, tick: _Tick) -> None:
        """The tick's posterior: its prior corrected by its DVL, depth and USBL readings at
        once (independent noises: one stacked update)."""
        state, covariance = tick.prior
        noise = self.noise
        parts = []  # (residual, H, variances)
        if tick.dvl is not None:
            h, H = dvl_model(state)
            parts.append((tick.dvl - h, H, np.full(3, noise.dvl_m_s**2)))
        if tick.depth is not None:
            h, H = depth_model(state)
            parts.append((tick.depth - h, H, np.array([noise.depth_m**2])))
        for fix in tick.fixes:
            h, H = position_model(state)
            parts.append((fix - h, H, np.full(3, noise.usbl_m**2)))
        if parts:
            residual, H, variance = (np.concatenate(x) for x in zip(*parts, strict=True))
            state, covariance = correct(state, covariance, residual, H, variance)
        tick.posterior = (state, covariance)

    def _fix(self, taken_s: float, position_world_m: np.ndarray) -> None:
        """A USBL fix of the position at ``taken_s``: applied at that tick, the later ticks
        filtered again."""
        history = self._history
        half = 0.5 * (history[-1].time_s - history[-2].time_s) if len(history) > 1 else 1e-9
        index = next(
            (
                i
                for i in range(len(history) - 1, -1, -1)
                if abs(history[i].time_s - taken_s) <= half
            ),
            None,
        )
        if index is None:
            self.late_fixes += 1
            return
        history[index].fixes.append(np.array(position_world_m, dtype=float))
        self._correct(history[index])
        for i in range(index + 1, len(history)):
            self._settle(history[i - 1], history[i])

    # ---- what the estimator gives --------------------------------------------------------
    @property
    def state(self) -> NavState:
        return self._history[-1].posterior[0]

    @property
    def covariance(self) -> np.ndarray:
        return self._history[-1].posterior[1]

    def measurement(self, measured: Measurement) -> Measurement:
        """``measured`` with its vehicle part replaced by the estimate: position, attitude
        quaternion, body-axes velocity R^T v and angular velocity (the last gyro reading
        less the estimated bias); the joints and the wrench as measured."""
        state, tick = self.state, self._history[-1]
        q = np.array(measured.q, dtype=float)
        v = np.array(measured.v, dtype=float)
        q[:3] = state.position_world_m
        q[3:7] = pin.Quaternion(state.rotation_world_body).coeffs()
        v[:3] = state.rotation_world_body.T @ state.velocity_world_m_s
        v[3:6] = tick.gyro - state.gyro_bias_rad_s
        return Measurement(
            measured.time_s, read_only(q), read_only(v), measured.wrench_world, measured.images
        )

    def signals(self) -> dict[str, Signal]:
        """``estimate`` and ``estimate_variance`` (`ESTIMATE_COLUMNS`, `VARIANCE_COLUMNS`)."""
        state = self.state
        values = np.concatenate(
            [
                state.position_world_m,
                pin.Quaternion(state.rotation_world_body).coeffs(),
                state.velocity_world_m_s,
                state.gyro_bias_rad_s,
                state.accel_bias_m_s2,
            ]
        )
        return {
            "estimate": Signal(values, *zip(*ESTIMATE_COLUMNS, strict=True)),
            "estimate_variance": Signal(
                np.diag(self.covariance).copy(), *zip(*VARIANCE_COLUMNS, strict=True)
            ),
        }
