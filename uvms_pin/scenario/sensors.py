"""``[sensors]``: the bounded noise of each measured channel and the sensors' rate; the
vehicle's navigation sensors in ``[sensors.imu]``, ``[sensors.depth]``, ``[sensors.dvl]``
and ``[sensors.usbl]`` (each fitted when its table is present)."""

from __future__ import annotations

from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.navigation.acoustic import DvlSpec, UsblSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.seabed import world_seabed
from uvms_pin.sim.navigation.suite import NavigationSpec
from uvms_pin.sim.sensors import NoiseSpec, SensorConfig


def build_sensors(
    t: Table, water_density_kg_m3: float = 1025.0, world: World | None = None
) -> SensorConfig:
    """The ``[sensors]`` table's `SensorConfig`; a DVL's bottom is ``world``'s seafloor
    (its upward planes) when it has one, else ``sensors.dvl.seabed_depth_m`` (not both)."""
    distribution = t.string("distribution", "uniform", ("uniform", "gaussian"))

    def spec(key: str) -> NoiseSpec:
        return NoiseSpec(t.number(key, 0.0, nonneg=True), distribution)

    config = SensorConfig(
        force_noise=spec("force_noise_N"),
        torque_noise=spec("torque_noise_Nm"),
        position_noise=spec("position_noise_m"),
        orientation_noise=spec("orientation_noise_rad"),
        joint_noise=spec("joint_noise_rad"),
        velocity_noise=spec("velocity_noise"),
        sample_period_s=t.number("sample_period_s", 1e-3, positive=True),
        navigation=_navigation(t, water_density_kg_m3, world),
    )
    t.finish()
    return config


def _navigation(t: Table, water_density_kg_m3: float, world: World | None) -> NavigationSpec:
    floor = None if world is None else world_seabed(world.objects)
    try:
        imu, depth, dvl, usbl = (
            _imu(t.table("imu")),
            _depth(t.table("depth")),
            _dvl(t.table("dvl"), floor is not None),
            _usbl(t.table("usbl")),
        )
        depth_m = None if dvl is None else dvl[1]
        return NavigationSpec(
            imu,
            depth,
            None if dvl is None else dvl[0],
            usbl,
            depth_m,
            water_density_kg_m3,
            seabed=floor if dvl is not None else None,
        )
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc


def _imu(t: Table | None) -> ImuSpec | None:
    if t is None:
        return None
    out = ImuSpec(
        t.number("gyro_noise_rad_s_rthz", 0.0, nonneg=True),
        t.number("gyro_bias_walk_rad_s2_rthz", 0.0, nonneg=True),
        t.number("accel_noise_m_s2_rthz", 0.0, nonneg=True),
        t.number("accel_bias_walk_m_s3_rthz", 0.0, nonneg=True),
    )
    t.finish()
    return out


def _depth(t: Table | None) -> float | None:
    if t is None:
        return None
    noise = t.number("noise_Pa", 0.0, nonneg=True)
    t.finish()
    return noise


def _dvl(t: Table | None, world_floor: bool) -> tuple[DvlSpec, float | None] | None:
    """(spec, the flat bottom's depth or None when the world has a seafloor)."""
    if t is None:
        return None
    out = DvlSpec(
        t.number("noise_m_s", 0.0, nonneg=True),
        t.number("min_altitude_m", 0.3, nonneg=True),
        t.number("max_altitude_m", 50.0, positive=True),
        t.number("dropout_probability", 0.0, nonneg=True),
    )
    if world_floor and t.has("seabed_depth_m"):
        raise t.error(
            "seabed_depth_m",
            "the world has a seafloor ([[world.objects]] plane): the DVL looks at it; "
            "remove seabed_depth_m (or the plane)",
        )
    if not (world_floor or t.has("seabed_depth_m")):
        raise t.error(
            "seabed_depth_m",
            "is required: a DVL needs a sea bottom (this key, or a [[world.objects]] plane)",
        )
    seabed = None if world_floor else t.number("seabed_depth_m", positive=True)
    t.finish()
    return out, seabed


def _usbl(t: Table | None) -> UsblSpec | None:
    if t is None:
        return None
    out = UsblSpec(
        t.number("noise_m", 0.0, nonneg=True),
        t.number("period_s", 1.0, positive=True),
        t.number("latency_s", 0.0, nonneg=True),
        t.number("dropout_probability", 0.0, nonneg=True),
    )
    t.finish()
    return out
