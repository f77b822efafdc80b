"""The compiled plant (src/uvms_core/plant.hpp) of a `Plant`: its dynamics, flow, contact,
disturbance, joint stops or limits, joint friction, fins and world, each built by its own part of the seam
(`uvms_pin.physics.compiled`)."""

from __future__ import annotations

from types import ModuleType
from typing import Any, Protocol

import numpy as np

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.compiled.disturbance import disturbance_to_core
from uvms_pin.physics.compiled.fins import fins_to_core
from uvms_pin.physics.compiled.flow import flow_to_core
from uvms_pin.physics.compiled.joint_friction import joint_friction_to_core
from uvms_pin.physics.compiled.joint_limits import joint_limits_to_core
from uvms_pin.physics.compiled.joint_stops import joint_stops_to_core
from uvms_pin.physics.compiled.world import world_bounds_to_core, world_contact_to_core
from uvms_pin.physics.dynamics import dynamics_of

__all__ = ["PlantParts", "plant_to_core"]


class PlantParts(Protocol):
    """What the compiled plant is built from: a `uvms_pin.sim.plant.Plant`'s public parts."""

    uvms: Any
    water: Any
    contact: Any
    disturbance: Any
    joint_stops: Any
    joint_limits: Any
    joint_friction: Any
    joint_coulomb: Any
    free_surface: bool
    world: Any


def plant_to_core(plant: PlantParts, core: ModuleType):
    """The compiled plant mirroring ``plant`` as it is now (its contact anchored, its water
    taken), or the `Fallback` of the first part the core has no counterpart of."""
    parts = (
        flow_to_core(plant.water, core),
        contact_to_core(plant.contact, core),
        disturbance_to_core(plant.disturbance, core),
        joint_stops_to_core(plant.joint_stops, core),
    )
    fallback = next((p for p in parts if isinstance(p, Fallback)), None)
    if fallback is not None:
        return fallback
    uvms = plant.uvms
    # the compiled plant uses the end-effector frame for contact only, which a model without
    # one cannot have (Plant checks): frame 0 (the world) stands in
    compiled = core.Plant(dynamics_of(uvms).core, uvms.ee_frame_id if uvms.has_end_effector else 0)
    compiled.flow, compiled.contact, compiled.disturbance, compiled.joint_stops = parts
    compiled.joint_friction = joint_friction_to_core(plant.joint_friction, core)
    compiled.fins = fins_to_core(uvms.fins, core)
    compiled.joint_limits = joint_limits_to_core(plant.joint_limits, uvms.model, core)
    if plant.joint_coulomb is not None:  # c at each rubbing joint's velocity coordinate
        coulomb = np.zeros(uvms.nv)
        friction = plant.joint_coulomb
        for joint, value in zip(friction.joint_ids, friction.coulomb_Nm, strict=True):
            coulomb[uvms.model.joints[joint].idx_v] = value
        compiled.joint_coulomb_Nm = coulomb
    compiled.free_surface = bool(plant.free_surface)
    bounds = world_bounds_to_core(plant.world, core)
    if bounds is not None:
        compiled.world_bounds = bounds
        compiled.world = world_contact_to_core(plant.world, core)
    return compiled
