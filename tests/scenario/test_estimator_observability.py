"""An estimator the controller is given, on sensors that cannot observe the state, is warned
at the start, naming what is unobservable and the sensor that would fix it (an IMU alone
drifted 449 m in 60 s while the run reported "ok")."""

from __future__ import annotations

import tomllib
import warnings

import pytest
from conftest import ROOT

from uvms_pin.errors import ObservabilityWarning
from uvms_pin.scenario.load import scenario_from_dict

SHIPPED = ROOT / "scenarios" / "estimator_station_keeping.toml"


def _without(*sensors: str) -> dict:
    doc = tomllib.loads(SHIPPED.read_text())
    for name in sensors:
        del doc["sensors"][name]
    return doc


def test_an_imu_alone_is_warned_with_what_it_cannot_observe():
    with pytest.warns(ObservabilityWarning) as caught:
        scenario_from_dict(_without("usbl", "dvl", "depth"), SHIPPED)
    message = str(caught[0].message)
    assert 'controller_input = "estimate"' in message
    assert "position is unobservable (fit a USBL or a depth sensor)" in message
    assert "velocity is unobservable (fit a DVL)" in message


def test_depth_and_dvl_leave_the_horizontal_position_unobserved():
    with pytest.warns(ObservabilityWarning) as caught:
        scenario_from_dict(_without("usbl"), SHIPPED)
    message = str(caught[0].message)
    assert "horizontal position is unobservable (fit a USBL)" in message
    assert "velocity" not in message


def test_the_shipped_estimator_observes_everything():
    with warnings.catch_warnings():
        warnings.simplefilter("error", ObservabilityWarning)
        scenario_from_dict(tomllib.loads(SHIPPED.read_text()), SHIPPED)
