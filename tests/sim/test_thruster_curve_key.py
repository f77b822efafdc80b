"""``[actuation] thruster_curve``: one key puts every thruster on a curve; the same run as
naming the curve (and its limits) thruster by thruster; the shipped BlueROV2 limits are the
T200 table's, so the key alone switches a shipped scenario."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ScenarioError
from uvms_pin.model.vehicles.bluerov2_heavy import T200_16V
from uvms_pin.model.vehicles.t200 import t200_16v_curve
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

BLUEROV = ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml"
SHORT = {"scenario.duration_s": 0.6}
N_THRUSTERS = 8


def _run(overrides: dict):
    rollout = simulate(load_scenario(BLUEROV, {**SHORT, **overrides}), progress=False)
    return rollout


def _same(a, b) -> None:
    for name in ("q", "v", "tau"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    for name in ("thrust", "thruster_command"):
        np.testing.assert_array_equal(a.signals[name], b.signals[name])


def test_the_key_is_the_24_settings_bit_for_bit():
    curve = t200_16v_curve()
    by_thruster = {}
    for k in range(N_THRUSTERS):
        by_thruster[f"actuation.thruster[{k}].curve"] = "t200_16v"
        by_thruster[f"actuation.thruster[{k}].max_forward_N"] = 51.48
        by_thruster[f"actuation.thruster[{k}].max_reverse_N"] = 39.91
    assert len(by_thruster) == 24
    keyed = _run({"actuation.thruster_curve": "t200_16v"})
    _same(keyed, _run(by_thruster))
    # and it is the table: every logged thrust is the curve's value of its command
    np.testing.assert_allclose(
        keyed.signals["thrust"], curve.thrust_N(keyed.signals["thruster_command"]), atol=1e-12
    )
    linear = _run({})
    assert (
        np.max(np.abs(keyed.signals["thruster_command"] - linear.signals["thruster_command"]))
        > 0.05
    )


def test_a_thrusters_own_curve_wins_over_the_key():
    scenario = load_scenario(
        BLUEROV,
        {**SHORT, "actuation.thruster_curve": "t200_16v", "actuation.thruster[2].curve": "linear"},
    )
    names = [c.name for c in scenario.plant.actuation.drives.curves]
    assert names[2] == "linear"
    assert names.count(t200_16v_curve().name) == N_THRUSTERS - 1


@pytest.mark.parametrize(
    "name",
    [
        "bluerov_alpha5_ee_circle",
        "bluerov_alpha5_force_tracking",
        "estimator_station_keeping",
        "seabed_survey",
        "valve_panel",
        "valve_turn",
    ],
)
def test_every_shipped_bluerov2_scenario_takes_the_key_alone(name):
    scenario = load_scenario(
        ROOT / "scenarios" / f"{name}.toml", {"actuation.thruster_curve": "t200_16v"}
    )
    curves = scenario.plant.actuation.drives.curves
    assert len(curves) == N_THRUSTERS and all(c is curves[0] for c in curves)
    for thruster in scenario.plant.actuation.thrusters:
        assert thruster.max_forward_N <= t200_16v_curve().max_forward_N
        assert thruster.max_reverse_N <= t200_16v_curve().max_reverse_N
        # the shipped limits are the table's ends, rounded to 0.01 N
        assert thruster.max_forward_N == pytest.approx(T200_16V.max_forward_N, abs=0.01)
        assert thruster.max_reverse_N == pytest.approx(T200_16V.max_reverse_N, abs=0.01)


def test_an_unknown_curve_is_named():
    with pytest.raises(ScenarioError, match=r"actuation\.thruster_curve.*t200_16v.*got 't300'"):
        load_scenario(BLUEROV, {"actuation.thruster_curve": "t300"})


def test_limits_beyond_the_keyed_curve_are_refused_by_thruster():
    with pytest.raises(
        ScenarioError, match=r"thruster\[0\]\.max_reverse_N'?: 40\.21 N is more than the t200_16v"
    ):
        load_scenario(
            BLUEROV,
            {"actuation.thruster_curve": "t200_16v", "actuation.thruster[0].max_reverse_N": 40.21},
        )
