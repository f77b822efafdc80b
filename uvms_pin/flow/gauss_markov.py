"""A slowly varying, bounded, seeded current: a first-order Gauss-Markov process.

Uniform in space, varying in time (Fossen, Handbook of Marine Craft Hydrodynamics, 8.3):
each world component follows dV/dt = -(V - V_mean) / T + w, sampled exactly on a grid of
period dt,

    V_{k+1} = V_mean + (V_k - V_mean) e^{-dt/T} + sigma sqrt(1 - e^{-2 dt/T}) n_k,

n_k standard normal from ``seed``, V_0 = V_mean, each deviation clipped to +-bound. Between
grid points V(t) is a monotone cubic (Fritsch-Carlson), so the velocity is C1, its
acceleration dV/dt is continuous, and V stays inside the bound. Samples are drawn in
chunks as time advances, so a long run allocates nothing up front and every evaluation
order gives the same field.
"""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.checks import finite_vector, number, seed_value
from uvms_pin.errors import ParameterError
from uvms_pin.flow.base import FlowField, as_points, zero_gradient_kinematics

_CHUNK = 1024


def _positive(value: float, name: str) -> float:
    value = number(name, value)
    if not (value > 0.0 and math.isfinite(value)):
        raise ParameterError(f"{name} must be positive and finite, got {value}")
    return value


def _pchip_slopes(values: np.ndarray, step: float) -> np.ndarray:
    """Fritsch-Carlson slopes (n, 3) of samples (n, 3) on a uniform grid: monotone."""
    secant = np.diff(values, axis=0) / step
    slopes = np.zeros_like(values)
    left, right = secant[:-1], secant[1:]
    same_sign = left * right > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = np.where(same_sign, 2.0 * left * right / (left + right), 0.0)
    slopes[1:-1] = harmonic
    return slopes


class GaussMarkovCurrent(FlowField):
    """A uniform current whose world velocity wanders around its mean (seeded).

    Args:
        mean_velocity_world_m_s: V_mean (3,) [m/s].
        std_m_s: stationary standard deviation sigma of each component [m/s].
        time_constant_s: T, the correlation time [s].
        bound_m_s: largest deviation of each component from the mean [m/s].
        seed: seed of the process.
        sample_period_s: dt of the exact discrete process [s] (interpolated between).
    """

    def __init__(
        self,
        mean_velocity_world_m_s,
        std_m_s: float,
        time_constant_s: float,
        bound_m_s: float,
        seed: int = 0,
        sample_period_s: float = 0.5,
    ):
        self.mean_velocity_world_m_s = finite_vector(
            "mean_velocity_world_m_s", mean_velocity_world_m_s, 3
        )
        self.std_m_s = number("std_m_s", std_m_s)
        if not (self.std_m_s >= 0.0 and math.isfinite(self.std_m_s)):
            raise ParameterError(f"std_m_s must be >= 0, got {std_m_s}")
        self.time_constant_s = _positive(time_constant_s, "time_constant_s")
        self.bound_m_s = _positive(bound_m_s, "bound_m_s")
        self.sample_period_s = _positive(sample_period_s, "sample_period_s")
        self.seed = seed_value("seed", seed)
        self._rng = np.random.default_rng(self.seed)
        self._samples = np.tile(self.mean_velocity_world_m_s, (1, 1))
        self._decay = math.exp(-self.sample_period_s / self.time_constant_s)
        self._kick = self.std_m_s * math.sqrt(1.0 - self._decay**2)

    def _extend_to(self, count: int) -> None:
        while len(self._samples) < count:
            noise = self._rng.standard_normal((_CHUNK, 3))
            out = np.empty((_CHUNK, 3))
            deviation = self._samples[-1] - self.mean_velocity_world_m_s
            for i in range(_CHUNK):
                deviation = np.clip(
                    self._decay * deviation + self._kick * noise[i], -self.bound_m_s, self.bound_m_s
                )
                out[i] = deviation
            self._samples = np.vstack([self._samples, self.mean_velocity_world_m_s + out])

    def _hermite(self, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        if not (time_s >= 0.0 and math.isfinite(time_s)):
            raise ParameterError(f"GaussMarkovCurrent is defined for t >= 0, got {time_s}")
        dt = self.sample_period_s
        i = int(time_s // dt)
        self._extend_to(i + 3)
        window = self._samples[max(i - 1, 0) : i + 3]
        slopes = _pchip_slopes(window, dt)
        j = 1 if i > 0 else 0  # index of sample i inside the window
        if i == 0:
            slopes[0] = 0.0  # the process starts at its mean, at rest
        v0, v1, m0, m1 = window[j], window[j + 1], slopes[j], slopes[j + 1]
        s = time_s / dt - i
        h00, h10, h01, h11 = (
            2 * s**3 - 3 * s**2 + 1,
            s**3 - 2 * s**2 + s,
            -2 * s**3 + 3 * s**2,
            s**3 - s**2,
        )
        d00, d10, d01, d11 = (
            6 * s**2 - 6 * s,
            3 * s**2 - 4 * s + 1,
            -6 * s**2 + 6 * s,
            3 * s**2 - 2 * s,
        )
        velocity = h00 * v0 + h10 * dt * m0 + h01 * v1 + h11 * dt * m1
        acceleration = (d00 * v0 + d10 * dt * m0 + d01 * v1 + d11 * dt * m1) / dt
        return velocity, acceleration

    def velocity(self, time_s, points_world):
        return np.tile(self._hermite(float(time_s))[0], (len(as_points(points_world)), 1))

    def local_acceleration(self, time_s, points_world):
        return np.tile(self._hermite(float(time_s))[1], (len(as_points(points_world)), 1))

    def velocity_gradient(self, time_s, points_world):
        return np.zeros((len(as_points(points_world)), 3, 3))

    # uniform in space: no gradient of du/dt, no curvature
    gradient_kinematics = zero_gradient_kinematics

    def record(self) -> dict:
        """Its parameters and seed: the same realisation is drawn again."""
        return {
            "type": "gauss_markov_current",
            "mean_velocity_world_m_s": self.mean_velocity_world_m_s.tolist(),
            "std_m_s": self.std_m_s,
            "time_constant_s": self.time_constant_s,
            "bound_m_s": self.bound_m_s,
            "seed": self.seed,
            "sample_period_s": self.sample_period_s,
        }

    def __repr__(self) -> str:
        return (
            f"GaussMarkovCurrent(mean={self.mean_velocity_world_m_s.tolist()}, "
            f"std={self.std_m_s}, T={self.time_constant_s}, bound={self.bound_m_s}, seed={self.seed})"
        )
