"""A world's broad phase as the core's (src/uvms_core/world_bounds.hpp): `WorldBounds`.

The contacts themselves stay in Python (coal); the compiled plant only says whether a
control period can touch anything (`uvms_pin.physics.world.touch.clear_of`)."""

from __future__ import annotations

from types import ModuleType

import numpy as np

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
