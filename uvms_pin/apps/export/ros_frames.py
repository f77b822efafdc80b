"""The robot's links as a ROS transform tree, from the model's kinematics.

Every link of the URDF (a Pinocchio BODY frame) and every named frame of the model (``ee``,
``ft_sensor``: OP frames) becomes a TF frame of its name; a link's parent is the link of its
joint's parent (as robot_state_publisher does), a named frame's the link it is fixed to. The vehicle's
root link hangs from ``odom`` (REP 105: ``map`` -> ``odom`` -> the vehicle). A link whose
joint to its parent is fixed never moves relative to it: it goes to ``/tf_static``.

The project's frames are already ROS's (REP 103): world z up, vehicle body x forward,
y left, z up; nothing is turned.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

__all__ = ["LinkTree", "relative_placements"]

ODOM = "odom"


@dataclass(frozen=True)
class LinkTree:
    """The links of a model as (parent, child) frame pairs.

    Attributes:
        children: each link's frame id in the model (BODY and OP frames, model order).
        names: each link's name (its TF frame). parents: its parent's TF frame.
        parent_ids: its parent's frame id (-1: the root, whose parent is ``odom``).
        moving: whether a moving joint lies between the link and its parent.
    """

    children: tuple[int, ...]
    names: tuple[str, ...]
    parents: tuple[str, ...]
    parent_ids: tuple[int, ...]
    moving: tuple[bool, ...]

    @classmethod
    def of(cls, model: pin.Model) -> LinkTree:
        rows = []
        for fid, frame in enumerate(model.frames):
            if frame.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
                continue
            parent, moving = _parent_body(model, fid)
            parent_name = ODOM if parent < 0 else model.frames[parent].name
            rows.append((fid, frame.name, parent_name, parent, moving))
        if not rows:
            return cls((), (), (), (), ())
        return cls(*map(tuple, zip(*rows, strict=True)))


def _parent_body(model: pin.Model, fid: int) -> tuple[int, bool]:
    """The BODY frame above frame ``fid`` (-1: none, the universe) and whether a moving
    joint (a JOINT frame) lies between them."""
    moving = False
    current = model.frames[fid].parentFrame
    while True:
        frame = model.frames[current]
        if frame.type == pin.FrameType.JOINT:
            moving = True
        if current == 0 or frame.type == pin.FrameType.BODY:
            return (-1 if current == 0 else current), moving
        current = frame.parentFrame


def relative_placements(
    model: pin.Model, data: pin.Data, tree: LinkTree, q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each link's placement in its parent's frame at configuration ``q``.

    Returns:
        (translations (n, 3) [m], quaternions (n, 4) x y z w): parent_X_child =
        (world_X_parent)^-1 world_X_child, the root's parent being the world (``odom``).
    """
    pin.framesForwardKinematics(model, data, q)
    n = len(tree.children)
    translations, quaternions = np.empty((n, 3)), np.empty((n, 4))
    for k, (child, parent) in enumerate(zip(tree.children, tree.parent_ids, strict=True)):
        placement = data.oMf[child]
        if parent >= 0:
            placement = data.oMf[parent].actInv(placement)
        translations[k] = placement.translation
        quaternions[k] = pin.Quaternion(placement.rotation).coeffs()
    return translations, quaternions
