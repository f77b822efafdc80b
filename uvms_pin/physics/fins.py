"""The fins' lift and drag as a generalized force: tau_fins = sum over fins of J_i^T f_i.

Each fin (`uvms_pin.model.uvms.Fin`) meets the water with the velocity of its centre of
pressure c (world) less the water's there, v_c = v_i + omega_i x (c - o_i) - u(t, c)
(gz-sim takes the link's velocity at c likewise, and subtracts the wind); its lift and
drag (`uvms_pin.hydro.lift_drag.lift_drag_wrench`) act at c with a moment M about the span.
As a spatial force at the world origin f = [F; M + c x F] it enters the dynamics through the
carrying joint's Jacobian in the world frame, tau = J_WORLD^T f.

With a free surface the fin works in the water only: its wrench is scaled by its wet
fraction w = clip(1/2 - (c_z - eta(t, c_xy)) / L, 0, 1), L = sqrt(A) the fin's size from its
area A: wholly wet with its centre of pressure L/2 below the surface, dry L/2 above it, a
ramp between (the fin's own extent across the surface, not its shape, which the LiftDrag
parameters do not give).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.flow import FlowField
from uvms_pin.hydro.lift_drag import lift_drag_wrench
from uvms_pin.hydro.vector import cross3
from uvms_pin.model.uvms import UVMS

__all__ = ["FinWrench", "fin_generalized_force", "fin_wrenches_world", "wet_fraction"]

#: a fin's (centre of pressure c [m], force F [N] at c, moment M [N m]), world axes
FinWrench = tuple[np.ndarray, np.ndarray, np.ndarray]


def wet_fraction(
    centre_m: np.ndarray, area_m2: float, water: FlowField | None, time_s: float
) -> float:
    """w [0, 1] of a fin of ``area_m2`` whose centre of pressure is ``centre_m`` (world):
    the module's ramp over L = sqrt(A) across the free surface eta(t, c_xy) of ``water``
    (None: the level surface z = 0)."""
    eta = 0.0 if water is None else float(water.surface_elevation(time_s, centre_m[None, :2])[0])
    size = np.sqrt(area_m2)
    if size == 0.0:
        return 1.0 if centre_m[2] <= eta else 0.0
    return float(np.clip(0.5 - (centre_m[2] - eta) / size, 0.0, 1.0))


def fin_wrenches_world(
    uvms: UVMS,
    data: pin.Data,
    q: np.ndarray,
    v: np.ndarray,
    water: FlowField | None = None,
    time_s: float = 0.0,
    free_surface: bool = False,
) -> list[FinWrench]:
    """Each fin's `FinWrench` at (q, v) in ``water`` (None: still water); with
    ``free_surface`` scaled by its `wet_fraction`; ``data`` is worked in (forward
    kinematics with velocities)."""
    pin.forwardKinematics(uvms.model, data, q, v)
    out = []
    for fin in uvms.fins:
        placement = data.oMi[fin.joint_id] * fin.placement_in_joint
        centre = placement.act(fin.params.cp_m)
        wet = wet_fraction(centre, fin.params.area_m2, water, time_s) if free_surface else 1.0
        if wet == 0.0:  # in the air: no lift, no drag
            out.append((centre, np.zeros(3), np.zeros(3)))
            continue
        motion = data.oMi[fin.joint_id].act(data.v[fin.joint_id])  # at the world origin
        velocity = motion.linear + cross3(motion.angular, centre)
        if water is not None:
            velocity = velocity - water.velocity(time_s, centre[None, :])[0]
        control = 0.0 if fin.control_q_index is None else float(q[fin.control_q_index])
        force, moment = lift_drag_wrench(fin.params, placement.rotation, velocity, control)
        out.append((centre, wet * force, wet * moment))
    return out


def fin_generalized_force(
    uvms: UVMS, data: pin.Data, q: np.ndarray, wrenches: list[FinWrench]
) -> np.ndarray:
    """tau_fins (nv,) [N, N m] of the fins' ``wrenches`` (`fin_wrenches_world` at this q)
    through their joints' Jacobians (the module's formula); zeros for a model without fins."""
    tau = np.zeros(uvms.nv)
    if not uvms.fins:
        return tau
    pin.computeJointJacobians(uvms.model, data, q)
    for fin, (centre, force, moment) in zip(uvms.fins, wrenches, strict=True):
        jacobian = pin.getJointJacobian(uvms.model, data, fin.joint_id, pin.WORLD)
        tau += jacobian.T @ np.concatenate([force, moment + cross3(centre, force)])
    return tau
