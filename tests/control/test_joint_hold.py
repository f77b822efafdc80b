"""``joint_hold``: named arm joints held by a PD at set angles, a constant push on the
vehicle, nothing on the other joints; its table read and refused by key."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, continuous_joint_urdf

import uvms_pin as up
from uvms_pin.control.joint_hold import JointHoldController
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError, ScenarioError


@pytest.fixture(scope="module")
def lbv():
    return up.load_uvms(ROOT / "models" / "uvms_lbv150.urdf")


def test_the_law_is_the_pd_on_the_held_joints_and_the_push_on_the_vehicle(lbv):
    wrench = [3.0, -1.0, 0.5, 0.1, 0.2, -0.3]
    law = JointHoldController(lbv.model, {"arm_joint2": 0.4}, 2.0, 0.5, wrench)
    rng = np.random.default_rng(2)
    q = lbv.neutral_configuration()
    q[7:] = rng.uniform(-0.5, 0.5, lbv.nv - 6)
    v = rng.normal(size=lbv.nv)
    tau = law.compute(0.0, Measurement(0.0, q, v, np.zeros(6)))
    joint = lbv.model.joints[lbv.model.getJointId("arm_joint2")]
    expected = np.zeros(lbv.nv)
    expected[:6] = wrench
    expected[joint.idx_v] = 2.0 * (0.4 - q[joint.idx_q]) - 0.5 * v[joint.idx_v]
    np.testing.assert_array_equal(tau, expected)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (({"wrist": 0.1}, 1.0), "'wrist' is not an arm joint"),
        (({}, 1.0), "names no joint"),
        (({"arm_joint1": 0.1}, 0.0), "stiffness_Nm_rad must be finite and > 0"),
        (({"arm_joint1": 0.1}, 1.0, -1.0), "damping_Nms_rad must be finite and >= 0"),
        (({"arm_joint1": 0.1}, 1.0, 0.0, [1.0, 2.0]), "vehicle_wrench_body"),
    ],
)
def test_bad_parameters_are_refused_by_name(lbv, args, message):
    with pytest.raises(ParameterError, match=message):
        JointHoldController(lbv.model, *args)


def test_the_scenario_table_builds_it_and_names_a_bad_key():
    path = ROOT / "scenarios" / "passive_still_water.toml"
    table = {"type": "joint_hold", "positions_rad": {"arm_joint1": 0.3}, "stiffness_Nm_rad": 5.0,
             "damping_Nms_rad": 1.0}  # fmt: skip
    sampled = {"control.period_s": 0.01, "joints.stops": "implicit"}
    scenario = up.load_scenario(path, {"controller": table, "scenario.duration_s": 3.0, **sampled})
    rollout = up.simulate(scenario, progress=False)
    joint = scenario.uvms.model.joints[scenario.uvms.model.getJointId("arm_joint1")]
    assert rollout.q[-1, joint.idx_q] == pytest.approx(0.3, abs=0.05)  # moved to its target
    assert rollout.metadata["controller"]["type"] == "joint_hold"
    for bad, key in (
        ({**table, "positions_rad": 0.3}, "positions_rad"),
        ({**table, "positions_rad": {"arm_joint1": "up"}}, "positions_rad"),
        ({**table, "stiffness_Nm_rad": -1.0}, "stiffness_Nm_rad"),
        ({**table, "positions_rad": {"elbow": 0.1}}, "'elbow' is not an arm joint"),
    ):
        with pytest.raises(ScenarioError, match=key):
            up.load_scenario(path, {"controller": bad})


def test_a_continuous_joint_is_refused_as_not_one_angle(tmp_path):
    """A continuous joint's configuration is (cos, sin), two numbers for one velocity: the
    hold, a PD on one angle, refuses it by name (a revolute one beside it is held)."""
    uvms = up.load_uvms(continuous_joint_urdf(tmp_path, ("arm_joint2",)))
    JointHoldController(uvms.model, {"arm_joint1": 0.1}, 1.0)
    with pytest.raises(ParameterError, match="'arm_joint2' is not a one-angle joint"):
        JointHoldController(uvms.model, {"arm_joint2": 0.1}, 1.0)
