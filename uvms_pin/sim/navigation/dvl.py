"""DVL bottom-lock velocity: the velocity over ground in body axes, v_body + n (sigma [m/s]
per axis), when the bottom is within the DVL's altitudes [h_min, h_max] and the ping is not
lost (probability p_drop); otherwise no lock (the velocity reads 0, the flag 0). Reports
[vx, vy, vz, h, lock] (``[sensors.dvl]``; its bottom: `uvms_pin.sim.navigation.seabed`).

Its bottom is found in one of two ways (``beams``):

- 0: the altitude h straight below the vehicle's origin over the seabed (a flat bottom or
  the world's upward planes), locked when h_min <= h <= h_max;
- 4: four beams in a Janus X, at ``beam_angle_rad`` a from the vehicle's down axis, at
  azimuths 45, 135, 225 and 315 degrees, d_j = (sin a cos psi_j, sin a sin psi_j, -cos a)
  in body axes (z up), cast from the vehicle's origin by the perception's ray caster
  (`uvms_pin.perception.caster`) at the bottom and every fixed object of the world. Each
  beam meets its first surface at a range r_j; it holds the bottom when
  h_min <= r_j cos a <= h_max (the altitudes it is rated for, along a tilted beam), and the
  DVL locks only when all four do (an object under a beam, a beam past a drop-off or into
  open water: lock lost). h is the mean height of the beams' hits below the vehicle,
  mean_j(-r_j (R d_j)_z) over the beams that met something (NaN when none did).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.seabed import FlatSeabed, Seabed, bottom_caster
from uvms_pin.sim.navigation.sensor import SensorKind, check_fields, register

__all__ = ["Dvl", "DvlSpec", "janus_beams"]


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
    #: 0: the altitude straight below; 4: four beams cast at the world (the module's doc)
    beams: float = 0.0
    #: the beams' angle from the vehicle's down axis [rad], in (0, pi/2) (30 degrees)
    beam_angle_rad: float = math.pi / 6

    def __post_init__(self) -> None:
        check_fields(
            self, "DVL", positive=("max_altitude_m",), probability=("dropout_probability",)
        )
        if self.min_altitude_m >= self.max_altitude_m:
            raise ParameterError(
                f"DVL min_altitude_m {self.min_altitude_m} >= max_altitude_m {self.max_altitude_m}"
            )
        if self.beams not in (0, 4):
            raise ParameterError(f"DVL beams must be 0 or 4, got {self.beams}")
        if not (0.0 < self.beam_angle_rad < math.pi / 2):
            raise ParameterError(
                f"DVL beam_angle_rad must be in (0, pi/2), got {self.beam_angle_rad}"
            )


def janus_beams(beam_angle_rad: float) -> np.ndarray:
    """The four beams' unit directions (4, 3) in body axes (z up): a Janus X."""
    psi = np.pi / 4 + np.arange(4) * np.pi / 2
    s, c = math.sin(beam_angle_rad), math.cos(beam_angle_rad)
    return np.column_stack([s * np.cos(psi), s * np.sin(psi), np.full(4, -c)])


class Dvl:
    def __init__(self, spec: DvlSpec, seabed: Seabed, rng: np.random.Generator):
        self.spec, self.seabed, self.rng = spec, seabed, rng
        self.caster = bottom_caster(seabed) if spec.beams else None
        self.beams_body = janus_beams(spec.beam_angle_rad)

    def measure(
        self,
        position_world_m: np.ndarray,
        velocity_body_m_s: np.ndarray,
        rotation_world_body: np.ndarray | None = None,
    ) -> np.ndarray:
        """[vx, vy, vz (body, m/s), altitude (m), lock (1 or 0)]; velocity 0 without lock.
        ``rotation_world_body`` (3, 3): the vehicle's attitude (needed when beams are cast;
        None: level)."""
        spec = self.spec
        draws = self.rng.standard_normal(3)
        lost = self.rng.random() < spec.dropout_probability
        if self.caster is None:
            altitude = self.seabed.altitude_m(position_world_m)
            held = spec.min_altitude_m <= altitude <= spec.max_altitude_m
        else:
            rotation = np.eye(3) if rotation_world_body is None else rotation_world_body
            altitude, held = self.cast(position_world_m, rotation)
        lock = held and not lost
        velocity = velocity_body_m_s + spec.noise_m_s * draws if lock else np.zeros(3)
        return np.r_[velocity, altitude, float(lock)]

    def cast(
        self, position_world_m: np.ndarray, rotation_world_body: np.ndarray
    ) -> tuple[float, bool]:
        """(the altitude h [m], whether all four beams hold the bottom) from the beams cast
        at the scene (the module's doc)."""
        spec = self.spec
        directions = self.beams_body @ rotation_world_body.T
        range_m = self.caster.cast(np.asarray(position_world_m, float), directions).range_m
        met = np.isfinite(range_m)
        slant_altitude = range_m * math.cos(spec.beam_angle_rad)
        held = bool(
            np.all(met)
            and np.all(slant_altitude >= spec.min_altitude_m)
            and np.all(slant_altitude <= spec.max_altitude_m)
        )
        below = -range_m[met] * directions[met, 2]
        return (float(below.mean()) if np.any(met) else math.nan), held


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
        read=lambda dvl, tick: {
            "dvl": dvl.measure(
                tick.position_world_m, tick.velocity_body_m_s, tick.rotation_world_body
            )
        },
    )
)
