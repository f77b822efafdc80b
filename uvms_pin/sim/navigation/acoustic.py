"""Depth from pressure, DVL bottom-lock velocity and USBL position fixes.

- Depth: p = p_atm + rho g d + n_p (n_p white, sigma_p [Pa]); the sensor reports
  d = (p - p_atm) / (rho g) [m].
- DVL: the velocity over ground in body axes, v_body + n (sigma [m/s] per axis), when the
  altitude h above the bottom is within [h_min, h_max] and the ping is not lost (probability
  p_drop); otherwise no lock. Reports [vx, vy, vz, h, lock].
- USBL: a fix of the vehicle position (world, + white noise sigma [m]) every period T; each
  is lost with probability p_drop, and a kept one arrives latency L after it was taken.
  Reports the newest arrived fix [x, y, z, age_s, new] (age: now minus its time of
  measurement; before the first fix every entry is 0 and age is -1).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.seabed import Seabed

__all__ = ["DepthSensor", "Dvl", "DvlSpec", "Usbl", "UsblSpec"]

ATMOSPHERIC_PRESSURE_PA = 101_325.0
GRAVITY_M_S2 = 9.81


def _check(name: str, value: float, *, positive: bool = False) -> None:
    if not math.isfinite(value) or value < 0.0 or (positive and value == 0.0):
        raise ParameterError(
            f"{name} must be finite and {'> 0' if positive else '>= 0'}, got {value}"
        )


def _check_probability(name: str, value: float) -> None:
    if not (0.0 <= value < 1.0):
        raise ParameterError(f"{name} must be in [0, 1), got {value}")


class DepthSensor:
    """A pressure sensor at the vehicle origin in water of density rho [kg/m^3]."""

    def __init__(self, noise_Pa: float, rho_kg_m3: float, rng: np.random.Generator):
        _check("depth noise_Pa", noise_Pa)
        self.noise_Pa, self.rho, self.rng = noise_Pa, rho_kg_m3, rng

    def measure(self, position_world_m: np.ndarray) -> float:
        depth = -float(position_world_m[2])
        pressure = (
            ATMOSPHERIC_PRESSURE_PA
            + self.rho * GRAVITY_M_S2 * depth
            + self.noise_Pa * self.rng.standard_normal()
        )
        return (pressure - ATMOSPHERIC_PRESSURE_PA) / (self.rho * GRAVITY_M_S2)


@dataclass(frozen=True)
class DvlSpec:
    noise_m_s: float = 0.0
    min_altitude_m: float = 0.3
    max_altitude_m: float = 50.0
    dropout_probability: float = 0.0

    def __post_init__(self) -> None:
        _check("DVL noise_m_s", self.noise_m_s)
        _check("DVL min_altitude_m", self.min_altitude_m)
        _check("DVL max_altitude_m", self.max_altitude_m, positive=True)
        if self.min_altitude_m >= self.max_altitude_m:
            raise ParameterError(
                f"DVL min_altitude_m {self.min_altitude_m} >= max_altitude_m {self.max_altitude_m}"
            )
        _check_probability("DVL dropout_probability", self.dropout_probability)


class Dvl:
    def __init__(self, spec: DvlSpec, seabed: Seabed, rng: np.random.Generator):
        self.spec, self.seabed, self.rng = spec, seabed, rng

    def measure(self, position_world_m: np.ndarray, velocity_body_m_s: np.ndarray) -> np.ndarray:
        """[vx, vy, vz (body, m/s), altitude (m), lock (1 or 0)]; velocity 0 without lock."""
        spec = self.spec
        draws = self.rng.standard_normal(3)
        lost = self.rng.random() < spec.dropout_probability
        altitude = self.seabed.altitude_m(position_world_m)
        lock = (spec.min_altitude_m <= altitude <= spec.max_altitude_m) and not lost
        velocity = velocity_body_m_s + spec.noise_m_s * draws if lock else np.zeros(3)
        return np.r_[velocity, altitude, float(lock)]


@dataclass(frozen=True)
class UsblSpec:
    noise_m: float = 0.0
    period_s: float = 1.0
    latency_s: float = 0.0
    dropout_probability: float = 0.0

    def __post_init__(self) -> None:
        _check("USBL noise_m", self.noise_m)
        _check("USBL period_s", self.period_s, positive=True)
        _check("USBL latency_s", self.latency_s)
        _check_probability("USBL dropout_probability", self.dropout_probability)


class Usbl:
    def __init__(self, spec: UsblSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self._next_ping_s = 0.0
        self._in_flight: deque[tuple[float, np.ndarray]] = deque()  # (time taken, fix)
        self._latest: tuple[float, np.ndarray] | None = None

    def measure(self, time_s: float, position_world_m: np.ndarray) -> np.ndarray:
        """[x, y, z (world, m), age_s, new (1 on the tick a fix arrives)]."""
        spec = self.spec
        # a ping at or before now is taken now (the ticks are the sensor's clock)
        if time_s + 1e-12 >= self._next_ping_s:
            draws = self.rng.standard_normal(3)
            lost = self.rng.random() < spec.dropout_probability
            if not lost:
                self._in_flight.append((time_s, position_world_m + spec.noise_m * draws))
            self._next_ping_s += spec.period_s * max(
                1, math.floor((time_s - self._next_ping_s) / spec.period_s) + 1
            )
        new = 0.0
        while self._in_flight and self._in_flight[0][0] + spec.latency_s <= time_s + 1e-12:
            self._latest = self._in_flight.popleft()
            new = 1.0
        if self._latest is None:
            return np.array([0.0, 0.0, 0.0, -1.0, 0.0])
        taken, fix = self._latest
        return np.r_[fix, time_s - taken, new]
