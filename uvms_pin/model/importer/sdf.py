"""An SDF ``<model>`` as a URDF ``<robot>`` tree (links, inertials, collision primitives,
joints), so that one writer and one loader serve both formats.

SDF places a link in the model frame (``<link><pose>``) and a joint in its child link's
frame; URDF places the child in the parent's frame through the joint. The joint origin is
X_parent^-1 X_child; a joint with its own non-zero ``<pose>`` has no URDF counterpart and
is refused. A joint axis is in the child frame (SDF 1.7+, and 1.6 without
``<use_parent_model_frame>``), or in the model frame when that flag is true.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.results.format import numbers_text

__all__ = ["sdf_model", "sdf_to_urdf"]

_JOINT_TYPES = {"revolute", "prismatic", "fixed", "continuous"}
#: what a URDF effort or velocity limit of "-1" (SDF: unlimited) is written as
UNLIMITED = 1e6


def sdf_model(root: ET.Element, where: str) -> ET.Element:
    """The one ``<model>`` with links in an ``<sdf>`` file (at the top or in a world)."""
    models = [m for m in root.iter("model") if m.find("link") is not None]
    if len(models) != 1:
        names = [m.get("name") for m in root.iter("model")]
        raise ModelError(
            f"needs exactly one <model> with <link>s, found {len(models)} (models: {names}); "
            'a model nested in another is not supported: include it with merge="true"',
            path=where,
        )
    return models[0]


def sdf_pose(element: ET.Element | None, where: str, what: str) -> pin.SE3:
    """The placement of a ``<pose>`` child: x y z roll pitch yaw [m, rad or degrees]."""
    pose = None if element is None else element.find("pose")
    if pose is None or not (pose.text or "").strip():
        return pin.SE3.Identity()
    frame = pose.get("relative_to")
    if frame:
        raise ModelError(f"{what}: <pose relative_to='{frame}'> is not supported", path=where)
    try:
        values = np.array([float(v) for v in pose.text.split()])
    except ValueError as exc:
        raise ModelError(f"{what}: <pose> is not numeric: '{pose.text}'", path=where) from exc
    if values.size != 6:
        raise ModelError(f"{what}: <pose> needs 6 numbers, got {values.size}", path=where)
    if pose.get("degrees", "false").lower() == "true":
        values[3:] = np.radians(values[3:])
    return pin.SE3(pin.rpy.rpyToMatrix(*values[3:]), values[:3])


def _origin(parent: ET.Element, placement: pin.SE3) -> None:
    rpy = pin.rpy.matrixToRpy(placement.rotation)
    ET.SubElement(parent, "origin", xyz=numbers_text(placement.translation), rpy=numbers_text(rpy))


def sdf_to_urdf(model: ET.Element, where: str, notes: list[str]) -> ET.Element:
    """The URDF ``<robot>`` of an SDF model."""
    robot = ET.Element("robot", name=model.get("name", "model"))
    link_poses = {}
    for link in model.findall("link"):
        name = link.get("name")
        link_poses[name] = sdf_pose(link, where, f"link '{name}'")
        robot.append(_link(link, where, notes))
    for joint in model.findall("joint"):
        robot.append(_joint(joint, link_poses, where, notes))
    return robot


def _link(link: ET.Element, where: str, notes: list[str]) -> ET.Element:
    name = link.get("name")
    out = ET.Element("link", name=name)
    inertial = link.find("inertial")
    if inertial is not None:
        element = ET.SubElement(out, "inertial")
        _origin(element, sdf_pose(inertial, where, f"link '{name}' <inertial>"))
        ET.SubElement(element, "mass", value=(inertial.findtext("mass") or "1").strip())
        inertia = inertial.find("inertia")
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        values = {
            k: (inertia.findtext(k) or "0").strip() if inertia is not None else "0" for k in keys
        }
        ET.SubElement(element, "inertia", **values)
        if inertial.find("fluid_added_mass") is not None:
            notes.append(
                f"link '{name}': <fluid_added_mass> not mapped (use the Hydrodynamics system)"
            )
    for collision in link.findall("collision"):
        geometry = _geometry(collision.find("geometry"), where, name, notes)
        if geometry is not None:
            element = ET.SubElement(out, "collision")
            _origin(element, sdf_pose(collision, where, f"link '{name}' <collision>"))
            element.append(geometry)
    return out


def _geometry(
    geometry: ET.Element | None, where: str, link: str, notes: list[str]
) -> ET.Element | None:
    """A URDF ``<geometry>`` of an SDF box, sphere, cylinder or mesh; None (noted) otherwise."""
    out = ET.Element("geometry")
    shape = None if geometry is None else next(iter(geometry), None)
    if shape is None:
        return None
    if shape.tag == "box":
        ET.SubElement(out, "box", size=(shape.findtext("size") or "").strip())
    elif shape.tag == "sphere":
        ET.SubElement(out, "sphere", radius=(shape.findtext("radius") or "").strip())
    elif shape.tag == "cylinder":
        radius, length = shape.findtext("radius"), shape.findtext("length")
        ET.SubElement(out, "cylinder", radius=(radius or "").strip(), length=(length or "").strip())
    elif shape.tag == "mesh":
        attributes = {"filename": (shape.findtext("uri") or "").strip()}
        if shape.findtext("scale"):
            attributes["scale"] = shape.findtext("scale").strip()
        ET.SubElement(out, "mesh", **attributes)
    else:
        notes.append(f"link '{link}': collision <{shape.tag}> not mapped (no URDF primitive)")
        return None
    return out


def _joint(
    joint: ET.Element, link_poses: dict[str, pin.SE3], where: str, notes: list[str]
) -> ET.Element:
    name, kind = joint.get("name"), joint.get("type")
    if kind not in _JOINT_TYPES:
        raise ModelError(f"joint '{name}': type '{kind}' has no URDF counterpart", path=where)
    if not sdf_pose(joint, where, f"joint '{name}'").isIdentity():
        raise ModelError(
            f"joint '{name}': a <pose> off its child link is not supported", path=where
        )
    parent, child = (
        (joint.findtext("parent") or "").strip(),
        (joint.findtext("child") or "").strip(),
    )
    for end in (parent, child):
        if end not in link_poses:
            raise ModelError(f"joint '{name}': no link '{end}' in the model", path=where)
    out = ET.Element("joint", name=name, type=kind)
    _origin(out, link_poses[parent].inverse() * link_poses[child])
    ET.SubElement(out, "parent", link=parent)
    ET.SubElement(out, "child", link=child)
    axis = joint.find("axis")
    if axis is not None and kind != "fixed":
        _axis(out, axis, link_poses[child], where, name, notes)
    return out


def _joint_numbers(text: str, count: int, where: str, what: str) -> np.ndarray:
    """``count`` finite numbers of ``text``, or a ModelError naming the file and ``what``."""
    try:
        values = np.array([float(v) for v in text.split()])
    except ValueError:
        values = np.array([])
    if values.size != count or not np.all(np.isfinite(values)):
        raise ModelError(f"{what} must be {count} finite numbers, got '{text.strip()}'", path=where)
    return values


def _axis(
    out: ET.Element, axis: ET.Element, child_pose: pin.SE3, where: str, name: str, notes: list[str]
) -> None:
    xyz = axis.find("xyz")
    if xyz is not None and xyz.get("expressed_in"):
        raise ModelError(f"joint '{name}': <xyz expressed_in> is not supported", path=where)
    direction = _joint_numbers(axis.findtext("xyz") or "0 0 1", 3, where, f"joint '{name}': <xyz>")
    if (axis.findtext("use_parent_model_frame") or "").strip().lower() in ("1", "true"):
        direction = child_pose.rotation.T @ direction
    ET.SubElement(out, "axis", xyz=numbers_text(direction))
    limit = axis.find("limit")
    if limit is None:
        return
    values = {}
    for key, default in (
        ("lower", -math.pi),
        ("upper", math.pi),
        ("effort", UNLIMITED),
        ("velocity", UNLIMITED),
    ):
        text = limit.findtext(key)
        value = (
            default
            if text is None
            else float(_joint_numbers(text, 1, where, f"joint '{name}': <{key}>")[0])
        )
        if key in ("effort", "velocity") and value < 0.0:
            notes.append(
                f"joint '{name}': {key} limit {value:g} (unlimited) written as {UNLIMITED:g}"
            )
            value = UNLIMITED
        values[key] = repr(value)
    ET.SubElement(out, "limit", **values)
