"""The paper's force task on the BlueROV2 Heavy + Alpha 5: funnels hold within its limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.actuation import ThrustersAndJointLimits
from uvms_pin.sim.run import simulate

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "bluerov_alpha5_force_tracking.toml"


def test_funnels_hold_through_the_transient_within_t200_and_joint_limits():
    """2 s (the orientation transient peaks at ~0.5 s): every error inside its funnel, every
    applied thrust inside the T200 limits, every joint torque inside the Alpha 5's."""
    scenario = load_scenario(SCENARIO, {"scenario.duration_s": 2.0})
    rollout = simulate(scenario)
    assert rollout.metadata["status"] == "ok"
    metrics = rollout.metrics()
    assert metrics["funnel_margin_min_first"] > 0.0
    assert metrics["funnel_margin_min_second"] > 0.0
    assert metrics["joint_limit_excess_max_rad"] == 0.0
    actuation = scenario.plant.actuation
    assert isinstance(actuation, ThrustersAndJointLimits)
    assert len(actuation.thrusters) == 8
    thrusts = np.array([actuation.thrusts(tau) for tau in rollout.tau])
    assert np.all(thrusts <= 5.25 * 9.80665 + 1e-9) and np.all(thrusts >= -4.1 * 9.80665 - 1e-9)
    np.testing.assert_allclose(actuation.joint_effort_limits_Nm, [9, 9, 9, 5])
    assert np.all(np.abs(rollout.tau[:, 6:]) <= actuation.joint_effort_limits_Nm + 1e-12)


def test_thrusters_allocate_all_six_components_unless_told_otherwise():
    """[actuation] without ``allocated_components``: surge to yaw, 0 to 5, all of them."""
    from uvms_pin.errors import ScenarioError
    from uvms_pin.scenario.load import scenario_from_dict
    from uvms_pin.scenario.toml import read_toml

    raw = read_toml(SCENARIO, ScenarioError)
    del raw["actuation"]["allocated_components"]
    actuation = scenario_from_dict(raw, SCENARIO).plant.actuation
    assert list(actuation.allocated_components) == [0, 1, 2, 3, 4, 5]
