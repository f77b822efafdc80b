"""Names in the merged file: the arm's links and joints that clash with the vehicle's or
with the frames the mount adds get the prefix ``arm_``; so do the added frames while the
vehicle already uses their names (a kept arm has its own ``ee``)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.model.trim_urdf import TRIM_LINKS

__all__ = [
    "ADDED_FRAMES",
    "RENAME_PREFIX",
    "added_names",
    "is_mount_joint",
    "original_name",
    "rename_clashes",
    "unique_frame_names",
]

RENAME_PREFIX = "arm_"
#: The links and joints the mount adds (the trim's are in `added_names`).
ADDED_FRAMES = (
    "arm_mount_joint",
    "ft_sensor",
    "ft_sensor_joint",
    "tool",
    "tool_joint",
    "ee",
    "ee_joint",
)


def is_mount_joint(name: str) -> bool:
    """Whether ``name`` is the fixed joint a mount bolted an arm's base with
    (``arm_mount_joint``, or a kept arm's ``arm_arm_mount_joint``...)."""
    return re.fullmatch(f"({RENAME_PREFIX})*arm_mount_joint", name) is not None


def unique_frame_names(taken: set[str]) -> dict[str, str]:
    """The names of the frames the mount adds (``ee``, ``ft_sensor``, ...), prefixed with
    ``arm_`` while the vehicle already uses them (a kept arm has its own)."""
    out = {}
    for name in ADDED_FRAMES:
        new = name
        while new in taken:
            new = RENAME_PREFIX + new
        out[name] = new
    return out


def added_names(*, sensor_link: str | None, with_tool: bool, ee_link: str) -> set[str]:
    """The names the merged file will have that no arm element may keep: the mount joint,
    the trim's links and joints, and the sensor, tool and ee frames that will be added."""
    names = {"arm_mount_joint"} | {n for link in TRIM_LINKS for n in (link, f"{link}_joint")}
    if sensor_link is None:
        names |= {"ft_sensor", "ft_sensor_joint"}
    if with_tool:
        names |= {"tool", "tool_joint", "ee", "ee_joint"}
    elif ee_link != "ee":
        names |= {"ee", "ee_joint"}
    return names


def rename_clashes(
    arm: URDFTree,
    links: list[ET.Element],
    joints: list[ET.Element],
    vehicle_names: set[str],
    reserved: set[str],
) -> dict[str, str]:
    """Rename the arm ``links`` and ``joints`` (copies, changed in place) whose names the
    vehicle uses or that are ``reserved``, and every reference to them (joint parents and
    children, mimic joints); returns old -> new."""
    renamed: dict[str, str] = {}
    for element in links + joints:
        name = element.get("name")
        if name in vehicle_names or name in reserved:
            new = RENAME_PREFIX + name
            while new in vehicle_names or new in arm.links or new in arm.joints:
                new = RENAME_PREFIX + new
            renamed[name] = new
    for element in links + joints:
        if element.get("name") in renamed:
            element.set("name", renamed[element.get("name")])
    for joint in joints:
        for tag in ("parent", "child"):
            el = joint.find(tag)
            el.set("link", renamed.get(el.get("link"), el.get("link")))
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in renamed:
            mimic.set("joint", renamed[mimic.get("joint")])
    return renamed


def original_name(name: str, renamed: dict[str, str]) -> str:
    """The arm file's name of a merged-file name."""
    for old, new in renamed.items():
        if new == name:
            return old
    return name
