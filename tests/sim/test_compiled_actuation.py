"""The compiled core's one actuation (src/uvms_core/actuation.hpp), which the compiled closed
loop and the batched plant both apply: the Python `ThrustersAndJointLimits` and `Unlimited`
to 1e-12, saturating or not, every allocated-components choice the scenarios use."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.apps.gym.env import scenario_path
from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.actuation import Unlimited
from uvms_pin.sim.compiled.actuation import actuation_to_core


def _commands(actuation, nv: int, seed: int) -> np.ndarray:
    """Commands from well inside the limits to 3x past them (thrusters and joints)."""
    scale = np.concatenate([np.full(6, 60.0), actuation.joint_effort_limits_Nm * 3.0])
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, (200, nv)) * scale * rng.uniform(0.01, 1.0, (200, 1))


@pytest.mark.parametrize("components", [None, [0, 1, 2, 3, 4, 5]])
def test_the_core_actuation_is_the_python_one(components):
    overrides = {"scenario.duration_s": 0.03}
    if components is not None:  # all six asked of thrusters that cannot roll or pitch
        overrides["actuation.allocated_components"] = components
    scenario = load_scenario(scenario_path("realistic_force_tracking"), overrides)
    actuation, nv = scenario.plant.actuation, scenario.uvms.nv
    core = actuation_to_core(actuation, core_module(), nv)
    assert core.thrusters
    saturated = 0
    for tau in _commands(actuation, nv, 3):
        applied, thrust = core.apply(tau)
        np.testing.assert_allclose(applied, actuation.apply(tau), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(thrust, actuation.thrusts(tau), rtol=1e-12, atol=1e-12)
        saturated += actuation.saturated(tau)
    assert 20 < saturated < 190  # both cases were exercised


def test_unlimited_applies_the_command():
    core = actuation_to_core(Unlimited(), core_module(), 10)
    tau = np.linspace(-1e3, 1e3, 10)
    applied, thrust = core.apply(tau)
    np.testing.assert_array_equal(applied, tau)
    assert thrust.size == 0


def test_joint_limits_of_the_wrong_size_are_refused():
    scenario = load_scenario(scenario_path("realistic_force_tracking"))
    core = actuation_to_core(scenario.plant.actuation, core_module(), scenario.uvms.nv)
    with pytest.raises(ParameterError, match="joint limits"):
        core.apply(np.zeros(scenario.uvms.nv + 1))
