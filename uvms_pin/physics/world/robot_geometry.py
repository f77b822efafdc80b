"""What of a UVMS touches the world: each body's collision shapes, in its joint's frame.

The shapes are the hulls a free surface cuts (`uvms_pin.model.hulls`: each link's URDF
``<collision>`` shapes, or a sphere of its volume when it has none), in coal's geometry: a
sphere, ellipsoid or cylinder as itself, a box or mesh as its convex hull. Against a plane
a piece touches by its corner points, each its own contact (exact for a polyhedron: a box
resting flat carries its load on its four corners; a cylinder by the 2 x 16 corners of the
prism on its rims); spheres and ellipsoids by their one deepest point.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.objects import convex_hull

__all__ = ["RobotPiece", "coal_of", "robot_pieces"]

RIM_POINTS = 16  # corners of the prism standing for a cylinder's rims against a plane


@dataclass(frozen=True)
class RobotPiece:
    """One collision shape of a body.

    Attributes:
        body: the index of its hull (``uvms.surface_bodies``), the pair's first half.
        joint_id: the joint that carries it. placement_in_joint: its frame there.
        shape: coal geometry in its frame. corners_m: the points it touches a plane by,
            in its frame (k, 3), or None (a smooth shape: coal's deepest point).
        bound_radius_m: a sphere about its frame's origin holding it.
    """

    body: int
    joint_id: int
    placement_in_joint: pin.SE3
    shape: Any
    corners_m: np.ndarray | None
    bound_radius_m: float


def _prism_corners(radius_m: float, length_m: float) -> np.ndarray:
    angles = np.linspace(0.0, 2.0 * np.pi, RIM_POINTS, endpoint=False)
    ring = np.column_stack([radius_m * np.cos(angles), radius_m * np.sin(angles)])
    return np.vstack(
        [np.column_stack([ring, np.full(RIM_POINTS, z)]) for z in (-0.5 * length_m, 0.5 * length_m)]
    )


def coal_of(shape: Any, name: str) -> tuple[Any, np.ndarray | None]:
    """(coal geometry, corner points or None) of a hull piece's shape."""
    if isinstance(shape, Sphere):
        return coal.Sphere(shape.radius_m), None
    if isinstance(shape, Ellipsoid):
        return coal.Ellipsoid(*shape.semi_axes_m), None
    if isinstance(shape, Cylinder):
        return coal.Cylinder(shape.radius_m, shape.length_m), _prism_corners(
            shape.radius_m, shape.length_m
        )
    if isinstance(shape, Polyhedron):
        hull = convex_hull(shape.vertices_m)
        corners = np.array(hull.points(), dtype=float).reshape(-1, 3)
        return hull, corners
    raise ModelError(f"body '{name}': no contact geometry for a {type(shape).__name__}")


def robot_pieces(uvms: UVMS, names: list[str]) -> tuple[RobotPiece, ...]:
    """Every collision piece of every hull of ``uvms`` (``names``: each hull's body)."""
    bodies = uvms.surface_bodies
    pieces = []
    for h, hull in enumerate(bodies.hulls):
        for piece in hull.pieces:
            shape, corners = coal_of(piece.shape, names[h])
            pieces.append(
                RobotPiece(
                    body=h,
                    joint_id=int(bodies.joint_ids[h]),
                    placement_in_joint=pin.SE3(piece.rotation, piece.translation_m),
                    shape=shape,
                    corners_m=corners,
                    bound_radius_m=float(piece.shape.bounding_radius_m),
                )
            )
    return tuple(pieces)
