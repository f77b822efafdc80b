"""Thruster drives in a closed-loop run: logged per thruster, and what the plant gets."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.model.vehicles.t200 import t200_16v_curve
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.thruster_drive import first_order_step

SCENARIO = "scenarios/realistic_force_tracking.toml"
THRUSTERS = [
    {
        "name": "lagged",
        "position_body_m": [-0.29, 0.09, -0.03],
        "direction_body": [1.0, 0.0, 0.0],
        "curve": "quadratic",
        "max_forward_N": 21.6,
        "max_reverse_N": 15.0,
        "deadband": 0.05,
        "time_constant_s": 0.05,
        "rate_limit_N_s": 200.0,
    },
    {
        "name": "t200",
        "position_body_m": [-0.29, -0.09, -0.03],
        "direction_body": [1.0, 0.0, 0.0],
        "curve": "t200_16v",
    },
    {
        "name": "lateral",
        "position_body_m": [0.03, 0.0, -0.03],
        "direction_body": [0.0, 1.0, 0.0],
        "max_forward_N": 21.6,
        "max_reverse_N": 15.0,
    },
    {
        "name": "vertical",
        "position_body_m": [0.03, 0.0, 0.0],
        "direction_body": [0.0, 0.0, 1.0],
        "max_forward_N": 21.6,
        "max_reverse_N": 15.0,
    },
]


@pytest.fixture(scope="module")
def run():
    overrides = {
        "actuation.thruster": THRUSTERS,
        "scenario.duration_s": 0.4,
        "output.log_period_s": 0.002,  # every control tick
    }
    scenario = load_scenario(ROOT / SCENARIO, overrides)
    return scenario, up.simulate(scenario)


def test_the_plant_gets_the_logged_thrusts(run):
    scenario, rollout = run
    actuation = scenario.plant.actuation
    thrust = rollout.signals["thrust"]
    np.testing.assert_allclose(
        rollout.tau[:, :6], thrust @ actuation.allocation.T, rtol=0, atol=1e-12
    )


def test_each_thruster_follows_its_command_through_its_drive(run):
    scenario, rollout = run
    command, thrust = rollout.signals["thruster_command"], rollout.signals["thrust"]
    assert np.all(np.abs(command) <= 1.0)
    # no lag: the steady thrust of the command at once
    np.testing.assert_allclose(
        thrust[:, 1], t200_16v_curve().thrust_N(command[:, 1]), rtol=1e-15, atol=1e-15
    )
    np.testing.assert_allclose(
        thrust[:, 2], np.where(command[:, 2] > 0, 21.6, 15.0) * command[:, 2], atol=1e-12
    )
    # the lagged one: replay its ODE from the logged commands (a log row per tick)
    curve = scenario.plant.actuation.drives.curves[0]
    state = np.zeros(1)
    period = 0.002
    for k in range(len(command) - 1):
        state, mean = first_order_step(
            state,
            curve.thrust_N(command[k : k + 1, 0]),
            np.array([0.05]),
            np.array([200.0]),
            period,
        )
        assert mean[0] == pytest.approx(thrust[k, 0], abs=1e-12)


def test_the_table_names_each_thrusters_columns(run):
    _, rollout = run
    frame = rollout.to_dataframe()
    assert frame.attrs["units"]["thrust.lagged_N"] == "N"
    assert "thruster_command.vertical" in frame.columns


def test_a_limit_above_the_tabulated_curve_is_refused():
    from uvms_pin.errors import ScenarioError

    thruster = {**THRUSTERS[1], "max_forward_N": 60.0}
    with pytest.raises(
        ScenarioError, match=r"max_forward_N: 60.0 N is more than the t200_16v curve gives \(51.48"
    ):
        load_scenario(ROOT / SCENARIO, {"actuation.thruster": [thruster]})


def test_each_drive_key_of_an_entry_can_be_overridden():
    """``--set 'actuation.thruster[i].key=...'`` and study paths of the same form."""
    scenario = load_scenario(
        ROOT / SCENARIO,
        {
            "actuation.thruster[0].time_constant_s": 0.05,
            "actuation.thruster[1].curve": "quadratic",
            "actuation.thruster[1].deadband": 0.1,
            "actuation.thruster[2].rate_limit_N_s": 100.0,
        },
    )
    drives = scenario.plant.actuation.drives
    np.testing.assert_array_equal(drives.time_constant_s, [0.05, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(drives.rate_limit_N_s, [np.inf, np.inf, 100.0, np.inf])
    assert drives.curves[1].deadband == 0.1
