"""The kinematic tree of a URDF ``<robot>``: each link's placement in the root link's frame."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.read import read_numbers, read_origin

__all__ = ["fix_immobile_joints", "hold_uuv_fins", "link_placements", "make_fixed", "root_link"]


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


def axis_of(joint: ET.Element, where: str) -> np.ndarray:
    """A joint's unit axis in its (child link's) frame; URDF's default is x. ModelError
    naming the joint, its link and the file ``where`` unless it is a direction."""
    axis = joint.find("axis")
    text = axis.get("xyz", "1 0 0") if axis is not None else "1 0 0"
    name, child = joint.get("name"), joint.find("child").get("link")
    values = read_numbers(text, 3, f"joint '{name}' <axis xyz>", where, child)
    norm = float(np.linalg.norm(values))
    if not norm > 0.0:
        raise ModelError(
            f"joint '{name}': its axis must be a direction, not zero ('{text}')",
            path=where,
            link=child,
        )
    return values / norm


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
            make_fixed(joint)


def make_fixed(joint: ET.Element) -> None:
    """``joint`` as a fixed joint where it stands (its origin kept; limit, axis, dynamics and
    mimic dropped)."""
    joint.set("type", "fixed")
    for child in [c for c in joint if c.tag in ("limit", "axis", "dynamics", "mimic")]:
        joint.remove(child)


def hold_uuv_fins(robot: ET.Element, fins: list[ET.Element], notes: list[str]) -> None:
    """uuv_simulator's Fin plugins (``fins``): each sets its joint to the commanded angle
    itself (first-order toward it; 0 without a command), so the joint is no degree of freedom
    of the dynamics: written fixed at 0 (a free fin link of no inertia would make the mass
    matrix singular), said in ``notes``. Their lift and drag: `add_fins`."""
    joints = {j.get("name"): j for j in robot.findall("joint")}
    for plugin in fins:
        name = (plugin.findtext("joint_name") or "").strip()
        joint = joints.get(name)
        if joint is None:
            notes.append(f"fin plugin '{plugin.get('name')}': no joint {name!r} in the model")
            continue
        if joint.get("type") != "fixed":
            make_fixed(joint)
        notes.append(
            f"fin joint '{name}': uuv_simulator's Fin plugin sets its angle (0 without a "
            "command): written fixed at 0, the fin's deflection not commandable"
        )
