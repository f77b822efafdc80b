"""The estimator in a run: its keys, the controller given the estimate, the logged signals."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.control.base import Controller
from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario

SCENARIO = ROOT / "scenarios" / "estimator_station_keeping.toml"
SHORT = {"scenario.duration_s": 3.0}


class Spy(Controller):
    """Zero input; keeps every measurement it is given."""

    def __init__(self, nv: int):
        self.nv, self.seen = nv, []

    def reset(self) -> None:
        self.seen = []

    def compute(self, t, measurement):
        self.seen.append(measurement)
        return np.zeros(self.nv)


def _run(overrides=None, controller=None):
    scenario = load_scenario(SCENARIO, {**SHORT, **(overrides or {})})
    return up.simulate(scenario, controller=controller), scenario


def test_the_controller_is_given_the_estimate_in_the_vehicle_part():
    spy = Spy(6)
    rollout, _ = _run(controller=spy)
    estimate = rollout.signals["estimate"]
    log_every = round(0.05 / 0.01)
    seen = spy.seen[::log_every]
    assert len(seen) == len(rollout)
    q_seen = np.array([m.q for m in seen])
    v_seen = np.array([m.v for m in seen])
    np.testing.assert_array_equal(q_seen[:, :7], estimate[:, :7])
    rotations = [pin.Quaternion(q[3:7]).toRotationMatrix() for q in q_seen]
    v_world = np.array([r @ v[:3] for r, v in zip(rotations, v_seen, strict=True)])
    np.testing.assert_allclose(v_world, estimate[:, 7:10], atol=1e-12)
    # the angular velocity: the gyro less the estimated bias
    np.testing.assert_allclose(
        v_seen[:, 3:6], rollout.signals["imu_gyro"] - estimate[:, 10:13], atol=1e-15
    )
    # and it is not the truth (the estimate started off it)
    assert np.abs(q_seen[:, :3] - rollout.q[:, :3]).max() > 1e-3


def test_with_controller_input_measurement_the_controller_sees_the_sensors():
    spy = Spy(6)
    rollout, _ = _run({"estimator.controller_input": "measurement"}, controller=spy)
    q_seen = np.array([m.q for m in spy.seen[:: round(0.05 / 0.01)]])
    np.testing.assert_array_equal(q_seen, rollout.q)  # no state noise in this scenario
    assert "estimate" in rollout.signals


def test_estimate_signals_carry_names_and_units():
    rollout, _ = _run()
    units = rollout.metadata["signal_units"]
    assert units["estimate"]["components"][:4] == ["x", "y", "z", "qx"]
    assert units["estimate"]["units"][0] == "m" and units["estimate"]["units"][7] == "m/s"
    assert units["estimate_variance"]["units"][:3] == ["m^2"] * 3
    assert units["estimate_variance"]["components"][6] == "attitude_x"
    assert rollout.signals["estimate"].shape == (len(rollout), 16)
    variance = rollout.signals["estimate_variance"]
    assert variance.shape == (len(rollout), 15) and np.all(variance > 0)


def test_a_run_is_determined_by_its_seed():
    a, _ = _run()
    b, _ = _run()
    c, _ = _run({"scenario.seed": 26})
    np.testing.assert_array_equal(a.signals["estimate"], b.signals["estimate"])
    np.testing.assert_array_equal(a.q, b.q)
    assert np.abs(a.signals["estimate"] - c.signals["estimate"]).max() > 1e-6


def test_without_an_imu_the_estimator_is_refused():
    raw_overrides = {**SHORT, "sensors": {"depth": {"noise_Pa": 10.0}}}
    with pytest.raises(ScenarioError, match=r"estimator.*\[sensors.imu\]"):
        load_scenario(SCENARIO, raw_overrides)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("estimator.type", "ukf", "must be one of eskf"),
        ("estimator.controller_input", "truth", "must be one of measurement, estimate"),
        ("estimator.initial_position_sigma_m", 0.0, "must be positive"),
        ("estimator.usbl_noise_m", -1.0, "must be >= 0"),
        ("estimator.initial_position_sigma", 1.0, "initial_position_sigma_m"),
    ],
)
def test_bad_estimator_keys_are_named(key, value, message):
    with pytest.raises(ScenarioError, match=message) as info:
        load_scenario(SCENARIO, {**SHORT, key: value})
    assert key.split(".")[1][:20] in str(info.value)


def test_the_estimators_noise_defaults_to_the_sensors_and_can_be_overridden():
    scenario = load_scenario(SCENARIO, SHORT)
    spec = scenario.sensor_config.estimator
    nav = scenario.sensor_config.navigation
    noise = spec.measurement_noise_of(nav)
    assert noise.usbl_m == 0.1 and noise.dvl_m_s == 0.01
    assert noise.depth_m == pytest.approx(100.0 / (1025.0 * 9.81), rel=1e-12)
    assert spec.imu_noise_of(nav).gyro_noise == 3e-4
    changed = load_scenario(
        SCENARIO, {**SHORT, "estimator.usbl_noise_m": 0.5, "estimator.gyro_noise_rad_s_rthz": 1e-3}
    ).sensor_config.estimator
    assert changed.measurement_noise_of(nav).usbl_m == 0.5
    imu = changed.imu_noise_of(nav)
    assert imu.gyro_noise == 1e-3 and imu.accel_noise == 2e-3  # the rest from the IMU


def test_the_shipped_scenario_holds_its_station_on_the_estimate():
    """The bound of docs/actuators_sensors.md: within 0.15 m of the station (true distance) after the 10 s
    transient, the controller never seeing the truth; the filter consistent meanwhile."""
    rollout = up.simulate(load_scenario(SCENARIO))
    metrics = rollout.metrics()
    assert rollout.metadata["status"] == "ok"
    assert metrics["task_position_error_max_m"] < 0.15
    assert metrics["estimate_within_3_sigma_fraction"] > 0.98
    assert metrics["estimate_position_error_rms_m"] < 0.1


def test_the_ppc_runs_on_the_estimate():
    """The model-free PPC of the realistic force task, its vehicle measured by the filter
    (started at the truth): the force task still holds over its first half second."""
    scenario = ROOT / "scenarios" / "realistic_force_tracking.toml"
    overrides = {
        "scenario.duration_s": 0.5,
        "sensors.imu": {"gyro_noise_rad_s_rthz": 3e-4, "accel_noise_m_s2_rthz": 2e-3},
        "sensors.depth": {"noise_Pa": 100.0},
        "sensors.dvl": {"noise_m_s": 0.01, "seabed_depth_m": 10.0},
        "sensors.usbl": {"noise_m": 0.1, "latency_s": 0.5},
        "estimator": {"controller_input": "estimate", "draw_initial_error": False},
    }
    rollout = up.simulate(load_scenario(scenario, overrides))
    assert rollout.metadata["status"] == "ok"
    estimate = rollout.signals["estimate"]
    assert 0.0 < np.abs(estimate[:, :3] - rollout.q[:, :3]).max() < 0.05
