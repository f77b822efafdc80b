"""What a rollout records of its controller: a controller set in code (replacing the
scenario's) is recorded as what ran, not the TOML's [controller] table it replaced."""

from __future__ import annotations

import json

import numpy as np
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


class Hold(Controller):
    def __init__(self, nv: int):
        self.gain = 2.5
        self.weights = np.arange(3.0)
        self.label = "hold"
        self._state = object()  # private: not recorded
        self.nv = nv

    def compute(self, time_s, measurement):
        return np.zeros(self.nv)


def test_the_scenario_controller_is_recorded_from_its_table():
    rollout = simulate(load_scenario(REALISTIC, {"scenario.duration_s": 0.02}), progress=False)
    assert rollout.metadata["controller"]["type"] == "ppc"
    assert rollout.metadata["parameters"]["controller"]["type"] == "ppc"
    assert "set_in_code" not in rollout.metadata["parameters"]["controller"]


def test_a_controller_set_in_code_is_recorded_as_what_ran():
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.02})
    scenario.controller_factory = lambda uvms: Hold(uvms.nv)
    rollout = simulate(scenario, progress=False)
    record = rollout.metadata["controller"]
    assert record["class"] == record["type"] == f"{__name__}:Hold"
    assert record["params"] == {"gain": 2.5, "weights": [0.0, 1.0, 2.0], "label": "hold", "nv": 10}
    table = rollout.metadata["parameters"]["controller"]
    assert table == {"type": f"{__name__}:Hold", "set_in_code": True, **record["params"]}
    assert "k_zeta" not in table  # the TOML's PPC gains did not run
    json.dumps(rollout.metadata)  # recordable


def test_a_spec_set_in_code_is_recorded_with_its_parameters():
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.02})
    scenario.controller_factory = ControllerSpec("hold", {"gain": 1.0}, lambda uvms: Hold(uvms.nv))
    rollout = simulate(scenario, progress=False)
    assert rollout.metadata["controller"]["params"] == {"gain": 1.0}
    assert rollout.metadata["parameters"]["controller"] == {
        "type": "hold", "set_in_code": True, "gain": 1.0
    }  # fmt: skip
