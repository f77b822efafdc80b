"""How far a robot reaches: a sphere about its vehicle holding every collision piece of the
robot whatever its arm's configuration, grown by the distance its points can cover.

For a robot whose arm joints are all revolute, every point of a piece on joint j is at most

    R = max over pieces (sum of the joint offsets |p_i| from the vehicle to j
        + |the piece's offset in j| + its bound radius)

from the vehicle's origin (a rotation keeps lengths: the triangle inequality along the
chain), and moves at most

    |v_point| <= |v| + |w| R + 2 R sum_j |qdot_j|

(v, w the vehicle's body velocity; a joint's axis is within R of the vehicle's origin, the
point within R of it too, so within 2 R of the axis). Two robots whose spheres of radius
R + 2 |v_point| h + clearance do not meet cannot touch over h (the factor 2 and the
clearance as `uvms_pin.physics.world.touch.reach_spheres`'s). A robot with another kind of
arm joint (prismatic, spherical) has no such bound: R is infinite, its pieces are always
tested.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.robot_geometry import RobotPiece
from uvms_pin.physics.world.touch import CLEARANCE_M

__all__ = ["reach_sphere", "robot_reach_m"]


def _revolute(joint) -> bool:
    return joint.nv == 1 and joint.shortname().startswith("JointModelR")


def robot_reach_m(model: pin.Model, pieces: Sequence[RobotPiece]) -> float:
    """R [m]: the distance from the vehicle's origin (joint 1) every piece stays within;
    infinite for an arm joint that is not revolute, 0 without pieces."""
    chain = {0: 0.0, 1: 0.0}
    for j in range(2, model.njoints):
        if not _revolute(model.joints[j]):
            return math.inf
        chain[j] = chain[model.parents[j]] + float(
            np.linalg.norm(model.jointPlacements[j].translation)
        )
    lengths = [
        chain[p.joint_id]
        + float(np.linalg.norm(p.placement_in_joint.translation))
        + p.bound_radius_m
        for p in pieces
    ]
    return max([*lengths, *chain.values()]) if lengths else 0.0


def reach_sphere(
    q: np.ndarray, v: np.ndarray, reach_m: float, horizon_s: float
) -> tuple[np.ndarray, float]:
    """(centre (3,) [m], radius [m]) of the sphere holding the robot at (q, v) (free-flyer
    first) over ``horizon_s`` (see the module docstring); an infinite one without a
    bound (``reach_m`` infinite)."""
    if math.isinf(reach_m):
        return q[:3], math.inf
    speed = (
        float(np.linalg.norm(v[:3]))
        + float(np.linalg.norm(v[3:6])) * reach_m
        + 2.0 * reach_m * float(np.abs(v[6:]).sum())
    )
    return q[:3], reach_m + 2.0 * speed * horizon_s + CLEARANCE_M
