"""Where a body may touch the fixed world within a period: the candidate contact points with
their signed gaps, touching or not (what a contact solved as a constraint needs; the
penalty contact's `touch` only sees points already inside).

Each candidate is a material point x of a piece, the unit normal n out of the object
towards the piece and the signed gap r [m] (> 0 apart, < 0 inside) along n:

- a polyhedron against a plane: each corner, r = n . (x - p0);
- a cylinder against a plane: the lowest point of each rim circle, x = c_rim - R u with
  u the normal's part across the axis, normalised (the smooth cylinder rolls on these two
  points as a real one does); standing on an end face (the axis along n) the rim's corners
  (`robot_geometry.RIM_POINTS`);
- anything else (a sphere, an ellipsoid, any piece against a solid): coal's signed distance
  (`coal.distance`), x its nearest point on the piece (a sphere's: c - R n).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece
from uvms_pin.physics.world.touch import Bounds

__all__ = ["Candidate", "candidates", "coal_candidate"]

_REQUEST = coal.DistanceRequest()  # signed distance and nearest points

#: |axis . n| beyond which a cylinder stands on an end face (its rim's corners touch)
_STANDING = 1.0 - 1.0e-9


@dataclass(frozen=True)
class Candidate:
    """One candidate contact point: ``piece`` and ``obj`` (indices), ``corner`` (the
    piece's corner, a rim's lowest point -2 - rim, -1 coal's point), ``point_world_m``
    (3,) on the piece, ``normal_world`` (3,) out of the object, ``gap_m`` (signed)."""

    piece: int
    obj: int
    corner: int
    point_world_m: np.ndarray
    normal_world: np.ndarray
    gap_m: float


def _plane_points(piece: RobotPiece, where: pin.SE3, obj: WorldObject):
    """(corner ids, points (k, 3)) of a piece that touches a plane by points of its own."""
    normal = obj.normal_world
    if isinstance(piece.shape, coal.Cylinder):
        axis = where.rotation[:, 2]
        across = normal - axis * float(axis @ normal)
        if np.linalg.norm(across) > np.sqrt(1.0 - _STANDING**2):
            down = across / np.linalg.norm(across)
            half, radius = piece.shape.halfLength, piece.shape.radius
            rims = [where.translation + s * half * axis - radius * down for s in (-1.0, 1.0)]
            return [-2, -3], np.array(rims)
    points = where.translation + piece.corners_m @ where.rotation.T
    return list(range(len(points))), points


def coal_candidate(
    p: int, o: int, piece: RobotPiece, where: pin.SE3, obj: WorldObject
) -> Candidate:
    """The candidate of ``piece`` (index p, placed at ``where``) on ``obj`` (index o) by
    coal's signed distance: its nearest point on the piece, the normal out of the object."""
    result = coal.DistanceResult()
    transform = coal.Transform3s(where.rotation, where.translation)
    gap = coal.distance(piece.shape, transform, obj.shape, obj.transform, _REQUEST, result)
    # coal's normal points from the first shape (the piece) to the second (the object)
    normal = -np.asarray(result.normal, dtype=float)
    return Candidate(p, o, -1, np.asarray(result.getNearestPoint1(), float), normal, float(gap))


def candidates(
    data: pin.Data,
    pieces: Sequence[RobotPiece],
    objects: Sequence[WorldObject],
    bounds: Bounds,
    reach_m: float,
) -> list[Candidate]:
    """Every candidate point of ``pieces`` (placed by ``data`` after forward kinematics)
    on ``objects`` whose bounds are within ``reach_m`` [m] (the broad phase; the caller
    keeps the points whose gap it can close)."""
    where = [data.oMi[piece.joint_id] * piece.placement_in_joint for piece in pieces]
    centers = np.array([w.translation for w in where]).reshape(-1, 3)
    radii = np.array([piece.bound_radius_m + reach_m for piece in pieces], dtype=float)
    out = []
    for p, o in bounds.near(centers, radii):
        piece, obj = pieces[p], objects[o]
        if obj.is_plane and piece.corners_m is not None:
            normal, origin = obj.normal_world, obj.placement.translation
            corners, points = _plane_points(piece, where[p], obj)
            gaps = (points - origin) @ normal
            out += [
                Candidate(p, o, c, x, normal, float(r))
                for c, x, r in zip(corners, points, gaps, strict=True)
            ]
        else:
            out.append(coal_candidate(p, o, piece, where[p], obj))
    return out
