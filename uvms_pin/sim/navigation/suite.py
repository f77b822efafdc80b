"""The vehicle's navigation sensors together: sampled at every control tick from the true
state, their readings logged as signals (a column per component, with its unit).

The accelerometer's acceleration is the vehicle origin's mean acceleration over the last
control period, (v_world(t_k) - v_world(t_k-1)) / dt (what a delta-velocity IMU reports);
zero at t = 0. Each sensor draws from its own stream of the run's seed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.acoustic import DepthSensor, Dvl, DvlSpec, Usbl, UsblSpec
from uvms_pin.sim.navigation.imu import Imu, ImuSpec
from uvms_pin.sim.navigation.seabed import FlatSeabed, Seabed

__all__ = ["NAVIGATION_SEED_INDEX", "NavigationSpec", "NavigationSuite"]

#: The child of the run's SeedSequence the navigation sensors draw from (the measurement
#: noise uses children 0-5).
NAVIGATION_SEED_INDEX = 6

_COLUMNS = {
    "imu_gyro": [("wx", "rad_s"), ("wy", "rad_s"), ("wz", "rad_s")],
    "imu_accel": [("fx", "m_s2"), ("fy", "m_s2"), ("fz", "m_s2")],
    "depth": [("sensor", "m")],
    "dvl": [("vx", "m_s"), ("vy", "m_s"), ("vz", "m_s"), ("altitude", "m"), ("lock", "")],
    "usbl": [("x", "m"), ("y", "m"), ("z", "m"), ("age", "s"), ("new", "")],
}


@dataclass(frozen=True)
class NavigationSpec:
    """Which sensors the vehicle has (None: not fitted) and their parameters.

    Attributes:
        imu: `ImuSpec`. depth_noise_Pa: the pressure sensor's noise [Pa] (None: none fitted).
        dvl: `DvlSpec`, over a flat bottom ``seabed_depth_m`` [m] below the surface or over
            ``seabed`` (the world's seafloor, `uvms_pin.sim.navigation.seabed`): one of them.
        usbl: `UsblSpec`.
    """

    imu: ImuSpec | None = None
    depth_noise_Pa: float | None = None
    dvl: DvlSpec | None = None
    usbl: UsblSpec | None = None
    seabed_depth_m: float | None = None
    water_density_kg_m3: float = 1025.0
    seabed: Seabed | None = None

    def __post_init__(self) -> None:
        if self.seabed is not None and self.seabed_depth_m is not None:
            raise ParameterError(
                "the DVL's bottom is given twice: the world's seafloor and seabed_depth_m = "
                f"{self.seabed_depth_m}; give one of them"
            )
        if self.dvl is not None and self.seabed_depth_m is None and self.seabed is None:
            raise ParameterError(
                "a DVL needs a sea bottom: give its depth (seabed_depth_m) or a world "
                'seafloor ([[world.objects]] type = "plane")'
            )

    @property
    def fitted(self) -> bool:
        return any(x is not None for x in (self.imu, self.depth_noise_Pa, self.dvl, self.usbl))


class NavigationSuite:
    """The sensors of a `NavigationSpec`, seeded from ``seed``, in water of ``rho_kg_m3``."""

    def __init__(self, spec: NavigationSpec, seed: int):
        self.spec = spec
        root = np.random.SeedSequence(seed).spawn(NAVIGATION_SEED_INDEX + 1)[NAVIGATION_SEED_INDEX]
        rngs = [np.random.default_rng(child) for child in root.spawn(5)]
        self.imu = None if spec.imu is None else Imu(spec.imu, rngs[0], rngs[1])
        self.depth = (
            None
            if spec.depth_noise_Pa is None
            else DepthSensor(spec.depth_noise_Pa, spec.water_density_kg_m3, rngs[2])
        )
        seabed = spec.seabed
        if spec.seabed_depth_m is not None:
            seabed = FlatSeabed(spec.seabed_depth_m)
        self.dvl = None if spec.dvl is None else Dvl(spec.dvl, seabed, rngs[3])
        self.usbl = None if spec.usbl is None else Usbl(spec.usbl, rngs[4])
        self._velocity_world: np.ndarray | None = None
        self._readings: dict[str, np.ndarray] = {}
        self.period_s = 0.0

    def start(self, period_s: float | None) -> None:
        """A run starts; the sensors sample every control period ``period_s``."""
        if period_s is None:
            raise ParameterError(
                "navigation sensors sample at the control ticks: set [control] period_s"
            )
        self.period_s = period_s
        self._velocity_world = None

    def signal_columns(self) -> dict[str, list[tuple[str, str]]]:
        fitted = {
            "imu_gyro": self.imu,
            "imu_accel": self.imu,
            "depth": self.depth,
            "dvl": self.dvl,
            "usbl": self.usbl,
        }
        return {name: _COLUMNS[name] for name, sensor in fitted.items() if sensor is not None}

    def update(self, time_s: float, q: np.ndarray, v: np.ndarray) -> None:
        """Read every sensor at the tick ``time_s`` from the true (q, v)."""
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        position = q[:3]
        velocity_world = rotation @ v[:3]
        dt = self.period_s
        previous = self._velocity_world
        acceleration = np.zeros(3) if previous is None else (velocity_world - previous) / dt
        self._velocity_world = velocity_world
        readings = {}
        if self.imu is not None:
            readings["imu_gyro"], readings["imu_accel"] = self.imu.measure(
                v[3:6], acceleration, rotation, dt
            )
        if self.depth is not None:
            readings["depth"] = np.array([self.depth.measure(position)])
        if self.dvl is not None:
            readings["dvl"] = self.dvl.measure(position, v[:3])
        if self.usbl is not None:
            readings["usbl"] = self.usbl.measure(time_s, position)
        self._readings = readings

    def signals(self) -> dict[str, np.ndarray]:
        return {name: values.copy() for name, values in self._readings.items()}
