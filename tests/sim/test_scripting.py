"""Scenarios built in code (`scenario_from_dict`), a controller instance passed to
`simulate`, and controllers' named, unit-carrying signals (`Signal`) as table columns."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.results.signal import Signal
from uvms_pin.scenario.load import scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.run import simulate

PASSIVE = ROOT / "scenarios" / "passive_still_water.toml"


def _passive(duration_s: float = 0.1) -> dict:
    raw = read_toml(PASSIVE, ScenarioError)
    raw["scenario"]["duration_s"] = duration_s
    return raw


class Braking(Controller):
    """tau = -c zeta, logging the vehicle's speed and the joint rates as named signals."""

    def __init__(self, damping: float):
        self.damping = damping
        self.calls = 0
        self._signals: dict = {}

    def reset(self) -> None:
        self.calls = 0

    def compute(self, time_s, measurement):
        self.calls += 1
        v = measurement.v
        self._signals = {
            "speed": Signal([np.linalg.norm(v[:3])], ["vehicle"], "m/s"),
            "rates": Signal(v[6:], [f"j{k}" for k in range(v.size - 6)], "rad/s"),
            "plain": np.array([1.0, 2.0]),
        }
        # the arm's links are light: a gentler damping keeps RK4 at 2 ms stable
        return -self.damping * np.asarray(v) * np.r_[np.ones(6), 0.01 * np.ones(v.size - 6)]

    def signals(self):
        return self._signals


def test_from_dict_equals_the_file(tmp_path):
    raw = _passive()
    from_file = up.load_scenario(PASSIVE, {"scenario.duration_s": 0.1})
    from_dict = scenario_from_dict(raw)
    assert from_dict.raw == from_file.raw and from_dict.name == from_file.name
    a, b = simulate(from_file, progress=False), simulate(from_dict, progress=False)
    np.testing.assert_array_equal(a.q, b.q)
    # the dict is the caller's: building the scenario changes nothing in it
    assert raw == _passive()


def test_from_dict_checks_keys_as_a_file_is():
    raw = _passive()
    raw["water"]["densty_kg_m3"] = 1000.0
    with pytest.raises(
        ScenarioError, match=r"<dict>: \[water\] has unknown key\(s\): densty_kg_m3"
    ):
        scenario_from_dict(raw)
    with pytest.raises(ScenarioError, match=r"override 'scenario\.duration_s': must be positive"):
        scenario_from_dict(_passive(), overrides={"scenario.duration_s": -1.0})


def test_a_controller_instance_runs_and_is_recorded():
    scenario = scenario_from_dict(_passive(0.2))
    passive = simulate(scenario, progress=False)
    braking = Braking(30.0)
    rollout = simulate(scenario, progress=False, controller=braking)
    calls = braking.calls
    assert calls >= len(rollout)  # continuous control: every integrator stage
    again = simulate(scenario, progress=False, controller=braking)
    assert braking.calls == calls  # reset at the start of every run
    np.testing.assert_array_equal(again.q, rollout.q)
    # recorded as a controller set in code: its class, and its public numbers
    path = f"{Braking.__module__}:Braking"
    record = rollout.metadata["controller"]
    assert record["class"] == record["type"] == path and record["params"]["damping"] == 30.0
    table = rollout.metadata["parameters"]["controller"]
    assert table["type"] == path and table["set_in_code"] is True
    # the damping slows the vehicle and the arm down compared with the passive run
    assert rollout.kinetic_energy_J[-1] < 0.8 * passive.kinetic_energy_J[-1]
    with pytest.raises(ParameterError, match="Controller instance"):
        simulate(scenario, progress=False, controller=lambda t, m: None)


def test_named_signals_become_named_columns_with_units(tmp_path):
    scenario = scenario_from_dict(_passive(0.1))
    rollout = simulate(scenario, progress=False, controller=Braking(1.0))
    frame = rollout.to_dataframe()
    names = rollout.metadata["arm_joint_names"]
    assert "speed.vehicle_m_s" in frame.columns
    assert frame.attrs["units"]["speed.vehicle_m_s"] == "m/s"
    rates = [f"rates.j{k}_rad_s" for k in range(len(names))]
    np.testing.assert_allclose(frame[rates].to_numpy(), rollout.v[:, 6:])
    np.testing.assert_allclose(
        frame["speed.vehicle_m_s"].to_numpy(), np.linalg.norm(rollout.v[:, :3], axis=1)
    )
    assert {"plain.0", "plain.1"} <= set(frame.columns)  # arrays keep numbered columns
    # a saved rollout reads back with the names and units
    rollout.save(tmp_path)
    again = up.Rollout.load(tmp_path).to_dataframe()
    assert list(again.columns) == list(frame.columns)
    assert json.loads((tmp_path / "rollout.json").read_text())["signal_units"]["speed"] == {
        "components": ["vehicle"], "units": ["m/s"],
    }  # fmt: skip


@pytest.mark.parametrize(
    "args, match",
    [
        (([1.0, 2.0], ["a"], "m"), "must agree"),
        (([1.0], ["a"], ["m", "s"]), "must agree"),
        (([1.0, 2.0], ["a", "a"], "m"), "distinct identifiers"),
        (([1.0], ["not a name"], "m"), "distinct identifiers"),
        ((np.zeros((2, 2)), ["a", "b"], "m"), "must agree"),
    ],
)
def test_bad_signal_records_are_refused(args, match):
    with pytest.raises(ParameterError, match=match):
        Signal(*args)
