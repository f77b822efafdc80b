"""The kinematic tree of a URDF ``<robot>``: each link's placement in the root link's frame."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.read import read_origin

__all__ = ["fix_immobile_joints", "link_placements", "root_link"]


def root_link(robot: ET.Element, where: str) -> str:
    """The one link that is no joint's child."""
    children = {
        j.find("child").get("link") for j in robot.findall("joint") if j.find("child") is not None
    }
    roots = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise ModelError(f"needs exactly one root link, found {roots}", path=where)
    return roots[0]


def link_placements(robot: ET.Element, where: str) -> dict[str, pin.SE3]:
    """X_root_link for every link reachable from the root, at zero joint positions."""
    by_parent: dict[str, list[ET.Element]] = {}
    for joint in robot.findall("joint"):
        parent = joint.find("parent")
        if parent is None or joint.find("child") is None:
            raise ModelError(f"joint '{joint.get('name')}' needs <parent> and <child>", path=where)
        by_parent.setdefault(parent.get("link"), []).append(joint)
    root = root_link(robot, where)
    placements = {root: pin.SE3.Identity()}
    stack = [root]
    while stack:
        parent = stack.pop()
        for joint in by_parent.get(parent, []):
            child = joint.find("child").get("link")
            placements[child] = placements[parent] * read_origin(
                joint.find("origin"), where, f"joint {joint.get('name')}"
            )
            stack.append(child)
    return placements


def axis_of(joint: ET.Element) -> np.ndarray:
    """A joint's unit axis in its (child link's) frame; URDF's default is x."""
    axis = joint.find("axis")
    values = np.array(
        [float(v) for v in (axis.get("xyz", "1 0 0") if axis is not None else "1 0 0").split()]
    )
    return values / np.linalg.norm(values)


def fix_immobile_joints(robot: ET.Element, notes: list[str]) -> None:
    """Joints that cannot move become fixed joints, said so in ``notes``: a ``revolute`` or
    ``prismatic`` joint whose ``<limit>`` has lower = upper (a simulator's sensor mount,
    written as a joint of limits 0 to 0) would otherwise be a degree of freedom without
    inertia behind it: a singular mass matrix."""
    for joint in robot.findall("joint"):
        limit = joint.find("limit")
        if joint.get("type") not in ("revolute", "prismatic") or limit is None:
            continue
        lower, upper = limit.get("lower"), limit.get("upper")
        try:
            immobile = lower is not None and upper is not None and float(lower) == float(upper)
        except ValueError:  # not numbers: the loader names them
            continue
        if immobile:
            notes.append(
                f"joint '{joint.get('name')}': {joint.get('type')} with limits {lower} to "
                f"{upper} cannot move; written as a fixed joint"
            )
            joint.set("type", "fixed")
            for child in [c for c in joint if c.tag in ("limit", "axis", "dynamics", "mimic")]:
                joint.remove(child)
