"""Depth from pressure: p = p_atm + rho g d + n_p (n_p white, sigma_p [Pa]); the sensor
reports d = (p - p_atm) / (rho g) [m] (``[sensors.depth]``: ``noise_Pa``)."""

from __future__ import annotations

import numpy as np

from uvms_pin.sim.navigation.sensor import SensorKind, Tick, check_nonneg, register

__all__ = ["ATMOSPHERIC_PRESSURE_PA", "GRAVITY_M_S2", "DepthSensor"]

ATMOSPHERIC_PRESSURE_PA = 101_325.0
GRAVITY_M_S2 = 9.81


class DepthSensor:
    """A pressure sensor at the vehicle origin in water of density rho [kg/m^3]."""

    def __init__(self, noise_Pa: float, rho_kg_m3: float, rng: np.random.Generator):
        check_nonneg("depth noise_Pa", noise_Pa)
        self.noise_Pa, self.rho, self.rng = noise_Pa, rho_kg_m3, rng

    def measure(self, position_world_m: np.ndarray) -> float:
        depth = -float(position_world_m[2])
        pressure = (
            ATMOSPHERIC_PRESSURE_PA
            + self.rho * GRAVITY_M_S2 * depth
            + self.noise_Pa * self.rng.standard_normal()
        )
        return (pressure - ATMOSPHERIC_PRESSURE_PA) / (self.rho * GRAVITY_M_S2)


def _noise(noise_Pa: float) -> float:
    check_nonneg("depth noise_Pa", noise_Pa)
    return noise_Pa


def _make(noise_Pa: float, nav, rngs: list[np.random.Generator]) -> DepthSensor:
    """In the suite's water (its density)."""
    return DepthSensor(noise_Pa, nav.water_density_kg_m3, rngs[0])


def _read(sensor: DepthSensor, tick: Tick) -> dict[str, np.ndarray]:
    return {"depth": np.array([sensor.measure(tick.position_world_m)])}


#: its one key: the pressure's noise (its spec is that number, None: not fitted)
DEPTH = register(
    SensorKind("depth", _noise, (2,), {"depth": [("sensor", "m")]}, _make, _read,
               keys=(("noise_Pa", 0.0),), spec_field="depth_noise_Pa")
)  # fmt: skip
