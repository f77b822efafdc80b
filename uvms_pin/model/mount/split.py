"""Split a UVMS URDF into a vehicle URDF and an arm URDF (the inverse of `mount_arm`).

Used to mount other arms on the reference vehicle (the LBV150 without its arm) and to check
that mounting the reference arm back gives the reference model. The foam and ballast a mount
trimmed the arm with (`uvms_pin.model.trim_urdf.TRIM_LINKS` on fixed joints of the vehicle)
go to neither file: they balanced that arm, and another arm is trimmed for itself.
"""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.mount.existing_arm import mount_trim
from uvms_pin.model.mount.names import is_mount_joint
from uvms_pin.model.mount.origin import origin_of
from uvms_pin.model.mount.text import urdf_text, write_text_file
from uvms_pin.model.mount.tree import URDFTree

__all__ = ["SplitURDF", "split_urdf"]

ARM_MOUNT_LINK = "arm_mount"


@dataclass(frozen=True)
class SplitURDF:
    """Paths of the two files and the arm's mount pose in the vehicle link."""

    vehicle_urdf: Path
    arm_urdf: Path
    vehicle_link: str  # the vehicle's root link, which mount_pose is in
    mount_pose: pin.SE3
    trim_links: tuple[str, ...] = ()  # the mount's trim, left out of both files


def split_urdf(
    urdf: str | Path,
    out_dir: str | Path,
    first_arm_joint: str | None = None,
) -> SplitURDF:
    """Write ``vehicle.urdf`` (everything but the arm and its trim) and ``arm.urdf`` into
    ``out_dir``. The arm is everything below ``first_arm_joint`` (default: the moving joint
    nearest the vehicle; ModelError where there are several or none) or, in a file `mount_arm`
    wrote, below the fixed joint above it that bolted the arm's base (`is_mount_joint`).

    The arm file's root is an empty link ``arm_mount`` at the first arm joint's origin, so
    mounting it at ``mount_pose`` (in the vehicle's root link, through the fixed joints
    between that link and the first arm joint's parent) rebuilds the same kinematics.
    Top-level ``<hydrodynamics link=...>`` elements follow their link. Mesh paths are made
    absolute.
    """
    path = Path(urdf)
    tree = URDFTree.read(path)
    if first_arm_joint is None:
        first_arm_joint = _first_moving_joint(tree, path)
    if first_arm_joint not in tree.joints:
        raise ModelError(
            f"joint '{first_arm_joint}' not found (joints: {', '.join(tree.joints) or 'none'})",
            path=str(path),
        )
    # a mount's file: the arm from the joint that bolted its base (the base is the arm's)
    above = tree.path_joints(tree.root_link, tree.parent_of(first_arm_joint))
    split_at = next((name for name in above if is_mount_joint(name)), first_arm_joint)
    joint = tree.joints[split_at]
    vehicle_link = tree.root_link
    arm_links = set(tree.subtree(tree.child_of(split_at)))
    trim = tuple(mount_trim(tree))
    dropped = {*trim, *(tree.parent_joint[link] for link in trim)}
    mount = _placement_in_root(tree, tree.parent_of(split_at), path) * origin_of(joint, path)

    vehicle = ET.Element("robot", {"name": tree.root.get("name", "robot") + "_vehicle"})
    arm = ET.Element("robot", {"name": tree.root.get("name", "robot") + "_arm"})
    ET.SubElement(arm, "link", {"name": ARM_MOUNT_LINK})
    for element in tree.root:
        if element.tag in ("link", "joint", "hydrodynamics") and (
            element.get("name") in dropped or element.get("link") in dropped
        ):
            continue
        item = copy.deepcopy(element)
        for mesh in item.iter("mesh"):
            filename = mesh.get("filename", "")
            if filename and "://" not in filename and not Path(filename).is_absolute():
                mesh.set("filename", str((path.parent / filename).resolve()))
        if element.tag == "link":
            (arm if element.get("name") in arm_links else vehicle).append(item)
        elif element.tag == "joint":
            child = element.find("child").get("link")
            if element.get("name") == split_at:
                item.find("parent").set("link", ARM_MOUNT_LINK)
                origin = item.find("origin")
                if origin is not None:
                    item.remove(origin)
                arm.append(item)
            else:
                (arm if child in arm_links else vehicle).append(item)
        elif element.tag == "hydrodynamics":
            (arm if element.get("link") in arm_links else vehicle).append(item)
        else:
            vehicle.append(item)
            if element.tag == "material":
                arm.append(copy.deepcopy(element))
    out = Path(out_dir)
    vehicle_path, arm_path = out / "vehicle.urdf", out / "arm.urdf"
    for root, target in ((vehicle, vehicle_path), (arm, arm_path)):
        write_text_file(target, urdf_text(root))
    return SplitURDF(vehicle_path, arm_path, vehicle_link, mount, trim)


def _placement_in_root(tree: URDFTree, link: str, path: Path) -> pin.SE3:
    """Where ``link`` is in the root link's frame, through the fixed joints between them (an
    arm's base bracket: the Alpha 5's ``alpha_base_link``); ModelError if one of them moves
    (then the joint split at is not the arm's first)."""
    placement = pin.SE3.Identity()
    for name in tree.path_joints(tree.root_link, link):
        if tree.is_moving(name):
            raise ModelError(
                f"the arm's first joint hangs below the moving joint '{name}': split at the "
                "first moving joint from the vehicle",
                path=str(path),
            )
        placement = placement * origin_of(tree.joints[name], path)
    return placement


def _first_moving_joint(tree: URDFTree, path: Path) -> str:
    """The one moving joint without a moving joint above it (an arm's first joint)."""
    first = [n for n in tree.joint_order if tree.is_moving(n) and not tree.moving_above(n)]
    if len(first) != 1:
        found = ", ".join(first) if first else "none: a vehicle alone"
        raise ModelError(
            f"split needs the arm's first joint: give first_arm_joint (moving joints nearest "
            f"the vehicle: {found})",
            path=str(path),
        )
    return first[0]
