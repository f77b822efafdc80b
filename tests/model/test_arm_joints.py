"""The arm's joints of a model (uvms_pin.model.arm_joints): their kinds and limits as the
model has them, a position exactly on a limit inside them, the names of those beyond."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.model.arm_joints import ArmJoints

JAWS = ROOT / "models" / "uvms_bluerov2_alpha5_jaws.urdf"


@pytest.fixture(scope="module")
def joints() -> ArmJoints:
    uvms = up.load_uvms(JAWS)
    return ArmJoints.of(uvms.model)


def test_the_limits_are_the_models(joints):
    uvms = up.load_uvms(JAWS)
    model = uvms.model
    for k, name in enumerate(joints.names):
        at = model.joints[model.getJointId(name)].idx_q
        assert joints.lower[k] == model.lowerPositionLimit[at]
        assert joints.upper[k] == model.upperPositionLimit[at]
    assert joints.limited.all()


def test_a_position_on_a_limit_is_inside_and_one_beyond_is_named(joints):
    """The jaws start closed, on their lower limit: not outside. A hair beyond either limit
    names that joint, and only it."""
    assert joints.outside(joints.lower) == [] and joints.outside(joints.upper) == []
    middle = 0.5 * (joints.lower + joints.upper)
    for k, name in enumerate(joints.names):
        for beyond in (joints.lower[k] - 1e-9, joints.upper[k] + 1e-9):
            positions = middle.copy()
            positions[k] = beyond
            assert joints.outside(positions) == [name]
    np.testing.assert_array_equal(joints.clip(joints.upper + 1.0), joints.upper)
