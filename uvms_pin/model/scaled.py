"""A UVMS with scaled parameters: the model error of a study or of a model-based controller."""

from __future__ import annotations

import pinocchio as pin

from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.uvms import UVMS, HydroBody


def scaled_uvms(
    uvms: UVMS,
    *,
    mass_scale: float = 1.0,
    added_mass_scale: float = 1.0,
    damping_scale: float = 1.0,
    buoyancy_scale: float = 1.0,
) -> UVMS:
    """A copy of ``uvms`` with scaled parameters.

    - ``mass_scale``: every body's mass and rotational inertia (about its CoM, which
      stays put) and the joint armature;
    - ``added_mass_scale``: every body's added-mass matrix M_A;
    - ``damping_scale``: linear and quadratic damping;
    - ``buoyancy_scale``: every displaced volume (buoyancy rho g V; centres unchanged).

    Mass and volume are scaled independently: a mass_scale of 1.2 with buoyancy_scale 1
    leaves the vehicle 20 % of its weight heavy in water.
    """
    model = uvms.model
    if mass_scale != 1.0:
        model = pin.Model(model)
        for j in range(1, model.njoints):
            inertia = model.inertias[j]
            model.inertias[j] = pin.Inertia(
                inertia.mass * mass_scale, inertia.lever, inertia.inertia * mass_scale
            )
        model.armature = uvms.model.armature * mass_scale
    out = uvms.with_model(model)
    if (added_mass_scale, damping_scale, buoyancy_scale) == (1.0, 1.0, 1.0):
        return out

    def hydro(body: HydroBody) -> HydroParams:
        p = body.params
        return HydroParams(
            p.volume_m3 * buoyancy_scale,
            p.center_of_buoyancy_m,
            p.added_mass * added_mass_scale,
            p.linear_damping * damping_scale,
            p.quadratic_damping * damping_scale,
            derived=p.derived,
            origin=p.origin,
        )

    return out.with_hydro(hydro)
