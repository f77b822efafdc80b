"""DVL bottom-lock velocity: the velocity over ground in body axes, v_body + n (sigma [m/s]
per axis), when the altitude h above the bottom is within [h_min, h_max] and the ping is not
lost (probability p_drop); otherwise no lock. Reports [vx, vy, vz, h, lock]
(``[sensors.dvl]``; its bottom: `uvms_pin.sim.navigation.seabed`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.seabed import FlatSeabed, Seabed
from uvms_pin.sim.navigation.sensor import SensorKind, check_fields, register

__all__ = ["Dvl", "DvlSpec"]


@dataclass(frozen=True)
class DvlSpec:
    """A DVL's parameters (``[sensors.dvl]``)."""

    #: sigma of the white noise on each velocity component [m/s] (>= 0)
    noise_m_s: float = 0.0
    #: the altitudes it locks on the bottom within [m]
    min_altitude_m: float = 0.3
    max_altitude_m: float = 50.0
    #: the chance a ping is lost, in [0, 1)
    dropout_probability: float = 0.0

    def __post_init__(self) -> None:
        check_fields(
            self, "DVL", positive=("max_altitude_m",), probability=("dropout_probability",)
        )
        if self.min_altitude_m >= self.max_altitude_m:
            raise ParameterError(
                f"DVL min_altitude_m {self.min_altitude_m} >= max_altitude_m {self.max_altitude_m}"
            )


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


def _make(spec: DvlSpec, nav, rngs: list[np.random.Generator]) -> Dvl:
    """Over the flat bottom ``seabed_depth_m`` below the surface, or the world's seafloor."""
    flat = nav.seabed_depth_m is not None
    return Dvl(spec, FlatSeabed(nav.seabed_depth_m) if flat else nav.seabed, rngs[0])


DVL = register(
    SensorKind(
        name="dvl",
        spec=DvlSpec,
        streams=(3,),
        columns={
            "dvl": [("vx", "m_s"), ("vy", "m_s"), ("vz", "m_s"), ("altitude", "m"), ("lock", "")]
        },
        make=_make,
        read=lambda dvl, tick: {"dvl": dvl.measure(tick.position_world_m, tick.velocity_body_m_s)},
    )
)
