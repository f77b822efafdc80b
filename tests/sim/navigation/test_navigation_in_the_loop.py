"""Navigation sensors in a run: exact readings without noise, seeded readings with it."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.scenario.load import load_scenario

SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"
BASE = {"scenario.duration_s": 0.2, "output.log_period_s": 0.002}
SILENT = {
    "sensors.imu": {},
    "sensors.depth": {},
    "sensors.dvl": {"seabed_depth_m": 10.0},
    "sensors.usbl": {"period_s": 0.05, "latency_s": 0.02},
}
NOISY = {
    "sensors.imu": {
        "gyro_noise_rad_s_rthz": 1e-3,
        "accel_noise_m_s2_rthz": 1e-2,
        "gyro_bias_walk_rad_s2_rthz": 1e-4,
    },
    "sensors.depth": {"noise_Pa": 50.0},
    "sensors.dvl": {"seabed_depth_m": 10.0, "noise_m_s": 0.01, "dropout_probability": 0.2},
    "sensors.usbl": {"period_s": 0.05, "noise_m": 0.1},
}


def _run(extra, seed=None):
    overrides = {**BASE, **extra}
    if seed is not None:
        overrides["scenario.seed"] = seed
    return up.simulate(load_scenario(SCENARIO, overrides))


@pytest.fixture(scope="module")
def silent():
    return _run(SILENT)


def test_noiseless_readings_are_the_true_state(silent):
    r = silent
    np.testing.assert_allclose(r.signals["imu_gyro"], r.v[:, 3:6], rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.signals["depth"][:, 0], -r.q[:, 2], rtol=1e-12)
    dvl = r.signals["dvl"]
    np.testing.assert_allclose(dvl[:, 3], 10.0 + r.q[:, 2], rtol=1e-12)
    assert np.all(dvl[:, 4] == 1.0)
    np.testing.assert_allclose(dvl[:, :3], r.v[:, :3], atol=1e-15)


def test_the_accelerometer_is_the_specific_force_of_the_mean_acceleration(silent):
    r, dt = silent, 0.002
    rotations = [pin.Quaternion(q[3:7]).toRotationMatrix() for q in r.q]
    v_world = np.array([rot @ v[:3] for rot, v in zip(rotations, r.v, strict=True)])
    for k in range(1, len(r.time_s)):
        a = (v_world[k] - v_world[k - 1]) / dt
        expected = rotations[k].T @ (a - np.array([0.0, 0.0, -9.81]))
        np.testing.assert_allclose(r.signals["imu_accel"][k], expected, rtol=1e-9, atol=1e-9)


def test_usbl_fixes_are_the_position_a_latency_earlier(silent):
    r = silent
    usbl = r.signals["usbl"]
    for k in np.flatnonzero(usbl[:, 4]):
        taken = k - 10  # 0.02 s latency = 10 ticks
        np.testing.assert_allclose(usbl[k, :3], r.q[taken, :3], atol=1e-15)


def test_noise_is_seeded_and_the_table_names_the_columns():
    one, same, other = _run(NOISY, 5), _run(NOISY, 5), _run(NOISY, 6)
    for name in ("imu_gyro", "imu_accel", "depth", "dvl", "usbl"):
        np.testing.assert_array_equal(one.signals[name], same.signals[name])
        assert not np.array_equal(one.signals[name], other.signals[name])
    frame = one.to_dataframe()
    assert frame.attrs["units"]["imu_accel.fz_m_s2"] == "m_s2"
    assert "dvl.lock" in frame.columns and "usbl.age_s" in frame.columns


def test_navigation_sensors_in_a_continuous_loop_are_refused_at_load(tmp_path):
    from uvms_pin.errors import ScenarioError

    with pytest.raises(ScenarioError, match=r"\[control\] period_s"):
        load_scenario(
            ROOT / "scenarios" / "paper_force_tracking.toml", {"sensors.depth": {"noise_Pa": 1.0}}
        )
