"""The registry of navigation sensors (`uvms_pin.sim.navigation.sensor`): the suite and
the scenario reader run every registered kind without naming one."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.navigation.dvl import DvlSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.sensor import SENSORS, register
from uvms_pin.sim.navigation.suite import NavigationSpec, NavigationSuite
from uvms_pin.sim.navigation.usbl import UsblSpec

SCENARIO = ROOT / "scenarios" / "estimator_station_keeping.toml"


def test_the_four_sensors_are_registered_once_with_distinct_streams():
    assert set(SENSORS) == {"imu", "depth", "dvl", "usbl"}
    streams = [k for kind in SENSORS.values() for k in kind.streams]
    assert len(streams) == len(set(streams))
    with pytest.raises(ParameterError, match="registered already"):
        register(dataclasses.replace(SENSORS["imu"], streams=(9,)))


def test_the_suite_logs_the_columns_of_the_fitted_kinds_only():
    spec = NavigationSpec(imu=ImuSpec(1e-3), usbl=UsblSpec(0.1))
    suite = NavigationSuite(spec, seed=3)
    assert list(suite.signal_columns()) == ["imu_gyro", "imu_accel", "usbl"]
    assert suite.imu is not None and suite.dvl is None
    suite.start(0.1)
    q = np.r_[0.0, 0.0, -5.0, 0.0, 0.0, 0.0, 1.0]
    suite.update(0.0, q, np.zeros(6))
    assert set(suite.signals()) == {"imu_gyro", "imu_accel", "usbl"}


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ({"sensors.usbl.period_s": 0.0}, r"sensors\.usbl.*period_s must be finite and > 0"),
        ({"sensors.imu.gyro_noise": 1.0}, r"sensors\.imu.*unknown key.*gyro_noise"),
        ({"sensors.depth.noise_Pa": -1.0}, r"sensors\.depth.*noise_Pa must be finite"),
    ],
)
def test_the_scenario_reader_checks_each_sensor_in_its_table(override, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario(SCENARIO, override)


def test_each_signal_has_the_columns_its_kind_declares():
    """A kind's ``columns`` name and unit each component of the signal it reads (the run's
    log and DataFrame are laid out by them): as many as the signal's values, every kind."""
    spec = NavigationSpec(
        imu=ImuSpec(1e-3),
        depth_noise_Pa=10.0,
        dvl=DvlSpec(0.01),
        usbl=UsblSpec(0.1),
        seabed_depth_m=20.0,
    )
    suite = NavigationSuite(spec, seed=3)
    suite.start(0.1)
    suite.update(0.0, np.r_[0.0, 0.0, -5.0, 0.0, 0.0, 0.0, 1.0], np.zeros(6))
    signals, columns = suite.signals(), suite.signal_columns()
    assert set(signals) == set(columns) and len(signals) >= 5
    for name, values in signals.items():
        assert np.size(values) == len(columns[name]), name


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"water_density_kg_m3": np.nan}, "water_density_kg_m3"),
        ({"water_density_kg_m3": 0.0}, "water_density_kg_m3"),
        ({"depth_noise_Pa": np.inf}, "depth_noise_Pa"),
        ({"seabed_depth_m": np.nan}, "seabed_depth_m"),
    ],
)
def test_a_navigation_spec_refuses_a_non_finite_water_or_bottom_by_name(changes, match):
    """The water's density (> 0), the pressure sensor's noise and the bottom's depth, when
    given, finite: a nan density was accepted (the depth sensor then read nan)."""
    with pytest.raises(ParameterError, match=match):
        NavigationSpec(**changes)
