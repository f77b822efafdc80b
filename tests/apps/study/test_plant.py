"""`modify_plant`: the factors change the plant, never the controller's model."""

from __future__ import annotations

from pathlib import Path

from uvms_pin.apps.study.plant import modify_plant
from uvms_pin.scenario.load import load_scenario

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"


def test_a_model_based_controller_keeps_the_nominal_model():
    """computed torque on a plant x1.3: the plant's vehicle is 30 % heavier, the controller's
    model (what it cancels) is still the nominal one; its record is unchanged."""
    scenario = load_scenario(
        SCENARIOS / "passive_still_water.toml", {"controller": {"type": "computed_torque"}}
    )
    modified = modify_plant(scenario, {"mass_scale": 1.3, "damping_scale": 1.3})
    controller = modified.controller_factory(modified.uvms)
    nominal_mass = scenario.uvms.model.inertias[1].mass
    assert modified.uvms.model.inertias[1].mass == 1.3 * nominal_mass
    assert controller.uvms.model.inertias[1].mass == nominal_mass
    assert modified.controller_factory.type == "computed_torque"
    assert modified.controller_factory.params == scenario.controller_factory.params
    assert modify_plant(scenario, {"mass_scale": 1.0}) is scenario
