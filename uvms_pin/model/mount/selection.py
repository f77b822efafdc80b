"""Which part of the arm file is mounted: the subtree below ``arm_base_link`` (default: the
arm's root), the end-effector (wrist) link ``ee_link`` and the moving joints between them.

Without an ``ee_link``, follow the arm from its base while one single branch carries moving
joints, and stop before a branch or a gripper joint (a name with finger, gripper, jaw or
hand): the wrist is the child of the last moving joint passed.
"""

from __future__ import annotations

from dataclasses import dataclass

from uvms_pin.errors import ModelError
from uvms_pin.model.jaw import GRIPPER_WORDS, is_jaw_name
from uvms_pin.model.mount.tree import URDFTree

__all__ = ["GRIPPER_WORDS", "ArmSelection", "choose_ee_link", "select_arm"]


@dataclass(frozen=True)
class ArmSelection:
    """The part of the arm that is mounted (arm file names).

    Attributes:
        base: the link bolted to the vehicle.
        ee: the wrist link carrying the F/T sensor.
        subtree: ``base`` and every link below it (what is mounted).
        chain: the moving joints from ``base`` to ``ee`` (the UVMS's arm joints).
        sensor_link: an arm link used as the sensor frame, or None.
    """

    base: str
    ee: str
    subtree: list[str]
    chain: list[str]
    sensor_link: str | None


def select_arm(
    arm: URDFTree, arm_base_link: str | None, ee_link: str | None, sensor_link: str | None
) -> ArmSelection:
    """The base, wrist, chain and sensor link the options name (or the defaults).

    Raises:
        ModelError: an unknown link, an ``ee_link`` or ``sensor_link`` not below the base,
            no moving joint between the base and the wrist.
    """
    path = str(arm.path)
    base = (
        arm.root_link if arm_base_link is None else arm.require_link(arm_base_link, "arm_base_link")
    )
    subtree = arm.subtree(base)
    if ee_link is None:
        ee = choose_ee_link(arm, base)
    else:
        ee = arm.require_link(ee_link, "ee_link")
        if ee not in subtree:
            raise ModelError(
                f"ee_link '{ee}' is not below arm_base_link '{base}'", path=path, link=ee
            )
    chain = [j for j in arm.path_joints(base, ee) if arm.is_moving(j)]
    if not chain:
        raise ModelError(
            f"no moving joint between arm_base_link '{base}' and ee_link '{ee}'", path=path
        )
    if sensor_link is not None:
        sensor_link = arm.require_link(sensor_link, "sensor_link")
        if sensor_link not in subtree:
            raise ModelError(
                f"sensor_link '{sensor_link}' is not below arm_base_link '{base}'",
                path=path,
                link=sensor_link,
            )
    return ArmSelection(base, ee, subtree, chain, sensor_link)


def choose_ee_link(arm: URDFTree, base: str) -> str:
    """Follow the single branch that carries moving joints; stop before grippers."""
    current, last_moving_child = base, None
    while True:
        branches = []
        for joint in arm.children[current]:
            child = arm.child_of(joint)
            moving = arm.is_moving(joint)
            if moving or arm.moving_below(child):
                branches.append((joint, child, moving))
        if len(branches) != 1:
            break
        joint, child, moving = branches[0]
        if moving and is_jaw_name(joint):
            break
        current = child
        if moving:
            last_moving_child = child
    if last_moving_child is None:
        raise ModelError(f"no moving joint below arm_base_link '{base}'", path=str(arm.path))
    return last_moving_child
