"""A scenario's controller: its parameters checked once, where the table is read; the
controller built once per run (the build that checked it when the scenario was read is the
first run's)."""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin.scenario.ppc as ppc_table
from uvms_pin.control import ppc_params
from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.control.ppc_params import PPCParams
from uvms_pin.errors import ParameterError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
SHORT = {"scenario.duration_s": 0.04}


@pytest.fixture
def builds(monkeypatch) -> list[object]:
    """Every PPC the scenario reader builds, in order."""
    built: list[object] = []

    class Counted(PrescribedPerformanceController):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            built.append(self)

    monkeypatch.setattr(ppc_table, "PrescribedPerformanceController", Counted)
    return built


def test_the_controller_is_built_once_per_run(builds):
    scenario = load_scenario(REALISTIC, SHORT)
    assert len(builds) == 1  # built when read: a bad parameter is refused before any run
    first = simulate(scenario, progress=False, compiled_loop=False)
    assert len(builds) == 1  # ... and that build is the first run's
    again = simulate(scenario, progress=False, compiled_loop=False)
    assert len(builds) == 2  # a second run: a fresh controller
    np.testing.assert_array_equal(first.tau, again.tau)
    np.testing.assert_array_equal(first.q, again.q)


def test_a_copy_or_another_model_gets_a_fresh_controller(builds):
    scenario = load_scenario(REALISTIC, SHORT)
    copied = copy.deepcopy(scenario)  # a batch's copy: its own plant, its own controller
    assert copied.controller_factory(copied.uvms) is builds[-1] and len(builds) == 2
    other = copy.deepcopy(scenario.uvms)  # not the model the spec built for
    scenario.controller_factory(other)
    assert len(builds) == 3
    kept = scenario.controller_factory(scenario.uvms)  # the kept build, on its own model
    assert kept is builds[0] and len(builds) == 3


def test_the_ppc_parameters_are_checked_once(monkeypatch):
    calls: list[str] = []
    checked = ppc_params.sized_vector

    def counted(name, value, size):
        calls.append(name)
        return checked(name, value, size)

    monkeypatch.setattr(ppc_params, "sized_vector", counted)
    scenario = load_scenario(REALISTIC, SHORT)
    once = sorted(calls)
    assert once.count("k_x") == 1 and once.count("rho0_zeta") == 1
    simulate(scenario, progress=False)
    assert sorted(calls) == once  # neither the controller nor the run checks them again
    params = PPCParams.for_uvms(4)
    assert params.sized(10) is params  # a sized instance is trusted ...
    assert dataclasses.replace(params, k_x=0.3).sized(10) is not params  # a changed copy: checked


@pytest.mark.parametrize(
    ("fields", "needle"),
    [
        ({"k_zeta": -1.0}, "k_zeta must be > 0"),
        ({"rho0_x": 0.1}, "funnel 'f_x': rho0 = 0.1 must be > rho_inf = 0.2"),
        ({"l_zeta_per_s": [1.0] * 9 + [0.0]}, "funnel 'joint 4 rate': decay_rate_per_s = 0.0"),
        ({"k_x": "fast"}, "k_x must be a number or a list of numbers, got 'fast'"),
        ({"k_x": [1.0, 2.0]}, "k_x must be a scalar or have 6 entries, got (2,)"),
        ({"null_space_gain_per_s": True}, "null_space_gain_per_s must be a number, got True"),
    ],
)
def test_bad_ppc_parameters_are_refused_where_they_are_sized(fields, needle):
    with pytest.raises(ParameterError) as info:
        PPCParams(**fields).sized(10)
    assert needle in str(info.value)
