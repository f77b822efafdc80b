"""The end-effector's compliant contact (`uvms_pin.physics.contact`) as a generalized force of
the state, and its derivatives along the tangent: what an optimal-control problem needs to
put the force task in its dynamics.

The environment's model gives lambda = [f; n] (N; N m), the wrench the end-effector exerts ON
it at the end-effector frame's origin p, world-aligned axes, as a function of p and of its
world velocity p_dot. The robot receives

    tau_ext(q, v) = -J(q)^T lambda(p(q), p_dot(q, v))          (J: LOCAL_WORLD_ALIGNED, 6 x nv)

Along the tangent (q (+) dq, v + dv), with J_p = J[:3] (dp = J_p dq, p_dot = J_p v):

    d lambda/dq = L_p J_p + L_pdot d(p_dot)/dq,     d lambda/dv = L_pdot J_p
    d tau_ext/dq = -d(J^T lambda)/dq |_(lambda fixed) - J^T d lambda/dq
    d tau_ext/dv = -J^T d lambda/dv

(L_p = d lambda/dp, L_pdot = d lambda/dp_dot (6 x 3), one function per contact model.)
p_dot = R nu_v with nu = [nu_v; nu_w] the frame's LOCAL velocity and R world <- frame; as R
moves to R exp([dtheta]x) with dtheta = J_w^local dq,

    d(p_dot)/dq = R (d nu_v/dq - [nu_v]x J_w^local)

(d nu/dq: Pinocchio's `getFrameVelocityDerivatives` in LOCAL.)

The term with lambda fixed: J^T lambda = J_W^T F with J_W the WORLD Jacobian (the joints'
screws in world coordinates) and F = [f; n + p x f] the same wrench about the world origin.
A column J_k of J_W moves with q only through the joints before it (m before or equal to
k on the path from the root): d J_k/dq_m = J_m x J_k (the motion cross product; zero for
m = k on a one-DoF joint; the free-flyer's own columns included, its tangent being in its
own frame). With (a x b) . F = -b . (a x* F):

    d(J_W^T F)/dq [k, m] = -J_k . (J_m x* F)   if m precedes-or-equals k, else 0
    and F moves with p:   d(J_W^T F)/dq += J_W^T [0; -[f]x J_p]   (d(p x f) = -f x dp)

Both models of the scenarios are covered: `LinearSpring` (L_p = diag(K), L_pdot = 0) and
`CompliantPlane` (inside, pushing: L_p = k n n^T, L_pdot = c n n^T; outside or pulling: 0 -
the max(0, .) is not differentiable at the kink, and its derivative there is taken from the
side where the contact is lost).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from pinocchio import skew  # [a]x (3, 3), compiled

from uvms_pin.errors import ParameterError
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring

__all__ = [
    "ContactJacobians",
    "ContactWrench",
    "TaskContact",
    "contact_derivatives",
    "contact_wrench",
    "wrench_jacobians",
]


def spring_jacobians(
    spring: LinearSpring, position_world_m: np.ndarray, velocity_world_m_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(d lambda/dp, d lambda/dp_dot) (6, 3) of f = K (p - p_0): (diag(K) [N/m], 0)."""
    by_position = np.zeros((6, 3))
    by_position[:3] = np.diag(spring.stiffness_N_m)
    return by_position, np.zeros((6, 3))


