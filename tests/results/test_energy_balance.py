"""The energy a run reports: for a driven run the balance E(T) - E(0) = W_tau + W_rest (the
work of the applied generalized force and of the water, contact and disturbance), checked
where W_rest is known to vanish (no damping, still water); for a run nothing drives, the
largest relative change of E."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

STILL = ROOT / "scenarios" / "passive_still_water.toml"


class Constant(Controller):
    def __init__(self, tau):
        self.tau = np.asarray(tau, dtype=float)

    def compute(self, time_s, measurement):
        return self.tau


def _undamped(overrides):
    scenario = load_scenario(STILL, overrides)
    uvms = scenario.uvms.with_hydro(
        lambda b: dataclasses.replace(
            b.params,
            linear_damping=np.zeros((6, 6)),
            quadratic_damping=np.zeros(6),
        )
    )
    return dataclasses.replace(scenario, plant=dataclasses.replace(scenario.plant, uvms=uvms))


def test_the_work_of_tau_is_the_energy_change_when_nothing_else_works():
    # an arm joint reaches its limit within the second: its stop would work on it too
    overrides = {"scenario.duration_s": 1.0, "output.log_period_s": 0.002}
    scenario = _undamped({**overrides, "joints.hard_stops": False})
    tau = [1.0, -0.5, 0.3, 0.0, 0.05, 0.2, 0.3, -0.2, 0.1, 0.05]
    scenario.controller_factory = lambda uvms: Constant(tau)
    metrics = simulate(scenario, progress=False).metrics()
    assert "energy_relative_drift_max" not in metrics  # driven: a balance instead
    assert abs(metrics["work_of_tau_J"]) > 0.1  # the input did real work
    assert metrics["work_of_tau_J"] == pytest.approx(metrics["energy_change_J"], rel=1e-3)
    assert abs(metrics["work_of_water_contact_disturbance_J"]) < 1e-3 * abs(
        metrics["work_of_tau_J"]
    )


def test_damping_shows_as_the_rest_of_the_balance():
    scenario = load_scenario(STILL, {"scenario.duration_s": 1.0})
    scenario.controller_factory = lambda uvms: Constant([2.0] + [0.0] * 9)
    metrics = simulate(scenario, progress=False).metrics()
    assert metrics["work_of_tau_J"] > 0.0
    assert metrics["work_of_water_contact_disturbance_J"] < 0.0  # the water dissipates


def test_an_undriven_run_reports_its_relative_energy_change():
    metrics = simulate(_undamped({"scenario.duration_s": 1.0}), progress=False).metrics()
    assert "work_of_tau_J" not in metrics
    assert metrics["energy_relative_drift_max"] < 1e-6  # conservative: RK4's error only
