"""The arm's joints as a UVMS needs them: the joints from the arm base to the wrist move
(continuous ones become revolute with limits +-2 pi, so q has one angle per joint, as the
rest of uvms-pin assumes); every other moving joint (gripper fingers, a second branch) is
locked, made fixed at its lock position."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.origin import origin_of, set_origin, vector_attribute
from uvms_pin.model.mount.tree import MOVING_JOINT_TYPES

__all__ = ["CONTINUOUS_LIMIT_RAD", "lock_joint", "prepare_arm_joints"]

#: Limits of a continuous joint of the chain once revolute [rad].
CONTINUOUS_LIMIT_RAD = 2.0 * math.pi


def prepare_arm_joints(
    joints: list[ET.Element],
    chain: list[str],
    lock_positions: Mapping[str, float],
    path: Path,
) -> dict[str, float]:
    """Convert the arm ``joints`` (copies, changed in place): those of ``chain`` keep moving
    (mimic dropped, continuous made revolute), the other moving ones are locked at
    ``lock_positions[name]`` (default 0 clipped into the limits). Returns name -> position
    locked at [rad or m].

    Raises:
        ModelError: a floating, planar or unknown joint type; a continuous chain joint
            without <limit effort velocity>.
        ParameterError: a lock position outside the joint's limits.
    """
    locked: dict[str, float] = {}
    for joint in joints:
        name = joint.get("name")
        kind = joint.get("type")
        if kind in ("floating", "planar"):
            raise ModelError(
                f"joint '{name}' is {kind}: an arm may only have revolute, continuous, "
                "prismatic and fixed joints",
                path=str(path),
            )
        if kind not in MOVING_JOINT_TYPES and kind != "fixed":
            raise ModelError(f"joint '{name}' has unknown type '{kind}'", path=str(path))
        if name in chain:
            _keep_moving(joint, path)
        elif kind in MOVING_JOINT_TYPES:
            locked[name] = lock_joint(joint, lock_positions.get(name), path)
    return locked


def _keep_moving(joint: ET.Element, path: Path) -> None:
    """A chain joint moves on its own (no mimic), with one angle (continuous -> revolute)."""
    if joint.find("mimic") is not None:
        joint.remove(joint.find("mimic"))
    if joint.get("type") == "continuous":
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            raise ModelError(
                f"continuous joint '{joint.get('name')}' has no <limit effort velocity>",
                path=str(path),
            )
        limit.set("lower", repr(-CONTINUOUS_LIMIT_RAD))
        limit.set("upper", repr(CONTINUOUS_LIMIT_RAD))


def lock_joint(joint: ET.Element, position: float | None, path: Path) -> float:
    """Make a moving joint fixed at ``position`` [rad or m] (default 0 clipped into its
    limits): its motion at that position is folded into its <origin>. Returns the position."""
    name = joint.get("name")
    limit = joint.find("limit")
    lower = -math.inf if limit is None else float(limit.get("lower", "-inf"))
    upper = math.inf if limit is None else float(limit.get("upper", "inf"))
    if joint.get("type") == "continuous":
        lower, upper = -math.inf, math.inf
    value = float(np.clip(0.0 if position is None else position, lower, upper))
    if position is not None and not (math.isfinite(position) and lower <= position <= upper):
        raise ParameterError(
            f"lock position {position} of joint '{name}' is outside its limits [{lower}, {upper}]"
        )
    axis = vector_attribute(joint.find("axis"), "xyz", "1 0 0", path, name)
    axis = axis / np.linalg.norm(axis)
    origin = origin_of(joint, path)
    if joint.get("type") == "prismatic":
        motion = pin.SE3(np.eye(3), axis * value)
    else:
        motion = pin.SE3(pin.exp3(axis * value), np.zeros(3))
    set_origin(joint, origin * motion)
    joint.set("type", "fixed")
    for tag in ("limit", "mimic", "dynamics", "safety_controller", "calibration", "axis"):
        for element in joint.findall(tag):
            joint.remove(element)
    return value
