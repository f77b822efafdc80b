"""Where a UVMS touches the world at one state: the contact points (narrow phase by coal,
a bounding-sphere broad phase first, so that objects far away cost one vector test).

Against a plane each corner of a piece below it is a contact point, its depth along the
plane's normal; against a solid (or a smooth piece against a plane) coal's GJK/EPA give
the deepest point, its depth and normal: one point per pair.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece

__all__ = ["Touch", "clear_of", "touch"]

_REQUEST = coal.CollisionRequest()  # one contact, depth and normal: what a pair needs


@dataclass(frozen=True)
class Touch:
    """The m contact points at one state.

    Attributes:
        piece, obj: which robot piece and world object (m,). corner: the piece's corner
            index, or -1 for coal's one point of the pair (m,).
        point_world_m: where the force acts, on the piece (m, 3).
        normal_world: unit, out of the object towards the robot (m, 3).
        depth_m: penetration, > 0 (m,).
        velocity_world_m_s: the piece's material velocity at the point (m, 3).
    """

    piece: np.ndarray
    obj: np.ndarray
    corner: np.ndarray
    point_world_m: np.ndarray
    normal_world: np.ndarray
    depth_m: np.ndarray
    velocity_world_m_s: np.ndarray

    def __len__(self) -> int:
        return len(self.piece)

    def keys(self) -> list[tuple[int, int, int]]:
        """Each point's identity over time: (piece, object, corner)."""
        return list(zip(self.piece.tolist(), self.obj.tolist(), self.corner.tolist(), strict=True))


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a x b of (n, 3) arrays (numpy's cross costs ~10 us a call on small arrays)."""
    return np.column_stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ]
    )


def _corners_below(piece: RobotPiece, where: pin.SE3, obj: WorldObject):
    """(corner indices, points (k, 3), depths (k,)) of the corners under a plane."""
    points = where.translation + piece.corners_m @ where.rotation.T
    normal = obj.normal_world
    depth = (obj.placement.translation - points) @ normal
    inside = np.flatnonzero(depth > 0.0)
    return inside, points[inside], depth[inside]


def _coal_point(piece: RobotPiece, where: pin.SE3, obj: WorldObject):
    """coal's deepest point of the pair: (point (3,), normal out of the object, depth) or
    None when apart."""
    result = coal.CollisionResult()
    transform = coal.Transform3s(where.rotation, where.translation)
    if not coal.collide(piece.shape, transform, obj.shape, obj.transform, _REQUEST, result):
        return None
    contact = result.getContact(0)
    depth = -float(contact.penetration_depth)
    if depth <= 0.0:
        return None
    point = 0.5 * (contact.getNearestPoint1() + contact.getNearestPoint2())
    # coal's normal points from the first shape (the piece) to the second (the object)
    return point, -np.asarray(contact.normal, dtype=float), depth


#: clearance added to the reach of every piece over a period [m] (see `clear_of`)
CLEARANCE_M = 0.05


def clear_of(
    data: pin.Data,
    pieces: Sequence[RobotPiece],
    objects: Sequence[WorldObject],
    horizon_s: float,
) -> bool:
    """Whether no piece can reach any object within ``horizon_s`` (after
    ``pin.forwardKinematics(model, data, q, v)``): every piece's bounding sphere, grown by
    twice the distance its fastest point covers at the current speed plus `CLEARANCE_M`,
    misses every object's bound. Then a whole control period runs without the world."""
    for piece in pieces:
        joint = data.oMi[piece.joint_id]
        center = joint.act(piece.placement_in_joint.translation)
        twist = data.v[piece.joint_id]
        offset = float(np.linalg.norm(piece.placement_in_joint.translation))
        speed = float(np.linalg.norm(twist.linear)) + float(np.linalg.norm(twist.angular)) * (
            offset + piece.bound_radius_m
        )
        reach = piece.bound_radius_m + 2.0 * speed * horizon_s + CLEARANCE_M
        for obj in objects:
            if _near_within(center, reach, obj):
                return False
    return True


def _near_within(center: np.ndarray, radius_m: float, obj: WorldObject) -> bool:
    if obj.is_plane:
        return float((center - obj.placement.translation) @ obj.normal_world) < radius_m
    gap = float(np.linalg.norm(center - obj.placement.translation))
    return gap < radius_m + obj.bound_radius_m


def touch(
    model: pin.Model, data: pin.Data, pieces: Sequence[RobotPiece], objects: Sequence[WorldObject]
) -> Touch:
    """The contact points after ``pin.forwardKinematics(model, data, q, v)``."""
    rows: list[tuple] = []
    for p, piece in enumerate(pieces):
        joint = data.oMi[piece.joint_id]
        where = joint * piece.placement_in_joint
        for o, obj in enumerate(objects):
            if not _near_within(where.translation, piece.bound_radius_m, obj):
                continue
            if obj.is_plane and piece.corners_m is not None:
                corners, points, depths = _corners_below(piece, where, obj)
                normal = obj.normal_world
                rows += [
                    (p, o, int(c), x, normal, d)
                    for c, x, d in zip(corners, points, depths, strict=True)
                ]
                continue
            found = _coal_point(piece, where, obj)
            if found is not None:
                rows.append((p, o, -1, *found))
    return _stacked(model, data, pieces, rows)


def _stacked(model: pin.Model, data: pin.Data, pieces: Sequence[RobotPiece], rows: list) -> Touch:
    if not rows:
        empty3 = np.zeros((0, 3))
        none = np.zeros(0, dtype=int)
        return Touch(none, none, none, empty3, empty3, np.zeros(0), empty3)
    piece, obj, corner, point, normal, depth = (list(c) for c in zip(*rows, strict=True))
    points = np.array(point, dtype=float)
    joints = [pieces[p].joint_id for p in piece]
    rotation = np.array([data.oMi[j].rotation for j in joints])
    origin = np.array([data.oMi[j].translation for j in joints])
    linear = np.einsum("kij,kj->ki", rotation, np.array([data.v[j].linear for j in joints]))
    angular = np.einsum("kij,kj->ki", rotation, np.array([data.v[j].angular for j in joints]))
    velocity = linear + cross(angular, points - origin)
    return Touch(
        np.array(piece, dtype=int),
        np.array(obj, dtype=int),
        np.array(corner, dtype=int),
        points,
        np.array(normal, dtype=float),
        np.array(depth, dtype=float),
        velocity,
    )