def plane_jacobians(
    plane: CompliantPlane, position_world_m: np.ndarray, velocity_world_m_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(d lambda/dp, d lambda/dp_dot) (6, 3) of f = -n max(0, k d + c d_dot), d = (p_s - p).n:
    (k n n^T [N/m], c n n^T [N s/m]) while the surface pushes, zero otherwise."""
    by_position, by_velocity = np.zeros((6, 3)), np.zeros((6, 3))
    wrench = plane.wrench_on_environment_world(position_world_m, velocity_world_m_s)
    if not np.any(wrench[:3]):
        return by_position, by_velocity
    normal = plane.normal_world
    by_position[:3] = plane.stiffness_N_m * np.outer(normal, normal)
    by_velocity[:3] = plane.damping_N_s_m * np.outer(normal, normal)
    return by_position, by_velocity


#: contact model class -> its (d lambda/dp, d lambda/dp_dot)
WRENCH_JACOBIANS: dict[type, Callable[..., tuple[np.ndarray, np.ndarray]]] = {
    LinearSpring: spring_jacobians,
    CompliantPlane: plane_jacobians,
}


def wrench_jacobians(
    contact: ContactModel, position_world_m: np.ndarray, velocity_world_m_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(d lambda/dp, d lambda/dp_dot) (6, 3) of ``contact``'s wrench at (p, p_dot).

    Raises:
        ParameterError: a contact model without derivatives here.
    """
    jacobians = WRENCH_JACOBIANS.get(type(contact))
    if jacobians is None:
        known = ", ".join(k.__name__ for k in WRENCH_JACOBIANS)
        raise ParameterError(
            f"no derivatives of the contact model {type(contact).__name__} (known: {known})"
        )
    return jacobians(contact, position_world_m, velocity_world_m_s)


@dataclass(frozen=True)
class TaskContact:
    """A contact model at a frame of a model: what an OCP's dynamics and its force cost see.

    Attributes:
        frame_id: the Pinocchio frame in contact (the end-effector's). model: the
            environment, placed (its anchor or surface point known: `ContactModel.attach`).
    """

    frame_id: int
    model: ContactModel

    def __post_init__(self) -> None:
        if type(self.model) not in WRENCH_JACOBIANS:
            wrench_jacobians(self.model, np.zeros(3), np.zeros(3))  # raises, naming it


@dataclass(frozen=True)
class ContactWrench:
    """The contact at one state: lambda (6,) on the environment [N; N m], tau_ext (nv,) on
    the robot, the frame's LOCAL_WORLD_ALIGNED Jacobian J (6, nv), p [m] and p_dot [m/s]."""

    wrench_world: np.ndarray
    tau_ext: np.ndarray
    jacobian_lwa: np.ndarray
    position_world_m: np.ndarray
    velocity_world_m_s: np.ndarray


def contact_wrench(
    contact: TaskContact, model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray
) -> ContactWrench:
    """The `ContactWrench` at (q, v); fills ``data``'s kinematics at (q, v) (joint placements,
    velocities, WORLD joint Jacobians, the frame's placement)."""
    pin.forwardKinematics(model, data, q, v)
    pin.computeJointJacobians(model, data, q)
    return _contact_in(contact, model, data)


def _contact_in(contact: TaskContact, model: pin.Model, data: pin.Data) -> ContactWrench:
    """The `ContactWrench` from ``data``'s joint placements, velocities and WORLD joint
    Jacobians (already at the state)."""
    placement = pin.updateFramePlacement(model, data, contact.frame_id)
    position = placement.translation.copy()
    velocity = pin.getFrameVelocity(model, data, contact.frame_id, pin.LOCAL_WORLD_ALIGNED).linear
    jacobian = pin.getFrameJacobian(model, data, contact.frame_id, pin.LOCAL_WORLD_ALIGNED)
    wrench = contact.model.wrench_on_environment_world(position, velocity)
    return ContactWrench(wrench, -jacobian.T @ wrench, jacobian, position, velocity.copy())


@dataclass(frozen=True)
class ContactJacobians:
    """The contact's derivatives along the tangent at one state.

    Attributes:
        wrench_dq, wrench_dv: d lambda/dq, d lambda/dv (6, nv).
        tau_dq, tau_dv: d tau_ext/dq, d tau_ext/dv (nv, nv).
    """

    wrench_dq: np.ndarray
    wrench_dv: np.ndarray
    tau_dq: np.ndarray
    tau_dv: np.ndarray


def supports_mask(model: pin.Model) -> np.ndarray:
    """(nv, nv) booleans: [k, m] true when velocity m's joint is velocity k's joint or one of
    its ancestors (where d J_k/dq_m = J_m x J_k can be non-zero)."""
    joint_of = np.empty(model.nv, dtype=int)
    for j in range(1, model.njoints):
        joint_of[model.idx_vs[j] : model.idx_vs[j] + model.nvs[j]] = j
    mask = np.zeros((model.nv, model.nv), dtype=bool)
    for k in range(model.nv):
        ancestors = set(model.supports[int(joint_of[k])])
        mask[k] = [int(joint_of[m]) in ancestors for m in range(model.nv)]
    return mask


def projection_dq(
    jacobian_world: np.ndarray, wrench_world_origin: np.ndarray, mask: np.ndarray
) -> np.ndarray:
    """d(J_W^T F)/dq (nv, nv) with F = [f; n] (6,) a fixed wrench about the world origin
    (world axes): [k, m] = -J_k . (J_m x* F) where ``mask`` [k, m] (`supports_mask`)."""
    force, moment = wrench_world_origin[:3], wrench_world_origin[3:]
    # -(J_m x* F) = -[w_m x f; v_m x f + w_m x n] = [[f]x w_m; [f]x v_m + [n]x w_m]
    linear, angular = jacobian_world[:3], jacobian_world[3:]
    by_force = skew(force)
    minus_dual = np.empty_like(jacobian_world)
    minus_dual[:3] = by_force @ angular
    minus_dual[3:] = by_force @ linear + skew(moment) @ angular
    return (jacobian_world.T @ minus_dual) * mask


def contact_derivatives(
    contact: TaskContact,
    model: pin.Model,
    data: pin.Data,
    q: np.ndarray,
    v: np.ndarray,
    mask: np.ndarray | None = None,
    at_state: ContactWrench | None = None,
) -> tuple[ContactWrench, ContactJacobians]:
    """The `ContactWrench` at (q, v) and its `ContactJacobians` (see the module docstring);
    ``mask``: `supports_mask` of ``model`` (computed when None); ``at_state``: the
    `ContactWrench` already computed at this (q, v) (`contact_wrench`: reused, not
    recomputed; None: computed here)."""
    mask = supports_mask(model) if mask is None else mask
    nv, fid = model.nv, contact.frame_id
    # the kinematics at (q, v) and the WORLD joint Jacobians, with their derivatives
    pin.computeForwardKinematicsDerivatives(model, data, q, v, np.zeros(nv))
    if at_state is None:
        state = _contact_in(contact, model, data)
    else:
        state = at_state
        pin.updateFramePlacement(model, data, fid)  # (what _contact_in leaves in data)
    local_dq, local_jacobian = pin.getFrameVelocityDerivatives(model, data, fid, pin.LOCAL)
    rotation = data.oMf[fid].rotation
    local_linear = rotation.T @ state.velocity_world_m_s
    velocity_dq = rotation @ (local_dq[:3] - skew(local_linear) @ local_jacobian[3:])
    by_position, by_velocity = wrench_jacobians(
        contact.model, state.position_world_m, state.velocity_world_m_s
    )
    position_dq = state.jacobian_lwa[:3]
    wrench_dq = by_position @ position_dq + by_velocity @ velocity_dq
    wrench_dv = by_velocity @ position_dq
    force, moment = state.wrench_world[:3], state.wrench_world[3:]
    about_origin = np.concatenate((force, moment + skew(state.position_world_m) @ force))
    jacobian_world = pin.getFrameJacobian(model, data, fid, pin.WORLD)
    # d(J^T lambda)/dq with lambda fixed: the projection's, and the moment arm p's
    fixed = projection_dq(jacobian_world, about_origin, mask)
    fixed += jacobian_world[3:].T @ (-skew(force) @ position_dq)
    tau_dq = -fixed - state.jacobian_lwa.T @ wrench_dq
    tau_dv = -state.jacobian_lwa.T @ wrench_dv
    return state, ContactJacobians(wrench_dq, wrench_dv, tau_dq, tau_dv)
