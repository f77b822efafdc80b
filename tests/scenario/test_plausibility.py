"""A scenario's physical numbers against what any water, sea or run has: refused (naming
the key, or the override that set it) where no water or wave can be that, warned (with the
number and the usual range) where none usually is."""

from __future__ import annotations

import warnings

import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.errors import PlausibilityWarning
from uvms_pin.scenario.load import load_scenario

PASSIVE = ROOT / "scenarios" / "passive_current.toml"
WAVES = {"water.waves.amplitude_m": 0.1, "water.waves.period_s": 8.0}


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"water.density_kg_m3": 1025000.0}, "override 'water.density_kg_m3': 1.025e+06 kg/m^3 cannot be physical"),
        ({"water.current_world_m_s": [1e6, 0.0, 0.0]}, "override 'water.current_world_m_s': 1e+06 m/s cannot be physical"),
        ({**WAVES, "water.waves.period_s": 1e-6}, "override 'water.waves.period_s': 1e-06 s cannot be physical"),
        ({**WAVES, "water.waves.amplitude_m": 60.0}, "60 m cannot be physical: no sea wave is that high"),
        ({**WAVES, "water.waves.amplitude_m": 20.0}, "steeper than 1/7: it breaks"),
        ({"water.sea.significant_height_m": 1.0, "water.sea.peak_period_s": 0.01}, "override 'water.sea.peak_period_s': 0.01 s cannot be physical"),
        ({"water.sea.significant_height_m": 45.0, "water.sea.peak_period_s": 15.0}, "45 m cannot be physical: no sea state is that high"),
        ({"initial.position_world_m": [0.0, 0.0, 1e9]}, "initial.position_world_m[2]: 1e+09 m cannot be physical"),
        ({"initial.position_world_m": [0.0, 0.0, -2e4]}, "initial.position_world_m[2]: -20000 m cannot be physical: deeper than the deepest sea floor"),
    ],
)  # fmt: skip
def test_what_no_water_or_sea_can_be_is_refused(overrides, message):
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(PASSIVE, overrides)
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"water.density_kg_m3": 1240.0}, "override 'water.density_kg_m3': 1240 kg/m^3 is far outside fresh to sea water (990 to 1050 kg/m^3)"),
        ({"water.current_world_m_s": [7.0, 0.0, 0.0]}, "7 m/s is far outside sea and tidal currents (0 to 5 m/s)"),
        ({**WAVES, "water.waves.period_s": 40.0}, "40 s is far outside sea waves"),
        ({"water.sea.significant_height_m": 18.0, "water.sea.peak_period_s": 15.0}, "18 m is far outside sea states"),
        ({**WAVES, "water.waves.amplitude_m": 12.0, "water.waves.period_s": 25.0}, "12 m is far outside sea waves"),
        ({"integrator.step_s": 1e-9}, "override 'integrator.step_s': 1e-09 s is far outside the steps a UVMS run needs (1e-05 to 0.05 s); every simulated second takes 1/step steps"),
        ({"initial.position_world_m": [0.0, 0.0, 50.0]}, "initial.position_world_m[2] = 50 m is far outside starting depths in the sea"),
        ({"control.period_s": 1e-5, "output.log_period_s": 0.02, "integrator.step_s": 1e-5}, "override 'control.period_s': 1e-05 s is far outside controller rates"),
        ({"initial.velocity": [100.0] + [0.0] * 9}, "override 'initial.velocity': 100 m/s is far outside the speeds of a vehicle in water (a few m/s at most) (0 to 10 m/s)"),
        ({"initial.velocity": [0.0] * 9 + [500.0]}, "override 'initial.velocity': 500 rad/s is far outside the rates of a vehicle or an arm's joint"),
    ],
)  # fmt: skip
def test_what_no_vehicle_usually_meets_is_warned_once(overrides, message):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        load_scenario(PASSIVE, overrides)
    texts = [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]
    assert len([t for t in texts if message in t]) == 1, texts
    assert len([t for t in texts if "density" in t]) <= 1  # the model's load says it no twice


def test_the_shipped_scenarios_are_plausible():
    for path in sorted((ROOT / "scenarios").glob("*.toml")):
        with warnings.catch_warnings():
            warnings.simplefilter("error", PlausibilityWarning)
            load_scenario(path)
