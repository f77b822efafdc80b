"""Free objects as the physics tests pose them."""

from __future__ import annotations

import dataclasses

import numpy as np

from uvms_pin.hydro.params import HydroParams
from uvms_pin.physics.world.free_object import FreeObject


def undamped(obj: FreeObject) -> FreeObject:
    """``obj`` without hydrodynamic damping (its buoyancy and added mass kept): the
    analytic cases (rolling, collisions, energy) have no drag."""
    uvms = obj.uvms.with_hydro(
        lambda b: HydroParams(
            b.params.volume_m3, b.params.center_of_buoyancy_m, b.params.added_mass,
            np.zeros(6), np.zeros(6),
        )
    )  # fmt: skip
    return dataclasses.replace(obj, uvms=uvms)
