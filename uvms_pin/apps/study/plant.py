"""Plant factors a scenario file does not carry: inertia, added mass, damping, buoyancy.

`modify_plant` returns the scenario with its UVMS replaced by a scaled copy
(`uvms_pin.model.scaled.scaled_uvms`). The
controller is built from the scenario's UVMS but uses only its kinematics (model-free),
so the factors change the plant, not the controller.
"""

from __future__ import annotations

import dataclasses

from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.sim.run import Scenario


def modify_plant(scenario: Scenario, factors: dict[str, float]) -> Scenario:
    """The scenario with its plant's UVMS scaled by ``factors`` (names of `scaled_uvms`)."""
    if all(v == 1.0 for v in factors.values()):
        return scenario
    uvms = scaled_uvms(scenario.uvms, **factors)
    plant = dataclasses.replace(scenario.plant, uvms=uvms)
    return dataclasses.replace(scenario, plant=plant)
