"""The Jacobians of the water's wrench on each joint body, one function per hydrodynamic term.

Each term's wrench w (LOCAL joint frame, as `uvms_pin.physics.reference` computes it) depends
on the state through the body's velocity nu, acceleration a, rotation R and the world
position p of the point where the flow is sampled. With the flow seen in body axes,
U = R^T u(p) and A = R^T Du/Dt(p) (G = grad u, G_A = grad Du/Dt):

    dU = R^T G dp + [U]x dtheta,       dA = R^T G_A dp + [A]x dtheta

and each term is a pure function of those (`uvms_pin.hydro` holds the wrenches and their
partial derivatives). A new term (e.g. a wet fraction near the free surface) adds a function
here and a line in `fluid_wrench_jacobians`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvms_pin.flow import FlowField
from uvms_pin.hydro.added_mass import kirchhoff_jacobian
from uvms_pin.hydro.damping import damping_jacobian
from uvms_pin.hydro.restoring import point_force_jacobians
from uvms_pin.hydro.vector import skew
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.derivatives.motion import JointMotion
from uvms_pin.physics.surface import WetState

_IDENTITY = np.eye(3)


@dataclass(frozen=True)
class FlowAtPoint:
    """The undisturbed flow at one world point (world axes): u [m/s], grad u [1/s],
    Du/Dt [m/s^2] and grad Du/Dt [1/s^2]."""

    velocity: np.ndarray
    gradient: np.ndarray
    acceleration: np.ndarray
    acceleration_gradient: np.ndarray


STILL_WATER = FlowAtPoint(np.zeros(3), np.zeros((3, 3)), np.zeros(3), np.zeros((3, 3)))


def flow_at(flow: FlowField | None, time_s: float, point_world_m: np.ndarray) -> FlowAtPoint:
    """The flow's `FlowAtPoint` at a world point (still water for ``flow`` None)."""
    if flow is None:
        return STILL_WATER
    u, grad, material, material_grad = flow.material_gradients(time_s, point_world_m[None, :])
    return FlowAtPoint(u[0], grad[0], material[0], material_grad[0])


@dataclass(frozen=True)
class FlowInBody:
    """The flow seen by a body frame: U = R^T u, A = R^T Du/Dt (3,) and their d/dq (3, nv)."""

    velocity: np.ndarray
    velocity_dq: np.ndarray
    acceleration: np.ndarray
    acceleration_dq: np.ndarray


def flow_in_body(
    motion: JointMotion,
    rotation_in_joint: np.ndarray,
    point_in_joint_m: np.ndarray,
    flow: FlowAtPoint,
) -> FlowInBody:
    """The flow at a point of the joint body, in the axes of a frame R_jb fixed on it."""
    rotation = motion.rotation @ rotation_in_joint
    point_dq = motion.point_dq(point_in_joint_m)
    theta_dq = rotation_in_joint.T @ motion.rotation_dq  # in the frame's own axes
    velocity = rotation.T @ flow.velocity
    acceleration = rotation.T @ flow.acceleration
    return FlowInBody(
        velocity=velocity,
        velocity_dq=rotation.T @ flow.gradient @ point_dq + skew(velocity) @ theta_dq,
        acceleration=acceleration,
        acceleration_dq=rotation.T @ flow.acceleration_gradient @ point_dq
        + skew(acceleration) @ theta_dq,
    )


def _linear(block: np.ndarray) -> np.ndarray:
    """A (3, n) block as the linear rows of a (6, n) twist block (zero angular part)."""
    return np.vstack([block, np.zeros_like(block)])


def added_mass_jacobians(
    added_mass: np.ndarray, motion: JointMotion, seen: FlowInBody
) -> tuple[np.ndarray, np.ndarray]:
    """(dw/dq, dw/dv) (6, nv) of w = -M_A (a - nu_c_dot) - C_A(nu_r) nu_r.

    nu_r = nu - [U; 0] and nu_c_dot = [A - w x U; 0] (w the body's angular velocity), so
    d nu_c_dot = dA - [w]x dU + [U]x dw. The joint accelerations' part, -M_A J dqdd, is the
    added mass inside M (not a state derivative).
    """
    omega = motion.velocity[3:]
    relative = motion.velocity - np.r_[seen.velocity, 0.0, 0.0, 0.0]
    flow_rate_dq = (
        seen.acceleration_dq
        - skew(omega) @ seen.velocity_dq
        + skew(seen.velocity) @ motion.velocity_dq[3:]
    )
    flow_rate_dv = skew(seen.velocity) @ motion.jacobian[3:]
    kirchhoff = kirchhoff_jacobian(added_mass, relative)
    dw_dq = -added_mass @ (motion.acceleration_dq - _linear(flow_rate_dq)) - kirchhoff @ (
        motion.velocity_dq - _linear(seen.velocity_dq)
    )
    dw_dv = -added_mass @ (motion.acceleration_dv - _linear(flow_rate_dv)) - (
        kirchhoff @ motion.jacobian
    )
    return dw_dq, dw_dv


