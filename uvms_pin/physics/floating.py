"""Where a body floats: the static equilibrium of a UVMS at a level free surface.

At rest in still water the load on the vehicle is its weight and the buoyancy of its wet
part (the arm's too, carried by the vehicle with the arm's joints held): the net force and
moment at the vehicle's origin, in world axes,

    F = -R h[0:3],   M = -R h[3:6],      h = h(q, 0) under the free surface (`bias_forces`)

(R the vehicle's attitude). A floating equilibrium has F_z = 0 and M_x = M_y = 0 (the loads
are vertical: F_x, F_y, M_z vanish anyway). The height comes first, at the start's attitude:
F_z(z) only grows as the body sinks (the wet volume does), so its root is bracketed and
unique (`scipy.optimize.brentq`); roll and pitch then follow with z by a Newton-type solve
of the three equations from there (`scipy.optimize.root`), which finds the equilibrium
nearest the start: start near the attitude you expect (a stable one is a minimum of the
potential energy, `potential_energy`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import SimulationError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces

__all__ = ["floating_equilibrium", "net_hydrostatic_load"]


def _with(q: np.ndarray, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    out = q.copy()
    out[2] = z
    out[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(roll, pitch, yaw)).coeffs()
    return out


def net_hydrostatic_load(uvms: UVMS, q: np.ndarray, backend: str = "core") -> np.ndarray:
    """(F_z [N], M_x, M_y [N m]): the net vertical force and the horizontal moments of
    weight and buoyancy on the UVMS at rest at q (world axes, at the vehicle's origin)."""
    h = bias_forces(uvms, q, np.zeros(uvms.nv), free_surface=True, backend=backend)
    rotation = pin.Quaternion(q[3:7]).normalized().toRotationMatrix()
    force, moment = -rotation @ h[:3], -rotation @ h[3:6]
    return np.array([force[2], moment[0], moment[1]])


def floating_equilibrium(
    uvms: UVMS, q_start: np.ndarray, *, free_attitude: bool = True, backend: str = "core"
) -> np.ndarray:
    """The configuration at which the UVMS floats at rest in still water, near ``q_start``
    (its x, y, yaw and arm joints are kept; ``free_attitude`` False keeps roll and pitch).

    Raises:
        SimulationError: the UVMS does not float (heavier than the water it can displace),
            or no equilibrium was found from this start.
    """
    q = finite_vector("q_start", q_start, uvms.nq)
    roll, pitch, yaw = pin.rpy.matrixToRpy(pin.Quaternion(q[3:7]).normalized().toRotationMatrix())
    bodies = uvms.surface_bodies
    reach = float(
        np.max(
            np.linalg.norm(bodies.bound_center_in_joint_m, axis=1) + bodies.bound_radius_m,
            initial=0.0,
        )
    )
    span = 2.0 * reach + 1.0  # the vehicle and an arm's reach: every hull crosses z = 0 in it

    def lift(z: float) -> float:
        return float(net_hydrostatic_load(uvms, _with(q, z, roll, pitch, yaw), backend)[0])

    if not lift(-span) > 0.0:
        raise SimulationError(
            f"{uvms.source or 'the model'} does not float: its weight is not less than the "
            "buoyancy of all its volume"
        )
    # scipy.optimize is imported where it is used: it takes a quarter second to import,
    # which every start-up would pay otherwise
    from scipy.optimize import brentq, root

    z = brentq(lift, -span, span, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
    if not free_attitude:
        return _with(q, z, roll, pitch, yaw)
    weight = uvms.mass_kg * float(np.linalg.norm(uvms.model.gravity.linear))
    scale = np.array([weight, weight * reach, weight * reach])  # the equations made O(1)
    solved = root(
        lambda x: net_hydrostatic_load(uvms, _with(q, x[0], x[1], x[2], yaw), backend) / scale,
        np.array([z, roll, pitch]),
        method="hybr",
        options={"xtol": 1e-13},
    )
    if not solved.success:
        raise SimulationError(f"no floating equilibrium found from this start: {solved.message}")
    return _with(q, *solved.x, yaw)
