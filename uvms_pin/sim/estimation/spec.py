"""What an estimator is told: its kind, its prior, the noise it assumes (by default the
navigation sensors' own noise models) and whether the controller reads its estimate."""

from __future__ import annotations

import math
from dataclasses import dataclass

from uvms_pin.errors import ParameterError
from uvms_pin.sim.estimation.eskf import ImuNoise
from uvms_pin.sim.navigation.depth import GRAVITY_M_S2
from uvms_pin.sim.navigation.suite import NavigationSpec

__all__ = ["CONTROLLER_INPUTS", "ESTIMATOR_TYPES", "EstimatorSpec", "MeasurementNoise"]

ESTIMATOR_TYPES = ("eskf",)
#: what a controller is given: the sensors' measurement, or the estimate in its vehicle part
CONTROLLER_INPUTS = ("measurement", "estimate")
#: the least standard deviation a correction assumes (in the measurement's unit): a sensor
#: without noise still leaves the innovation covariance invertible
MEASUREMENT_NOISE_FLOOR = 1e-6


@dataclass(frozen=True)
class MeasurementNoise:
    """Standard deviations the corrections assume: DVL [m/s per axis], depth [m], USBL
    [m per axis]."""

    dvl_m_s: float
    depth_m: float
    usbl_m: float


@dataclass(frozen=True)
class EstimatorSpec:
    """An error-state Kalman filter of the vehicle's navigation state
    (`uvms_pin.sim.estimation.eskf`).

    Attributes:
        kind: "eskf". controller_input: "measurement" or "estimate" (`CONTROLLER_INPUTS`).
        initial_sigma: standard deviations of the prior: position [m], velocity [m/s],
            attitude [rad], gyro bias [rad/s], accelerometer bias [m/s^2].
        draw_initial_error: the initial estimate is the true state plus a draw of that
            prior (seeded), else the true state.
        imu_noise: `ImuNoise` the propagation assumes; None: the IMU's own.
        dvl_noise_m_s, depth_noise_m, usbl_noise_m: what the corrections assume; None: the
            sensors' own (the depth's from its pressure noise, sigma_p / (rho g)).
    """

    kind: str = "eskf"
    controller_input: str = "measurement"
    initial_sigma: tuple[float, float, float, float, float] = (0.1, 0.05, 0.02, 1e-3, 0.01)
    draw_initial_error: bool = True
    imu_noise: ImuNoise | None = None
    dvl_noise_m_s: float | None = None
    depth_noise_m: float | None = None
    usbl_noise_m: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in ESTIMATOR_TYPES:
            raise ParameterError(
                f"estimator type must be one of {ESTIMATOR_TYPES}, got {self.kind!r}"
            )
        if self.controller_input not in CONTROLLER_INPUTS:
            raise ParameterError(
                f"estimator controller_input must be one of {CONTROLLER_INPUTS}, "
                f"got {self.controller_input!r}"
            )
        if len(self.initial_sigma) != 5:
            raise ParameterError(
                "estimator initial_sigma needs 5 values (position, velocity, attitude, gyro "
                f"bias, accelerometer bias), got {self.initial_sigma}"
            )
        numbers = [*self.initial_sigma, self.dvl_noise_m_s, self.depth_noise_m, self.usbl_noise_m]
        if self.imu_noise is not None:
            numbers += list(vars(self.imu_noise).values())
        for value in numbers:
            if value is not None and not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"estimator noise and sigma values must be >= 0, got {value}")
        if any(s == 0.0 for s in self.initial_sigma):
            raise ParameterError(
                f"estimator initial sigmas must be > 0 (a prior of certainty), got {self.initial_sigma}"
            )

    def checked_against(self, navigation: NavigationSpec) -> None:
        """Raise ParameterError when the vehicle has no IMU to propagate with."""
        if navigation.imu is None:
            raise ParameterError(
                "an estimator propagates with the IMU: the vehicle needs [sensors.imu]"
            )

    def imu_noise_of(self, navigation: NavigationSpec) -> ImuNoise:
        if self.imu_noise is not None:
            return self.imu_noise
        imu = navigation.imu
        return ImuNoise(
            imu.gyro_noise_rad_s_rthz,
            imu.gyro_bias_walk_rad_s2_rthz,
            imu.accel_noise_m_s2_rthz,
            imu.accel_bias_walk_m_s3_rthz,
        )

    def measurement_noise_of(self, navigation: NavigationSpec) -> MeasurementNoise:
        def pick(given: float | None, sensors: float) -> float:
            return max(sensors if given is None else given, MEASUREMENT_NOISE_FLOOR)

        dvl = 0.0 if navigation.dvl is None else navigation.dvl.noise_m_s
        usbl = 0.0 if navigation.usbl is None else navigation.usbl.noise_m
        pressure = navigation.depth_noise_Pa or 0.0
        depth = pressure / (navigation.water_density_kg_m3 * GRAVITY_M_S2)
        return MeasurementNoise(
            pick(self.dvl_noise_m_s, dvl),
            pick(self.depth_noise_m, depth),
            pick(self.usbl_noise_m, usbl),
        )
