"""Plant factors a scenario file does not carry: inertia, added mass, damping, buoyancy.

`modify_plant` returns the scenario with its UVMS replaced by a scaled copy
(`uvms_pin.model.scaled.scaled_uvms`). The controller is still built on the scenario's own
(nominal) UVMS: the factors change the plant, not the controller, so a model-based
controller (computed torque, MPC) meets a plant its model gets wrong, and a model-free one
(which reads only the kinematics, the same in both) is unaffected.
"""

from __future__ import annotations

import dataclasses
import functools

from uvms_pin.control.spec import ControllerSpec
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.sim.robots_run import RobotsScenario
from uvms_pin.sim.run import Scenario


def modify_plant(
    scenario: Scenario | RobotsScenario, factors: dict[str, float]
) -> Scenario | RobotsScenario:
    """The scenario with its plant's UVMS scaled by ``factors`` (names of `scaled_uvms`);
    a scenario of several robots with every robot's plant scaled alike."""
    if all(v == 1.0 for v in factors.values()):
        return scenario
    if isinstance(scenario, RobotsScenario):
        robots = tuple(modify_plant(robot, factors) for robot in scenario.robots)
        return dataclasses.replace(scenario, robots=robots)
    nominal, spec = scenario.uvms, scenario.controller_factory
    uvms = scaled_uvms(nominal, **factors)
    plant = dataclasses.replace(scenario.plant, uvms=uvms)
    build = functools.partial(_on_model, spec, nominal)
    factory = dataclasses.replace(spec, build=build) if isinstance(spec, ControllerSpec) else build
    return dataclasses.replace(scenario, plant=plant, controller_factory=factory)


def _on_model(factory, nominal: UVMS, plant_uvms: UVMS):
    """``factory``'s controller built on ``nominal`` whatever the plant's model is."""
    return factory(nominal)
