"""The arm a vehicle file already carries (``models/uvms_lbv150.urdf``), which a mount
replaces unless asked to keep it, with the trim a mount added for it."""

from __future__ import annotations

from uvms_pin.model.mount.names import is_mount_joint
from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.model.trim_urdf import TRIM_LINKS

__all__ = ["existing_arm", "mount_trim"]

#: Frames of a mounted arm that hang where the tool is, whatever the arm.
_MOUNT_FRAMES = ("ft_sensor", "tool", "ee")


def existing_arm(vehicle: URDFTree) -> tuple[list[str], list[str]]:
    """(links, joints) of the arm a vehicle file already carries: everything below each
    first moving joint (one without a moving joint above it) and below the joint a mount
    bolted an arm's base with (`is_mount_joint`: the base, e.g. the Alpha 5's
    ``alpha_base_link``, is the arm's), the ``ft_sensor``, ``tool`` and ``ee`` frames
    wherever they hang and, with an arm, the foam and ballast a mount trimmed it with
    (`TRIM_LINKS`, fixed to the vehicle: they balanced that arm); empty for a vehicle
    alone."""
    starts = [
        vehicle.child_of(name)
        for name in vehicle.joint_order
        if (vehicle.is_moving(name) or is_mount_joint(name)) and not vehicle.moving_above(name)
    ]
    starts += [f for f in _MOUNT_FRAMES if f in vehicle.parent_joint]
    if starts:
        starts += mount_trim(vehicle)
    links: set[str] = set()
    for start in starts:
        links.update(vehicle.subtree(start))
    ordered_links = [n for n in vehicle.link_order if n in links]
    joints = [n for n in vehicle.joint_order if vehicle.child_of(n) in links]
    return ordered_links, joints


def mount_trim(tree: URDFTree) -> list[str]:
    """The foam and ballast links a mount trimmed an arm with: `TRIM_LINKS` hanging by a
    fixed joint from the vehicle (no moving joint above it)."""
    return [
        link
        for link in TRIM_LINKS
        if link in tree.parent_joint
        and not tree.is_moving(tree.parent_joint[link])
        and not tree.moving_above(tree.parent_joint[link])
    ]
