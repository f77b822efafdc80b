"""scenarios/valve_turn.toml: the BlueROV2 Heavy + Alpha 5 turns a subsea panel's
quarter-turn valve (2 N m of Coulomb friction with stiction) through 90 degrees with its
closed jaw, the push from the thrusters; its own metrics (scenarios/valve_turn_metrics.py)
say whether it did. With a push budget below the friction torque over the lever
(15 N x 0.08 m = 1.2 N m < 2 N m) the valve does not move and ``turned`` is 0."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SCENARIO = SCENARIOS / "valve_turn.toml"
FRICTION_NM = 2.0
LEVER_M = 0.08


def _metrics(**overrides) -> dict[str, float]:
    rollout = up.simulate(up.load_scenario(SCENARIO, overrides=overrides))
    assert rollout.metadata["status"] == "ok"
    return rollout.metrics()


def test_the_valve_is_turned_a_quarter_turn_by_the_thrusters_push():
    metrics = _metrics()
    assert metrics["turned"] == 1.0
    assert metrics["valve_turned_rad"] >= 0.95 * math.pi / 2
    assert metrics["valve_turned_rad"] <= math.pi / 2 + 1e-3  # held at its stop
    # the push that turned it: at least the friction over the lever, within the budget
    assert FRICTION_NM / LEVER_M < metrics["contact_force_peak_N"] < 60.0
    assert metrics["energy_max_increase_J"] < 1.0


def test_a_push_budget_below_the_friction_leaves_the_valve_closed():
    budget_N = 15.0
    assert budget_N * LEVER_M < FRICTION_NM
    # the sweep ends at 12 s: the run stops there
    metrics = _metrics(**{"controller.max_push_N": budget_N, "scenario.duration_s": 12.0})
    assert metrics["turned"] == 0.0
    assert abs(metrics["valve_turned_max_rad"]) < 0.01
    assert metrics["contact_force_peak_N"] > 5.0  # it did press on the paddle


def test_the_controller_refuses_phases_it_does_not_have():
    sys.path.insert(0, str(SCENARIOS))
    try:
        from valve_turn import ValveTurn
    finally:
        sys.path.remove(str(SCENARIOS))
    uvms = up.load_uvms(SCENARIOS.parent / "models" / "uvms_bluerov2_alpha5.urdf")
    with pytest.raises(ParameterError, match="phase_durations_s"):
        ValveTurn(uvms, [0.785, -0.156, -2.027], [1.0, 2.0], [0.0] * 4, [1.0] * 4, [0.1] * 4)


def test_its_metric_names_the_missing_valve_when_the_world_is_replaced():
    """`--set world=...` without the panel: the metric said KeyError: 'panel' (an accident
    of its code); it names the fixture and joint it needs now."""
    seabed = {"type": "plane", "name": "seabed", "point_world_m": [0.0, 0.0, -30.0]}
    overrides = {"world": {"objects": [seabed]}, "scenario.duration_s": 0.1}
    rollout = up.simulate(up.load_scenario(SCENARIO, overrides=overrides))
    with pytest.raises(ParameterError, match="no fixture 'panel' with a joint 'valve'"):
        rollout.metrics()
