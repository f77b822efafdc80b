"""The derivatives of a plant's acceleration: the water's from
`uvms_pin.physics.dynamics.forward_dynamics_derivatives`, with the plant's own generalized
forces (world contacts, joint friction, joint stops) and their Jacobians added.

On the compiled core (a plant with ``backend="core"`` whose parts all have a compiled
counterpart) the whole of it is one compiled call, `src/uvms_core/plant_derivatives.cpp`,
on the compiled world's own contact points and forces and the end-effector's contact, a
linear spring or a compliant plane (`derivatives_world_contact.cpp`,
`derivatives_task_contact.cpp`, `derivatives_joint_limits.hpp` mirror the Python files); the
functions here are its reference (``backend="python"``). Any other end-effector contact model
(a user's, a subclass of those two included) has no compiled counterpart: the reference
computes, and refuses it by name."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.physics.configuration import checked_configuration
from uvms_pin.physics.derivatives.joint_limits import joint_friction_jacobian, joint_stop_jacobians
from uvms_pin.physics.derivatives.task_contact import TaskContact, contact_derivatives
from uvms_pin.physics.derivatives.world_contact import world_contact_jacobians
from uvms_pin.physics.dynamics import forward_dynamics_derivatives
from uvms_pin.physics.reference import check_time


def acceleration_derivatives(
    plant: Any,
    time_s: float,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    *,
    compiled: Any | None,
    scratch: pin.Data,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(da/dq, da/dv, da/dtau) (nv x nv each, q along the tangent) of ``plant``'s
    acceleration (a `uvms_pin.sim.plant.Plant`, which calls this: no import back; it
    passes its compiled counterpart, or None on the Python path, and a Pinocchio data of
    its model to work in, ``scratch``):
    the water (flow, free surface) by `forward_dynamics_derivatives`, and the plant's
    own generalized forces tau_g(q, v), the world's contacts (a piece's corners or a
    sphere on a plane: `uvms_pin.physics.derivatives.world_contact`), the end-effector's
    compliant contact (`uvms_pin.physics.derivatives.task_contact`: a linear spring or a
    compliant plane), the joint drives' friction and the joint stops
    (`uvms_pin.physics.derivatives.joint_limits`): da/dx += M^-1 d tau_g/dx. The
    disturbance depends on time only (no state derivative). Frozen at the state: the
    contacts' active set, anchors and stick or slip (``friction``). At a kink (a contact
    or a stop starting or ending) the derivative of the side the state is on is returned.

    Raises:
        ParameterError: the plant has a term whose derivatives are not implemented: free
            objects or self-collision, fins (lift and drag), an end-effector environment other than a linear
            spring or a compliant plane, or an active contact of an ellipsoid or with a
            solid object (coal's point).
    """
    q = checked_configuration("q", q, plant.uvms.model)
    v = finite_vector("v", v, plant.uvms.nv)
    world = plant.world
    if world is not None and (world.free or world.self_collision):
        raise ParameterError(
            "acceleration_derivatives: free objects and self-collision are not differentiated"
        )
    if plant.uvms.fins:
        raise ParameterError(
            "acceleration_derivatives: the fins' lift and drag (<lift_drag>) are not "
            f"differentiated (fins on links {', '.join(f.name for f in plant.uvms.fins)})"
        )
    if compiled is not None:  # (a contact model without a counterpart: no compiled plant)
        out = compiled.acceleration_derivatives(
            check_time(time_s), q, v, finite_vector("tau", tau, plant.uvms.nv), plant.friction
        )
        return out.da_dq, out.da_dv, out.da_dtau
    tau_ext, by_q, by_v = _own_forces(plant, scratch, time_s, q, v)
    da_dq, da_dv, inverse_mass = forward_dynamics_derivatives(
        plant.uvms,
        q,
        v,
        tau,
        flow=plant.water,
        time_s=time_s,
        tau_ext=tau_ext,
        backend=plant.backend,
        free_surface=plant.free_surface,
    )
    return da_dq + inverse_mass @ by_q, da_dv + inverse_mass @ by_v, inverse_mass


def _own_forces(
    plant: Any, data: pin.Data, time_s: float, q: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plant's own generalized force tau_g (nv,) at (q, v) and d tau_g/dq, d tau_g/dv
    (nv, nv): the sum of its parts' (the water's are `forward_dynamics_derivatives`');
    ``data``: a Pinocchio data of the plant's model to work in."""
    nv = plant.uvms.nv
    tau_ext, by_q, by_v = np.zeros(nv), np.zeros((nv, nv)), np.zeros((nv, nv))
    forces = None
    if plant.world is not None:
        pin.forwardKinematics(plant.uvms.model, data, q, v)
        forces = plant.world.forces(data, plant.friction)
    if forces is not None and len(forces.touch):
        tau_ext += plant.world.generalized_force(q, data, forces)
        world_q, world_v = world_contact_jacobians(plant.world, q, v, forces, plant.friction)
        by_q, by_v = by_q + world_q, by_v + world_v
    if plant.contact is not None:  # tau = -J^T lambda, lambda on the environment
        task = TaskContact(plant.uvms.ee_frame_id, plant.contact)  # refuses other models
        state, jacobians = contact_derivatives(task, plant.uvms.model, data, q, v)
        tau_ext += state.tau_ext
        by_q, by_v = by_q + jacobians.tau_dq, by_v + jacobians.tau_dv
    if plant.joint_friction is not None:
        tau_ext[6:] += plant.joint_friction.torque_Nm(v[6:])
        by_v += joint_friction_jacobian(plant.joint_friction, v)
    if plant.disturbance is not None:
        tau_ext[:6] -= plant.disturbance_wrench(time_s)
    if plant.joint_stops is not None:
        tau_ext += plant.joint_stops.torque(q, v)
        stop_q, stop_v = joint_stop_jacobians(plant.joint_stops, q, v)
        by_q, by_v = by_q + stop_q, by_v + stop_v
    return tau_ext, by_q, by_v
