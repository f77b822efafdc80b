"""A fin's ``<lift_drag>`` read from a URDF link (uvms_pin.model.urdf.lift_drag): its control
joint is one of the arm's joints of one coordinate, named; anything else is refused."""

from __future__ import annotations

import pytest
from conftest import ROOT

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.load import load_uvms

LBV = (ROOT / "models" / "uvms_lbv150.urdf").read_text()
FIRST_ARM_JOINT = "arm_joint1"


def _with_fin(tmp_path, control: str):
    """The LBV150 with a fin on its vehicle link (the file's first link), controlled by the
    joint ``control``."""
    fin = (
        '<lift_drag><area value="0.02"/><cla value="4.1"/>'
        f'<control_joint name="{control}" rad_to_cl="4" cm_delta="0.1"/></lift_drag></link>'
    )
    path = tmp_path / "fin.urdf"
    path.write_text(LBV.replace("</link>", fin, 1))
    return path


def test_the_control_joint_is_the_arm_joints_coordinate(tmp_path):
    uvms = load_uvms(_with_fin(tmp_path, FIRST_ARM_JOINT))
    (fin,) = uvms.fins
    joint = uvms.model.joints[uvms.model.getJointId(FIRST_ARM_JOINT)]
    assert fin.control_q_index == joint.idx_q == 7


@pytest.mark.parametrize("control", ["", "no_such_joint", "root_joint", "universe"])
def test_a_control_joint_that_is_no_arm_joint_is_refused_by_name(tmp_path, control):
    """Empty, not in the model, or the vehicle's own free-flyer (or the universe): no arm
    joint turns the fin."""
    with pytest.raises(ModelError, match=f"control_joint name='{control}'> is not an arm joint"):
        load_uvms(_with_fin(tmp_path, control))
