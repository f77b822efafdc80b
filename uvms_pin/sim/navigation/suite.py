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

from uvms_pin.checks import number_fields
from uvms_pin.errors import ParameterError

# the sensor kinds, each registered by its module on import: the one list of them (a new
# kind: its module here and its field in `NavigationSpec`)
from uvms_pin.sim.navigation import depth, dvl, imu, usbl  # noqa: F401
from uvms_pin.sim.navigation.dvl import DvlSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.seabed import Seabed
from uvms_pin.sim.navigation.sensor import SENSORS, SensorKind, Tick, check_nonneg
from uvms_pin.sim.navigation.usbl import UsblSpec

__all__ = ["NAVIGATION_SEED_INDEX", "NavigationSpec", "NavigationSuite"]

#: The child of the run's SeedSequence the navigation sensors draw from (the measurement
#: noise uses children 0-5).
NAVIGATION_SEED_INDEX = 6


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
        number_fields(self)
        check_nonneg(
            "the navigation's water_density_kg_m3", self.water_density_kg_m3, positive=True
        )
        for name in ("depth_noise_Pa", "seabed_depth_m"):
            if getattr(self, name) is not None:
                check_nonneg(name, getattr(self, name))
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
        return any(spec is not None for _, spec in self.sensors())

    def sensors(self) -> list[tuple[SensorKind, object]]:
        """Each registered kind (in the order of their streams) and its spec here (None: not
        fitted)."""
        kinds = sorted(SENSORS.values(), key=lambda kind: kind.streams[0])
        return [(kind, getattr(self, kind.field)) for kind in kinds]


class NavigationSuite:
    """The sensors of a `NavigationSpec`, seeded from ``seed``, in water of ``rho_kg_m3``."""

    def __init__(self, spec: NavigationSpec, seed: int):
        self.spec = spec
        root = np.random.SeedSequence(seed).spawn(NAVIGATION_SEED_INDEX + 1)[NAVIGATION_SEED_INDEX]
        count = 1 + max(k for kind in SENSORS.values() for k in kind.streams)
        rngs = [np.random.default_rng(child) for child in root.spawn(count)]
        #: the fitted sensors: (kind, sensor)
        self.fitted = [
            (kind, kind.make(own, spec, [rngs[k] for k in kind.streams]))
            for kind, own in spec.sensors()
            if own is not None
        ]
        self._by_name = {kind.name: sensor for kind, sensor in self.fitted}
        self._velocity_world: np.ndarray | None = None
        self._readings: dict[str, np.ndarray] = {}
        self.period_s = 0.0

    def __getattr__(self, name: str):
        """A sensor by its kind's name (``suite.imu``), None for a kind not fitted."""
        if name in SENSORS:
            return self.__dict__["_by_name"].get(name)
        raise AttributeError(name)

    def start(self, period_s: float | None) -> None:
        """A run starts; the sensors sample every control period ``period_s``."""
        if period_s is None:
            raise ParameterError(
                "navigation sensors sample at the control ticks: set [control] period_s"
            )
        self.period_s = period_s
        self._velocity_world = None

    def signal_columns(self) -> dict[str, list[tuple[str, str]]]:
        return {name: columns for kind, _ in self.fitted for name, columns in kind.columns.items()}

    def update(self, time_s: float, q: np.ndarray, v: np.ndarray) -> None:
        """Read every sensor at the tick ``time_s`` from the true (q, v)."""
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        velocity_world = rotation @ v[:3]
        dt = self.period_s
        previous = self._velocity_world
        acceleration = np.zeros(3) if previous is None else (velocity_world - previous) / dt
        self._velocity_world = velocity_world
        tick = Tick(time_s, q[:3], rotation, v[:3], v[3:6], acceleration, dt)
        self._readings = {}
        for kind, sensor in self.fitted:
            self._readings.update(kind.read(sensor, tick))

    def signals(self) -> dict[str, np.ndarray]:
        return {name: values.copy() for name, values in self._readings.items()}