def point_force_dq(
    force_world_N: np.ndarray,
    force_world_dq: np.ndarray | None,
    point_in_joint_m: np.ndarray,
    motion: JointMotion,
) -> np.ndarray:
    """dw/dq (6, nv) of the wrench [R^T F; r x R^T F] of a world force F at a body point r,
    with dF/dq (3, nv) (None: F constant), e.g. buoyancy, Froude-Krylov, a contact."""
    force_body = motion.rotation.T @ force_world_N
    by_rotation, by_force = point_force_jacobians(force_body, point_in_joint_m, motion.rotation)
    dw_dq = by_rotation @ motion.rotation_dq
    if force_world_dq is not None:
        dw_dq = dw_dq + by_force @ force_world_dq
    return dw_dq


def hydrostatics(uvms: UVMS, wet: WetState | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(V_j (nj,), r_j (nj, 3), M_A,j (nj, 6, 6)) per joint: the model's, or the wet ones
    under a free surface (`uvms_pin.physics.surface`)."""
    if wet is None:
        return (
            uvms.volume_per_joint_m3,
            uvms.center_of_buoyancy_per_joint_m,
            uvms.added_mass_per_joint,
        )
    return wet.volume_per_joint_m3, wet.center_of_buoyancy_per_joint_m, wet.added_mass_per_joint


def restoring_jacobian(
    uvms: UVMS,
    joint: int,
    motion: JointMotion,
    flow: FlowAtPoint,
    moving_water: bool,
    wet: WetState | None = None,
) -> np.ndarray:
    """dw/dq (6, nv) of buoyancy -rho V g and the Froude-Krylov load rho V Du/Dt, at the
    joint body's centre of buoyancy (both world forces at a body point); V and r held (the
    wet ones under a free surface: their own change is `derivatives.surface`'s)."""
    volumes, cobs, _ = hydrostatics(uvms, wet)
    volume, cob = volumes[joint], cobs[joint]
    mass_of_water = uvms.water_density_kg_m3 * volume
    force = -mass_of_water * uvms.model.gravity.linear
    force_dq = None
    if moving_water:
        force = force + mass_of_water * flow.acceleration
        force_dq = mass_of_water * flow.acceleration_gradient @ motion.point_dq(cob)
    return point_force_dq(force, force_dq, cob, motion)


def damping_scale(uvms: UVMS, wet: WetState, body: int) -> float:
    """The wet fraction that scales damped body ``body``'s drag (1 for a body without a
    hull: always wet)."""
    hull = int(uvms.surface_bodies.hull_of_damped[body])
    return 1.0 if hull < 0 else float(wet.fraction[hull])


def damping_jacobians(
    uvms: UVMS, body: int, motion: JointMotion, flow: FlowAtPoint, scale: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """(dw/dq, dw/dv) (6, nv) in the joint frame of damped body ``body`` (its index in
    ``uvms.hydro_bodies_with_damping``): w = s X^T d(nu_r), nu_r = X nu - [U; 0] in the
    body's own frame (X the joint-to-body motion transform), d the damping wrench, s a held
    scale (the wet fraction under a free surface)."""
    action = uvms.damping_action[body]
    seen = flow_in_body(
        motion,
        uvms.damping_rotation_in_joint[body],
        uvms.damping_origin_in_joint_m[body],
        flow,
    )
    relative = action @ motion.velocity - np.r_[seen.velocity, 0.0, 0.0, 0.0]
    slope = (
        scale
        * action.T
        @ damping_jacobian(uvms.damping_linear[body], uvms.damping_quadratic[body], relative)
    )
    dw_dq = slope @ (action @ motion.velocity_dq - _linear(seen.velocity_dq))
    dw_dv = slope @ action @ motion.jacobian
    return dw_dq, dw_dv


def fluid_wrench_jacobians(
    uvms: UVMS,
    motions: dict[int, JointMotion],
    flow: FlowField | None,
    time_s: float,
    wet: WetState | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """d fext_j / dq and d fext_j / dv (njoints, 6, nv) of the fluid wrench on every joint
    body, the sum of its terms (the flow sampled where `uvms_pin.physics.reference` samples
    it: each joint body's centre of buoyancy, each damped link's origin). Under a free
    surface (``wet``) the wet volumes, centres of buoyancy, added masses and damping scales
    are used and held: their own change with the state is `derivatives.surface`'s."""
    nj, nv = uvms.model.njoints, uvms.model.nv
    dw_dq, dw_dv = np.zeros((nj, 6, nv)), np.zeros((nj, 6, nv))
    _, cob, added_mass = hydrostatics(uvms, wet)
    at_cob = {
        j: flow_at(flow, time_s, motions[j].point(cob[j]))
        for j in {*uvms.joints_with_added_mass, *uvms.joints_with_volume}
    }
    for j in uvms.joints_with_added_mass:
        seen = flow_in_body(motions[j], _IDENTITY, cob[j], at_cob[j])
        dq, dv = added_mass_jacobians(added_mass[j], motions[j], seen)
        dw_dq[j] += dq
        dw_dv[j] += dv
    for j in uvms.joints_with_volume:
        dw_dq[j] += restoring_jacobian(uvms, j, motions[j], at_cob[j], flow is not None, wet)
    for body, j in enumerate(uvms.damping_joint_ids):
        motion = motions[int(j)]
        origin = motion.point(uvms.damping_origin_in_joint_m[body])
        scale = 1.0 if wet is None else damping_scale(uvms, wet, body)
        dq, dv = damping_jacobians(uvms, body, motion, flow_at(flow, time_s, origin), scale)
        dw_dq[j] += dq
        dw_dv[j] += dv
    return dw_dq, dw_dv
