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

__all__ = ["NO_TOUCH", "Bounds", "Touch", "clear_of", "coal_point", "reach_spheres", "touch"]

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


def coal_point(piece: RobotPiece, where: pin.SE3, obj: WorldObject):
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
    data: pin.Data, pieces: Sequence[RobotPiece], bounds: Bounds, horizon_s: float
) -> bool:
    """Whether no piece can reach any object within ``horizon_s`` (after
    ``pin.forwardKinematics(model, data, q, v)``): every piece's bounding sphere, grown by
    twice the distance its fastest point covers at the current speed plus `CLEARANCE_M`,
    misses every object's bound. Then a whole control period runs without the world."""
    centers_m, reach_m = reach_spheres(data, pieces, horizon_s)
    return not bounds.near(centers_m, reach_m)


def reach_spheres(
    data: pin.Data, pieces: Sequence[RobotPiece], horizon_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """(centres (p, 3) [m], radii (p,) [m]) of the spheres holding every piece over
    ``horizon_s`` (`clear_of`), after ``pin.forwardKinematics(model, data, q, v)``."""
    centers, reach = [], []
    for piece in pieces:
        local = piece.placement_in_joint.translation
        twist = data.v[piece.joint_id]
        speed = float(np.linalg.norm(twist.linear)) + float(np.linalg.norm(twist.angular)) * (
            float(np.linalg.norm(local)) + piece.bound_radius_m
        )
        centers.append(data.oMi[piece.joint_id].act(local))
        reach.append(piece.bound_radius_m + 2.0 * speed * horizon_s + CLEARANCE_M)
    return np.array(centers).reshape(-1, 3), np.array(reach, dtype=float)


@dataclass(frozen=True)
class Bounds:
    """The objects' bounds, stacked: planes (outward normals (k, 3), offsets n . p0 (k,))
    and the other objects' bounding spheres (centres (l, 3), radii (l,)), with their
    indices among the objects."""

    plane_index: np.ndarray
    plane_normals: np.ndarray
    plane_offsets_m: np.ndarray
    solid_index: np.ndarray
    solid_centers_m: np.ndarray
    solid_radii_m: np.ndarray

    @staticmethod
    def of(objects: Sequence[WorldObject]) -> Bounds:
        planes = [k for k, o in enumerate(objects) if o.is_plane]
        solids = [k for k, o in enumerate(objects) if not o.is_plane]
        normals = np.array([objects[k].normal_world for k in planes]).reshape(-1, 3)
        points = np.array([objects[k].placement.translation for k in planes]).reshape(-1, 3)
        return Bounds(
            np.array(planes, dtype=int),
            normals,
            np.einsum("ij,ij->i", normals, points),
            np.array(solids, dtype=int),
            np.array([objects[k].placement.translation for k in solids]).reshape(-1, 3),
            np.array([objects[k].bound_radius_m for k in solids], dtype=float),
        )

    def near(self, centers_m: np.ndarray, radii_m: np.ndarray) -> list[tuple[int, int]]:
        """(piece, object) of every sphere (centres (p, 3), radii (p,)) that reaches an
        object's bound."""
        out = []
        heights = centers_m @ self.plane_normals.T - self.plane_offsets_m  # (p, k)
        for p, k in zip(*np.nonzero(heights < radii_m[:, None]), strict=True):
            out.append((int(p), int(self.plane_index[k])))
        gaps = np.linalg.norm(centers_m[:, None, :] - self.solid_centers_m[None], axis=2)
        for p, k in zip(*np.nonzero(gaps < radii_m[:, None] + self.solid_radii_m), strict=True):
            out.append((int(p), int(self.solid_index[k])))
        return out


def touch(
    data: pin.Data,
    pieces: Sequence[RobotPiece],
    objects: Sequence[WorldObject],
    bounds: Bounds,
) -> Touch:
    """The contact points after ``pin.forwardKinematics(model, data, q, v)``."""
    where = [data.oMi[piece.joint_id] * piece.placement_in_joint for piece in pieces]
    centers = np.array([w.translation for w in where]).reshape(-1, 3)
    radii = np.array([piece.bound_radius_m for piece in pieces], dtype=float)
    chunks: list[tuple] = []
    for p, o in bounds.near(centers, radii):
        piece, obj = pieces[p], objects[o]
        if obj.is_plane and piece.corners_m is not None:
            corners, points, depths = _corners_below(piece, where[p], obj)
            if len(corners):
                normals = np.broadcast_to(obj.normal_world, points.shape)
                count = len(corners)
                chunks.append(
                    (np.full(count, p), np.full(count, o), corners, points, normals, depths)
                )
            continue
        found = coal_point(piece, where[p], obj)
        if found is not None:
            point, normal, depth = found
            chunks.append(
                ([p], [o], [-1], point[None], normal[None], np.array([depth], dtype=float))
            )
    return _stacked(data, pieces, chunks)


#: no contact point
NO_TOUCH = Touch(
    *(np.zeros(0, dtype=int),) * 3, *(np.zeros((0, 3)),) * 2, np.zeros(0), np.zeros((0, 3))
)


def _stacked(data: pin.Data, pieces: Sequence[RobotPiece], chunks: list) -> Touch:
    if not chunks:
        return NO_TOUCH
    columns = [np.concatenate(c) for c in zip(*chunks, strict=True)]
    piece, obj, corner = (c.astype(int) for c in columns[:3])
    points, normals, depth = columns[3:]
    joints = [pieces[p].joint_id for p in piece]
    rotation = np.array([data.oMi[j].rotation for j in joints])
    origin = np.array([data.oMi[j].translation for j in joints])
    linear = np.einsum("kij,kj->ki", rotation, np.array([data.v[j].linear for j in joints]))
    angular = np.einsum("kij,kj->ki", rotation, np.array([data.v[j].angular for j in joints]))
    velocity = linear + cross(angular, points - origin)
    return Touch(piece, obj, corner, points, normals, depth, velocity)
