"""A world as the core's: its broad phase (src/uvms_core/world_bounds.hpp, `WorldBounds`)
and its contacts (world_contact.hpp, `WorldContact`: the shapes of contact_shapes.hpp, the
law of contact_law.hpp), built from the Python reference (`uvms_pin.physics.world`).

Each robot piece and world object becomes a `ContactShape`: the same coal geometry on a
joint (0, the universe, for a fixed object) at a placement in that joint's frame; a convex
hull crosses as the points qhull built it from, so that the core's hull is the same one."""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.objects import registered_kinds
from uvms_pin.physics.world.robot_geometry import RobotPiece
from uvms_pin.physics.world.touch import CLEARANCE_M
from uvms_pin.physics.world.world import World


def world_bounds_to_core(world: World | None, core: ModuleType):
    """The core's bounds of ``world``'s pieces and objects (None: no world)."""
    if world is None:
        return None
    out = core.WorldBounds()
    out.joint_ids = [int(p.joint_id) for p in world.pieces]
    out.centers_in_joint = (
        np.array([p.placement_in_joint.translation for p in world.pieces], dtype=float)
        .reshape(-1, 3)
        .T
    )
    out.radii_m = np.array([p.bound_radius_m for p in world.pieces], dtype=float)
    planes = [o for o in world.objects if o.is_plane]
    solids = [o for o in world.objects if not o.is_plane]
    out.plane_normals = np.array([o.normal_world for o in planes], dtype=float).reshape(-1, 3).T
    out.plane_offsets_m = np.array(
        [o.normal_world @ o.placement.translation for o in planes], dtype=float
    )
    out.sphere_centers_m = (
        np.array([o.placement.translation for o in solids], dtype=float).reshape(-1, 3).T
    )
    out.sphere_radii_m = np.array([o.bound_radius_m for o in solids], dtype=float)
    out.clearance_m = CLEARANCE_M
    return out


def _geometry(shape: Any, core: ModuleType) -> tuple[Any, np.ndarray, np.ndarray]:
    """(core kind, sizes, points (3, n)) of a coal shape, a world object's or a robot
    piece's (what `ContactShape.set_geometry` takes), as the kind whose coal class it is
    says (`uvms_pin.physics.world.kind.Compiled`: a box's edges are twice coal's half
    sides, a hull the points qhull built it from)."""
    for kind in registered_kinds():
        if isinstance(shape, kind.compiled.coal_type):
            name, sizes, points = kind.compiled.of(shape)
            return getattr(core.ContactKind, name), sizes, points
    raise ModelError(f"no compiled contact geometry for a {type(shape).__name__}")


def _shape(core: ModuleType, shape: Any, joint_id: int, placement: pin.SE3, radius: float):
    out = core.ContactShape()
    out.joint_id = int(joint_id)
    out.set_placement(placement.rotation, placement.translation)
    out.set_geometry(*_geometry(shape, core))
    out.bound_radius_m = float(radius)
    return out


def pieces_to_core(pieces: Sequence[RobotPiece], core: ModuleType) -> list:
    """The core's `ContactShape` of each robot piece (or free object's piece): its shape on
    its joint, its hull index and the corners it touches a plane by."""
    out = []
    for piece in pieces:
        where = piece.placement_in_joint
        shape = _shape(core, piece.shape, piece.joint_id, where, piece.bound_radius_m)
        shape.body = int(piece.body)
        corners = piece.corners_m
        shape.corners_m = np.zeros((3, 0)) if corners is None else np.asarray(corners).T
        out.append(shape)
    return out


def contact_law_to_core(law: ContactLaw, core: ModuleType):
    """The core's `ContactLaw` (its coefficients of friction are the objects')."""
    out = core.ContactLaw()
    out.stiffness_N_m = law.stiffness_N_m
    out.dissipation_s_m = law.dissipation_s_m
    out.tangential_stiffness_N_m = law.tangential_stiffness_N_m
    out.tangential_damping_N_s_m = law.tangential_damping_N_s_m
    return out


def world_contact_to_core(world: World | None, core: ModuleType):
    """The core's contacts of ``world`` (None: no world): its pieces (on their joints), its
    objects (fixed: joint 0) and its law."""
    if world is None:
        return None
    objects = []
    for obj in world.objects:
        shape = _shape(core, obj.shape, 0, obj.placement, obj.bound_radius_m)
        shape.friction_static = float(obj.friction_static)
        shape.friction_kinetic = float(obj.friction_kinetic)
        objects.append(shape)
    out = core.WorldContact()
    out.pieces = pieces_to_core(world.pieces, core)
    out.objects = objects
    out.law = contact_law_to_core(world.law, core)
    return out
