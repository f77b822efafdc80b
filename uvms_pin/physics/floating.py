"""Where a body floats: the static equilibrium of a UVMS at a level free surface.

In still water the hydrostatic load of the wet part is the negative gradient of

    U(q) = U_gravity + rho g . sum_j V_sub,j r_sub,j          (`potential_energy`)

so a floating equilibrium is a minimum of U over the coordinates a floating body is free
in: its height z and its roll and pitch (U does not change with x, y and yaw). The arm's
joints are held where they are. The minimum is found from a start with a bounded scalar
search on z at that attitude, then a Nelder-Mead polish of (z, roll, pitch).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.optimize import minimize, minimize_scalar

from uvms_pin.checks import finite_vector
from uvms_pin.errors import SimulationError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import potential_energy

__all__ = ["floating_equilibrium"]


def _with(q: np.ndarray, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    out = q.copy()
    out[2] = z
    out[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(roll, pitch, yaw)).coeffs()
    return out


def floating_equilibrium(
    uvms: UVMS, q_start: np.ndarray, *, free_attitude: bool = True, tolerance_m: float = 1e-10
) -> np.ndarray:
    """The configuration at which the UVMS floats at rest in still water, from ``q_start``
    (its x, y, yaw and arm joints are kept; ``free_attitude`` False keeps its roll and pitch
    too). ``tolerance_m``: on z (and, in rad, on the angles).

    Raises:
        SimulationError: the UVMS does not float (it is heavier than the water it can
            displace: the minimum lies at the search's lower end).
    """
    q = finite_vector("q_start", q_start, uvms.nq)
    roll, pitch, yaw = pin.rpy.matrixToRpy(pin.Quaternion(q[3:7]).normalized().toRotationMatrix())
    reach = float(
        np.max(uvms.surface_bodies.bound_radius_m, initial=0.0)
        + np.max(np.linalg.norm(uvms.surface_bodies.bound_center_in_joint_m, axis=1), initial=0.0)
    )
    span = 2.0 * reach + 1.0  # the vehicle and an arm's reach: every hull crosses z = 0 in it

    def energy(x: np.ndarray) -> float:
        return potential_energy(uvms, _with(q, x[0], x[1], x[2], yaw), free_surface=True)

    search = minimize_scalar(
        lambda z: energy(np.array([z, roll, pitch])),
        bounds=(-span, span),
        method="bounded",
        options={"xatol": tolerance_m},
    )
    if search.x <= -span + 1e-3:
        raise SimulationError(
            f"{uvms.source or 'the model'} does not float: its weight exceeds the buoyancy of "
            "all its volume"
        )
    start = np.array([search.x, roll, pitch])
    if not free_attitude:
        return _with(q, search.x, roll, pitch, yaw)
    polished = minimize(
        energy,
        start,
        method="Nelder-Mead",
        options={"xatol": tolerance_m, "fatol": 1e-14, "maxiter": 4000},
    )
    return _with(q, *polished.x, yaw)
