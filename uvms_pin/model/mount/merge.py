"""Two URDF files, a vehicle and an arm, merged into one tree (steps 1-6 of
`uvms_pin.model.mount.mount`): the vehicle (without the arm it may carry), the arm's subtree
below its base with its joints prepared and its clashing names renamed, the fixed joint at
the mount pose, and the sensor, tool and end-effector frames."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from uvms_pin.checks import flag, number
from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.jaw import is_jaw_name
from uvms_pin.model.mount.existing_arm import existing_arm
from uvms_pin.model.mount.hull import first_box
from uvms_pin.model.mount.joints import prepare_arm_joints
from uvms_pin.model.mount.links import mark_dry_links, resolve_meshes, strip_undefined_materials
from uvms_pin.model.mount.names import (
    added_names,
    original_name,
    rename_clashes,
    unique_frame_names,
)
from uvms_pin.model.mount.origin import add_fixed_joint
from uvms_pin.model.mount.pose import parse_mount_pose
from uvms_pin.model.mount.selection import ArmSelection, select_arm
from uvms_pin.model.mount.tool import (
    REFERENCE_PROBE,
    ProbeTool,
    add_tool_frames,
    tool_axis_in_link,
)
from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.model.resources import package_folders

__all__ = ["ArmMerge", "MergedURDF", "merge_urdf"]

#: The vehicle's top-level elements that are kept (``<transmission>``, ``<gazebo>``, ... go).
_KEEP_TOP_LEVEL = ("link", "joint", "material", "hydrodynamics")


@dataclass(kw_only=True)
class ArmMerge:
    """What the merge did with the arm.

    Attributes:
        arm_joints: the arm's moving joints, base to wrist (merged-model names).
        locked_joints: joints made fixed, with the position they were locked at [rad or m].
        renamed: arm names changed to avoid clashes with the vehicle (old -> new).
        arm_base_link, ee_link: the links used (arm file names).
        tool_axis_in_ee_link: unit vector of the tool axis in ``ee_link``'s frame.
        dry_links: arm links with mass but neither hydrodynamics nor collision geometry.
        removed_links, removed_joints: the arm the vehicle file carried, replaced (empty
            for a vehicle alone or with ``keep_existing_arm=True``).
    """

    arm_joints: list[str]
    locked_joints: dict[str, float]
    renamed: dict[str, str]
    arm_base_link: str
    ee_link: str
    tool_axis_in_ee_link: np.ndarray
    dry_links: list[str] = field(default_factory=list)
    removed_links: list[str] = field(default_factory=list)
    removed_joints: list[str] = field(default_factory=list)


@dataclass(kw_only=True)
class MergedURDF(ArmMerge):
    """The merged tree and what :func:`mount_arm_detailed` needs to load it."""

    root: ET.Element
    ee_frame: str
    sensor_frame: str
    vehicle_link: str
    hull_box: tuple[np.ndarray, np.ndarray] | None


def merge_urdf(
    vehicle_urdf: str | Path,
    arm_urdf: str | Path,
    mount_pose,
    *,
    arm_base_link: str | None = None,
    ee_link: str | None = None,
    vehicle_link: str | None = None,
    sensor_link: str | None = None,
    tool_axis: str | Sequence[float] = "auto",
    tool: ProbeTool | None = REFERENCE_PROBE,
    lock_positions: Mapping[str, float] | None = None,
    package_dirs: Sequence[str | Path] = (),
    allow_dry_links: bool = False,
    keep_existing_arm: bool = False,
    moving_jaw: bool = False,
) -> MergedURDF:
    """Build the merged URDF tree (steps 1-6 of `uvms_pin.model.mount.mount`); nothing is
    written. The arguments before ``*`` are :func:`uvms_pin.model.mount.mount.mount_arm`'s.

    Args:
        arm_base_link: the arm link bolted to the vehicle (default: the arm's root).
        ee_link: the wrist/flange link carrying the F/T sensor (default: chosen, see
            `uvms_pin.model.mount.mount`).
        vehicle_link: vehicle link the arm is bolted to (default: the vehicle's root).
        sensor_link: an existing arm link to use as the F/T sensor frame (then no
            ``ft_sensor`` frame is added; with ``tool=None`` and an ``ee_link`` named as
            the end-effector frame, an arm file that already has both is used as it is).
        tool_axis: the tool direction in ``ee_link``'s frame: "x", "-z", ..., a 3-vector,
            or "auto" (the last arm joint's axis, pointing away from the arm).
        tool: the probe to add (None: no tool, ``ee`` = the sensor frame).
        lock_positions: positions of the joints that are locked (default 0, clipped).
        package_dirs: where ``package://`` mesh paths are found.
        allow_dry_links: accept arm links with mass but neither hydrodynamics nor collision
            geometry (they weigh but displace nothing; else ``load_uvms`` rejects them).
        keep_existing_arm: keep an arm the vehicle file already carries (default: replace it).
        moving_jaw: keep the jaw's joints below ``ee_link`` moving (named by the rule of
            `uvms_pin.model.jaw`; their <mimic> dropped: each finger is its own joint)
            instead of locking them.
    """
    placement = parse_mount_pose(mount_pose)
    allow_dry_links = flag("allow_dry_links", allow_dry_links)
    keep_existing_arm = flag("keep_existing_arm", keep_existing_arm)
    moving_jaw = flag("moving_jaw", moving_jaw)
    package_dirs = package_folders(package_dirs)
    vehicle = URDFTree.read(Path(vehicle_urdf))
    arm = URDFTree.read(Path(arm_urdf))
    removed_links, removed_joints = ([], []) if keep_existing_arm else existing_arm(vehicle)
    vlink = _vehicle_link(vehicle, vehicle_link, removed_links)
    selection = select_arm(arm, arm_base_link, ee_link, sensor_link)
    axis = tool_axis_in_link(arm, tool_axis, selection.chain, selection.ee, arm.path)
    locks = _lock_positions(arm, lock_positions)
    arm_links, arm_joints = _arm_copies(arm, selection)
    jaw = [j.get("name") for j in arm_joints if moving_jaw and is_jaw_name(j.get("name"))]
    jaw = [j for j in jaw if arm.is_moving(j)]
    locked = prepare_arm_joints(arm_joints, selection.chain + jaw, locks, arm.path)

    vehicle_names = (set(vehicle.links) | set(vehicle.joints)) - set(removed_links + removed_joints)
    frames = unique_frame_names(vehicle_names)
    reserved = added_names(
        sensor_link=selection.sensor_link, with_tool=tool is not None, ee_link=selection.ee
    )
    renamed = rename_clashes(arm, arm_links, arm_joints, vehicle_names, reserved)

    name = f"{vehicle.root.get('name', 'vehicle')}+{arm.root.get('name', 'arm')}"
    out = ET.Element("robot", {"name": name})
    materials = _copy_vehicle(out, vehicle, set(removed_links) | set(removed_joints), package_dirs)
    _copy_arm_links(out, arm, arm_links, renamed, materials, package_dirs)
    dry = mark_dry_links(arm_links, arm, renamed, allow_dry_links)
    _copy_arm_hydrodynamics(out, arm, selection.subtree, renamed)
    out.extend(arm_joints)
    base_new = renamed.get(selection.base, selection.base)
    add_fixed_joint(out, frames["arm_mount_joint"], vlink, base_new, placement)
    sensor = selection.sensor_link
    sensor_new = None if sensor is None else renamed.get(sensor, sensor)
    ee_new = renamed.get(selection.ee, selection.ee)
    sensor_frame, ee_frame = add_tool_frames(out, frames, ee_new, sensor_new, tool, axis)
    return MergedURDF(
        root=out,
        ee_frame=ee_frame,
        sensor_frame=sensor_frame,
        vehicle_link=vlink,
        arm_joints=[renamed.get(j, j) for j in selection.chain + jaw],
        locked_joints={renamed.get(k, k): v for k, v in locked.items()},
        renamed=renamed,
        arm_base_link=selection.base,
        ee_link=selection.ee,
        tool_axis_in_ee_link=axis,
        dry_links=dry,
        hull_box=first_box(vehicle.links[vlink]),
        removed_links=removed_links,
        removed_joints=removed_joints,
    )


def _vehicle_link(vehicle: URDFTree, vehicle_link: str | None, removed_links: list[str]) -> str:
    """The vehicle link the arm is bolted to (default: the root), not one being replaced."""
    vlink = (
        vehicle.root_link
        if vehicle_link is None
        else vehicle.require_link(vehicle_link, "vehicle_link")
    )
    if vlink in removed_links:
        raise ModelError(
            f"vehicle_link '{vlink}' belongs to the arm the vehicle file already carries, which "
            "is replaced (pass keep_existing_arm=True to mount on it)",
            path=str(vehicle.path),
            link=vlink,
        )
    return vlink


def _lock_positions(arm: URDFTree, lock_positions: Mapping[str, float] | None) -> dict:
    """``lock_positions`` as a dict of numbers, every name a joint of the arm file."""
    if lock_positions is not None and not isinstance(lock_positions, Mapping):
        raise ParameterError(
            f"lock_positions must be a dict of joint name -> position, got {lock_positions!r}"
        )
    locks = {
        name: number(f"lock_positions[{name!r}]", x) for name, x in (lock_positions or {}).items()
    }
    unknown = sorted(set(locks) - set(arm.joints))
    if unknown:
        raise ModelError(
            f"lock_positions names unknown joint(s): {', '.join(unknown)}", path=str(arm.path)
        )
    return locks


def _arm_copies(
    arm: URDFTree, selection: ArmSelection
) -> tuple[list[ET.Element], list[ET.Element]]:
    """Copies of the links of the mounted subtree and of the joints below its base."""
    links = [copy.deepcopy(arm.links[n]) for n in arm.link_order if n in selection.subtree]
    joints = [
        copy.deepcopy(arm.joints[n])
        for n in arm.joint_order
        if arm.child_of(n) in selection.subtree and arm.child_of(n) != selection.base
    ]
    return links, joints


def _copy_vehicle(
    out: ET.Element, vehicle: URDFTree, dropped: set[str], package_dirs: Sequence[str | Path]
) -> set[str]:
    """Append the vehicle's links, joints, materials and hydrodynamics, mesh paths made
    absolute, except the ``dropped`` names (the replaced arm, top-level
    ``<hydrodynamics link=...>`` included); returns the names of the materials."""
    materials: set[str] = set()
    for element in vehicle.root:
        if element.get("name") in dropped or element.get("link") in dropped:
            continue
        if element.tag in _KEEP_TOP_LEVEL:
            item = copy.deepcopy(element)
            if item.tag == "material":
                materials.add(item.get("name"))
            resolve_meshes(item, vehicle.path, package_dirs, needs_collision=False)
            out.append(item)
    return materials


def _copy_arm_links(
    out: ET.Element,
    arm: URDFTree,
    links: list[ET.Element],
    renamed: dict[str, str],
    materials: set[str],
    package_dirs: Sequence[str | Path],
) -> None:
    """Append the arm's materials the vehicle does not define (added to ``materials``), then
    its ``links``, mesh paths made absolute: a collision mesh must be found unless the link
    has hydrodynamics."""
    for element in arm.root:
        if element.tag == "material" and element.get("name") not in materials:
            out.append(copy.deepcopy(element))
            materials.add(element.get("name"))
    top_level = arm.root.findall("hydrodynamics")
    for link in links:
        name = original_name(link.get("name"), renamed)
        has_hydro = link.find("hydrodynamics") is not None or any(
            h.get("link") == name for h in top_level
        )
        resolve_meshes(link, arm.path, package_dirs, needs_collision=not has_hydro, link_name=name)
        strip_undefined_materials(link, materials)
        out.append(link)


def _copy_arm_hydrodynamics(
    out: ET.Element, arm: URDFTree, subtree: list[str], renamed: dict[str, str]
) -> None:
    """Append the arm's top-level ``<hydrodynamics link=...>`` of mounted links, renamed."""
    for element in arm.root.findall("hydrodynamics"):
        if element.get("link") in subtree:
            item = copy.deepcopy(element)
            item.set("link", renamed.get(item.get("link"), item.get("link")))
            out.append(item)
