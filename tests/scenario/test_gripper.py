"""``[gripper]``: the jaw's servo beside the arm's controller, its log and its errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import uvms_pin as up
from uvms_pin.control.jaw_servo import WithJaw
from uvms_pin.errors import ScenarioError

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "gripper_close.toml"


def _load(**overrides) -> up.Scenario:
    return up.load_scenario(SCENARIO, overrides=overrides)


def test_the_arm_controller_is_built_on_the_arm_only():
    scenario = _load()
    controller = scenario.controller_factory(scenario.plant.uvms)
    assert isinstance(controller, WithJaw)
    assert controller.arm.nv == 10  # vehicle 6 + the Alpha 5's four joints
    assert scenario.plant.uvms.nv == 12  # + the two fingers
    assert scenario.controller_factory.params["gripper"] == {
        "joints": ["alpha_jaw_finger_130_joint", "alpha_jaw_finger_139_joint"],
        "max_force_N": 10.0,
        "close_at_s": 0.2,
        "open_at_s": 3.0,
    }


def test_the_jaw_closes_and_its_opening_and_grip_are_logged():
    rollout = up.simulate(_load(**{"scenario.duration_s": 0.6}))
    table = rollout.to_dataframe()
    angle = table["jaw.alpha_jaw_finger_130_joint_rad"]
    grip = table["jaw.alpha_jaw_finger_130_joint_grip_N"]
    t = np.asarray(table.index, dtype=float)
    # open (the servo holds them within 0.1 mrad while the vehicle settles), pressing nothing
    np.testing.assert_allclose(angle[t < 0.2], 0.5, atol=1e-4)
    assert grip[t < 0.2].max() < 0.01
    assert grip[(t >= 0.2) & (t < 0.25)].max() == pytest.approx(10.0)  # closing: saturated
    assert angle.iloc[-1] == pytest.approx(0.36, abs=0.005)  # closed on the rod, hooks parallel
    assert grip.iloc[-1] == pytest.approx(10.0)  # pressing it with the full grip
    np.testing.assert_array_equal(table["q.alpha_jaw_finger_130_joint_rad"], angle)


def test_by_controller_builds_the_controller_on_the_whole_model():
    scenario = _load(**{"gripper": {"by_controller": True}, "controller": {"type": "none"}})
    controller = scenario.controller_factory(scenario.plant.uvms)
    assert not isinstance(controller, WithJaw) and controller.nv == 12


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"gripper.max_force_N": -1.0}, r"gripper\.max_force_N'?: must be positive"),
        ({"gripper.open_at_s": 0.1}, r"open_at_s \(0\.1\) must come after close_at_s"),
        ({"gripper.joints": ["alpha_axis_c"]}, r"gripper\.joints'?: .*moves below the jaw"),
        ({"gripper.joints": ["nope"]}, r"gripper\.joints'?: .*not among the model's moving"),
        ({"gripper.joints": "alpha_axis_c"}, r"gripper\.joints'?: must be a list of joint names"),
        ({"gripper.grip": 1.0}, r"gripper"),
    ],
)
def test_bad_gripper_tables_name_the_key(overrides, match):
    with pytest.raises(ScenarioError, match=match):
        _load(**overrides)


def test_a_gripper_table_needs_jaw_joints():
    path = ROOT / "scenarios" / "push_object.toml"
    with pytest.raises(ScenarioError, match=r"gripper.*has no jaw joints"):
        up.load_scenario(path, overrides={"gripper": {"max_force_N": 5.0}})
