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
  (`coal.distance`), x its nearest point on the piece (a sphere's: c - R n);
- two solids within the reach whose nearest features are faces or edges (a box on a box, a
  cylinder on its side on a box, a box on a rock's facet): coal's contact patch
  (`coal.computeContactPatch`) in place of that one point: the polygon where the two
  supporting faces overlap, each vertex x on the piece a candidate of the patch's normal and
  signed gap. One point would leave a crate on a shelf to rock between the shelf's edges
  and turn about its normal under the friction there; on the patch's vertices it rests.
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

__all__ = ["PATCH_CORNER", "Candidate", "candidates", "coal_candidate", "patch_candidates"]

_REQUEST = coal.DistanceRequest()  # signed distance and nearest points

#: |axis . n| beyond which a cylinder stands on an end face (its rim's corners touch)
_STANDING = 1.0 - 1.0e-9

#: coal's contact patch of two solids: one patch, curved rims sampled at 12 points, the
#: supporting features within 1 mm of the deepest (coal's defaults)
_PATCH_REQUEST = coal.ContactPatchRequest()

#: a patch's vertex k is candidate corner PATCH_CORNER - k (-2, -3: a cylinder's rims)
PATCH_CORNER = -4


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


def patch_candidates(
    p: int, o: int, piece: RobotPiece, where: pin.SE3, obj: WorldObject, reach_m: float
) -> list[Candidate]:
    """The candidates of ``piece`` (index p, placed at ``where``) on the solid ``obj``
    (index o): the vertices of coal's contact patch when the two are within ``reach_m``
    [m] and touch along a face or an edge (two vertices or more), else coal's one nearest
    point (`coal_candidate`: apart beyond the reach, or a curved piece's single point)."""
    nearest = coal_candidate(p, o, piece, where, obj)
    if not nearest.gap_m <= reach_m:
        return [nearest]
    transform = coal.Transform3s(where.rotation, where.translation)
    # coal 3.0's patch of a cylinder is one point when the cylinder's supporting disc is
    # the second shape's and the normal points away from it: the pair asked both ways
    for first in (True, False):
        pair = (piece.shape, transform, obj.shape, obj.transform)
        patch = _patch(*(pair if first else pair[2:] + pair[:2]), reach_m)
        if patch is not None:
            break
    else:
        return [nearest]
    # coal's normal points from the first shape to the second; ours out of the object
    normal = np.asarray(patch.getNormal(), dtype=float) * (-1.0 if first else 1.0)
    gap = float(patch.penetration_depth)
    on_piece = patch.getPointShape1 if first else patch.getPointShape2
    return [
        Candidate(p, o, PATCH_CORNER - k, np.asarray(on_piece(k), dtype=float), normal, gap)
        for k in range(patch.size())
    ]


def _patch(shape_1, transform_1, shape_2, transform_2, reach_m: float):
    """coal's contact patch of two shapes within ``reach_m`` [m] of each other when it has
    two vertices or more (a face or an edge), else None."""
    request = coal.CollisionRequest()
    request.security_margin = reach_m  # a pair within the reach counts as touching
    result = coal.CollisionResult()
    if not coal.collide(shape_1, transform_1, shape_2, transform_2, request, result):
        return None
    patches = coal.ContactPatchResult(_PATCH_REQUEST)
    coal.computeContactPatch(
        shape_1, transform_1, shape_2, transform_2, result, _PATCH_REQUEST, patches
    )
    if patches.numContactPatches() == 0 or patches.getContactPatch(0).size() < 2:
        return None
    return patches.getContactPatch(0)


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
            out += patch_candidates(p, o, piece, where[p], obj, reach_m)
    return out
