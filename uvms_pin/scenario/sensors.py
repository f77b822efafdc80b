"""``[sensors]``: the bounded noise of each measured channel and the sensors' rate."""

from __future__ import annotations

from uvms_pin.scenario.schema import Table
from uvms_pin.sim.sensors import NoiseSpec, SensorConfig


def build_sensors(t: Table) -> SensorConfig:
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
    )
    t.finish()
    return config
