"""An IMU at the vehicle's origin, in its body axes: gyroscope and accelerometer, each with
white noise and a bias that walks.

Per axis and sample (period dt), for a rate or specific force x:

    y_k = x_k + b_k + N / sqrt(dt) w_k,      b_k+1 = b_k + K sqrt(dt) u_k,

w, u independent standard normal draws; N the noise density [unit/sqrt(Hz)] (angle or
velocity random walk), K the bias instability's random walk [unit/s/sqrt(Hz)]. Its Allan
deviation is sigma(tau)^2 = N^2 / tau + K^2 tau / 3 (IEEE Std 952). The accelerometer
measures the specific force f = R^T (a - g), a the origin's acceleration in the world and
g = (0, 0, -9.81) m/s^2: at rest it reads +9.81 m/s^2 along the world's up
(``[sensors.imu]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.sensor import SensorKind, Tick, check_fields, register

__all__ = ["GRAVITY_WORLD_M_S2", "Imu", "ImuSpec", "NoisyChannel", "allan_deviation"]

GRAVITY_WORLD_M_S2 = np.array([0.0, 0.0, -9.81])


@dataclass(frozen=True)
class ImuSpec:
    """Noise densities N and bias random walks K of the gyroscope and accelerometer.

    Attributes:
        gyro_noise_rad_s_rthz: N_g [rad/s/sqrt(Hz)]; gyro_bias_walk_rad_s2_rthz: K_g
            [rad/s^2/sqrt(Hz)]; accel_noise_m_s2_rthz: N_a [m/s^2/sqrt(Hz)];
            accel_bias_walk_m_s3_rthz: K_a [m/s^3/sqrt(Hz)]. All >= 0.
    """

    gyro_noise_rad_s_rthz: float = 0.0
    gyro_bias_walk_rad_s2_rthz: float = 0.0
    accel_noise_m_s2_rthz: float = 0.0
    accel_bias_walk_m_s3_rthz: float = 0.0

    def __post_init__(self) -> None:
        check_fields(self, "IMU")


class NoisyChannel:
    """y = x + b + N/sqrt(dt) w, b walking by K sqrt(dt) u per sample (3 axes)."""

    def __init__(self, noise_density: float, bias_walk: float, rng: np.random.Generator):
        self.noise_density, self.bias_walk, self.rng = noise_density, bias_walk, rng
        self.bias = np.zeros(3)

    def sample(self, truth: np.ndarray, dt_s: float) -> np.ndarray:
        draws = self.rng.standard_normal((2, 3))
        out = truth + self.bias + self.noise_density / math.sqrt(dt_s) * draws[0]
        self.bias = self.bias + self.bias_walk * math.sqrt(dt_s) * draws[1]
        return out

    def record(self, truth: np.ndarray, dt_s: float) -> np.ndarray:
        """``sample`` for each row of ``truth`` (n, 3) in turn, in one draw: the same
        numbers as n calls (the generator fills the array in the order of the calls)."""
        draws = self.rng.standard_normal((truth.shape[0], 2, 3))
        steps = self.bias_walk * math.sqrt(dt_s) * draws[:, 1]
        # the bias of sample k is the walk up to k-1
        biases = self.bias + np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)[:-1]])
        self.bias = biases[-1] + steps[-1]
        return truth + biases + self.noise_density / math.sqrt(dt_s) * draws[:, 0]


class Imu:
    """The gyroscope and accelerometer of `ImuSpec`, each with its own seeded stream."""

    def __init__(
        self, spec: ImuSpec, rng_gyro: np.random.Generator, rng_accel: np.random.Generator
    ):
        self.gyro = NoisyChannel(
            spec.gyro_noise_rad_s_rthz, spec.gyro_bias_walk_rad_s2_rthz, rng_gyro
        )
        self.accel = NoisyChannel(
            spec.accel_noise_m_s2_rthz, spec.accel_bias_walk_m_s3_rthz, rng_accel
        )

    def measure(
        self,
        angular_velocity_body: np.ndarray,
        acceleration_world: np.ndarray,
        rotation_world_body: np.ndarray,
        dt_s: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(gyro [rad/s], accelerometer [m/s^2]) in body axes."""
        specific_force = rotation_world_body.T @ (acceleration_world - GRAVITY_WORLD_M_S2)
        return self.gyro.sample(angular_velocity_body, dt_s), self.accel.sample(
            specific_force, dt_s
        )


def allan_deviation(samples: np.ndarray, dt_s: float, tau_s: float) -> float:
    """Overlapping Allan deviation of a rate record (n,) sampled every ``dt_s`` at cluster
    time ``tau_s`` (a multiple of dt): sqrt(<(ybar_k+m - ybar_k)^2> / 2)."""
    m = round(tau_s / dt_s)
    if m < 1 or 2 * m >= samples.size:
        raise ParameterError(
            f"tau = {tau_s} s needs 1 <= tau/dt and 2 tau/dt < {samples.size} samples"
        )
    integral = np.concatenate([[0.0], np.cumsum(samples) * dt_s])
    means = (integral[m:] - integral[:-m]) / (m * dt_s)
    differences = means[m:] - means[:-m]
    return float(np.sqrt(0.5 * np.mean(differences**2)))


def _read(imu: Imu, tick: Tick) -> dict[str, np.ndarray]:
    gyro, accel = imu.measure(
        tick.angular_velocity_body_rad_s,
        tick.acceleration_world_m_s2,
        tick.rotation_world_body,
        tick.period_s,
    )
    return {"imu_gyro": gyro, "imu_accel": accel}


IMU = register(
    SensorKind(
        name="imu",
        spec=ImuSpec,
        streams=(0, 1),
        columns={
            "imu_gyro": [("wx", "rad_s"), ("wy", "rad_s"), ("wz", "rad_s")],
            "imu_accel": [("fx", "m_s2"), ("fy", "m_s2"), ("fz", "m_s2")],
        },
        make=lambda spec, nav, rngs: Imu(spec, rngs[0], rngs[1]),
        read=_read,
    )
)
