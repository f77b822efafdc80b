"""``[sensors]``: the bounded noise of each measured channel and the sensors' rate; the
vehicle's navigation sensors in ``[sensors.imu]``, ``[sensors.depth]``, ``[sensors.dvl]``
and ``[sensors.usbl]`` (each fitted when its table is present)."""

from __future__ import annotations

from uvms_pin.errors import ParameterError
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.navigation.acoustic import DvlSpec, UsblSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.suite import NavigationSpec
from uvms_pin.sim.sensors import NoiseSpec, SensorConfig


def build_sensors(t: Table, water_density_kg_m3: float = 1025.0) -> SensorConfig:
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
        navigation=_navigation(t, water_density_kg_m3),
    )
    t.finish()
    return config


def _navigation(t: Table, water_density_kg_m3: float) -> NavigationSpec:
    try:
        imu, depth, dvl, usbl = (
            _imu(t.table("imu")),
            _depth(t.table("depth")),
            _dvl(t.table("dvl")),
            _usbl(t.table("usbl")),
        )
        seabed = None if dvl is None else dvl[1]
        return NavigationSpec(
            imu, depth, None if dvl is None else dvl[0], usbl, seabed, water_density_kg_m3
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


def _dvl(t: Table | None) -> tuple[DvlSpec, float] | None:
    if t is None:
        return None
    out = DvlSpec(
        t.number("noise_m_s", 0.0, nonneg=True),
        t.number("min_altitude_m", 0.3, nonneg=True),
        t.number("max_altitude_m", 50.0, positive=True),
        t.number("dropout_probability", 0.0, nonneg=True),
    )
    seabed = t.number("seabed_depth_m", positive=True)
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
