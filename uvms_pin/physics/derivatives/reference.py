"""The derivatives of the forward dynamics in Python: the readable reference (the oracle the
compiled core is held to; docs/derivatives.md).

The forward dynamics a(q, v, tau) solve ID(q, v, a) = tau + tau_ext, where ID is the inverse
dynamics with the water in it: Pinocchio's RNEA with each joint body's fluid wrench
w_j(q, v, a) as an external force (added mass included: w_j holds -M_A,j a_j). Differentiating
the identity along the tangent,

    dID/dq = dRNEA/dq |_(w fixed) - sum_j J_j^T dw_j/dq          (likewise d/dv)
    dID/da = M = M_RB + sum_j J_j^T M_A,j J_j
    da/dq = -M^-1 dID/dq,   da/dv = -M^-1 dID/dv,   da/dtau = M^-1

`pin.computeRNEADerivatives` gives the first term (the wrenches held fixed in the joint
frames, their projection J_j^T moving with q); `fluid.fluid_wrench_jacobians` the second.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.configuration import checked_configuration
from uvms_pin.physics.derivatives.fluid import fluid_wrench_jacobians, hydrostatics
from uvms_pin.physics.derivatives.motion import JointMotion, joint_motions
from uvms_pin.physics.derivatives.surface import wet_term_jacobians
from uvms_pin.physics.reference import ReferenceDynamics, mass_solve
from uvms_pin.physics.reference import _fluid_wrenches as fluid_wrenches
from uvms_pin.physics.surface import WetState, wet_state


def hydro_joints(uvms: UVMS) -> list[int]:
    """The joints whose bodies carry a hydrodynamic term (added mass, volume or damping)."""
    damped = (int(j) for j in uvms.damping_joint_ids)
    return sorted({*uvms.joints_with_added_mass, *uvms.joints_with_volume, *damped})


def inverse_dynamics_derivatives(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    a: np.ndarray,
    flow: FlowField | None,
    time_s: float,
    free_surface: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, JointMotion]]:
    """(dID/dq, dID/dv, M, the joint motions) at (q, v, a), water included (nv x nv each);
    ``free_surface``: the hulls cut by the surface (`derivatives.surface`)."""
    model, data = uvms.model, uvms.data
    motions = joint_motions(model, data, q, v, a, hydro_joints(uvms))
    # forward kinematics at (q, v, a) is in data: the wrenches hold -M_A a_j, a_j the body's
    # whole acceleration
    wet: WetState | None = wet_state(uvms, data, flow, time_s) if free_surface else None
    fext = fluid_wrenches(uvms, flow, time_s, wet)
    dw_dq, dw_dv = fluid_wrench_jacobians(uvms, motions, flow, time_s, wet)
    if wet is not None:
        surface_dq, surface_dv = wet_term_jacobians(uvms, motions, flow, time_s, wet)
        dw_dq, dw_dv = dw_dq + surface_dq, dw_dv + surface_dv
    added_mass = hydrostatics(uvms, wet)[2]
    did_dq, did_dv, mass = (
        np.array(m) for m in pin.computeRNEADerivatives(model, data, q, v, a, fext)
    )
    for j, motion in motions.items():
        jac = motion.jacobian
        did_dq -= jac.T @ dw_dq[j]
        did_dv -= jac.T @ dw_dv[j]
        mass += jac.T @ added_mass[j] @ jac
    return did_dq, did_dv, mass, motions


def inverse_of_mass(mass: np.ndarray, q: np.ndarray) -> np.ndarray:
    """M^-1 by a Cholesky factorisation (SimulationError if M is not positive definite)."""
    return mass_solve(mass, q, np.eye(len(mass)))


def forward_dynamics_derivatives(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    flow: FlowField | None,
    time_s: float,
    tau_ext: np.ndarray | None = None,
    free_surface: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(da/dq, da/dv, da/dtau) (nv x nv each) of the forward dynamics, q along the tangent;
    ``tau_ext`` (a generalized force, nv) is held fixed; ``free_surface``: the water has a
    top (the wet-fraction terms of a cut hull included, `derivatives.surface`).
    ParameterError for a vector of the wrong shape or with a non-finite entry, or a q off
    the configuration manifold (`uvms_pin.physics.configuration`)."""
    q, v = checked_configuration("q", q, uvms.model), finite_vector("v", v, uvms.nv)
    tau = finite_vector("tau", tau, uvms.nv)
    if tau_ext is not None:
        tau_ext = finite_vector("tau_ext", tau_ext, uvms.nv)
    a = ReferenceDynamics(uvms).forward_dynamics_in(q, v, tau, flow, time_s, tau_ext, free_surface)
    did_dq, did_dv, mass, _ = inverse_dynamics_derivatives(
        uvms, q, v, a, flow, time_s, free_surface
    )
    inverse = inverse_of_mass(mass, q)
    return -inverse @ did_dq, -inverse @ did_dv, inverse
