"""The derivatives of the world's contact forces (`uvms_pin.physics.world`) as a generalized
force: d tau_world / dq and d tau_world / dv at one state, for the corner contacts of a
robot piece on a plane (the seafloor, a wall: `touch` gives one point per corner below it).

At corner i (a point r_i fixed in joint j's frame, world position x_i, material velocity
v_i, the plane's normal n constant and its point p_0):

    delta_i = (p_0 - x_i) . n,   delta_dot_i = -n . v_i
    f_n,i = k delta_i max(0, 1 + d delta_dot_i)
    s_i = P (x_i - a_i),  v_t,i = P v_i   (P = I - n n^T, a_i the anchor; a sphere's s_i
        from its material point the period began at, `FrictionMemory.material`)
    f_trial,i = -k_t s_i - c_t v_t,i
    f_t,i = f_trial,i  (sticking patch),   sigma f_trial,i  (slipping patch),
        sigma = mu_k L / |T|,  L = sum_patch f_n,  T = sum_patch f_trial
    F_i = f_n,i n + f_t,i,   tau_world = sum_i J_i^T F_i = sum_j J_j^T w_j,
        w_j = sum_(i on j) [R^T F_i; r_i x R^T F_i]   (LOCAL joint wrench)

with, along the tangent (`motion.JointMotion`):

    dx_i = R (J^v - [r]x J^w) dq = J_i dq,   dv_i = R (dnu_v - [r]x dnu_w - [u]x J^w dq)
        + J_i dv  (u = nu_v + nu_w x r, the point's velocity in joint axes)
    d tau_world = (d J_j^T / dq) w_j dq + J_j^T (dw_j/dtheta J^w dq + dw_j/dF dF)

The first term (the projection moving with q, w_j held in the joint frame) is Pinocchio's:
RNEA(q, 0, 0, w) = g(q) - sum_j J_j^T w_j, so it is dg/dq - dRNEA/dq at zero velocity.

Frozen at the state (documented in docs/derivatives.md): the active set (which corners are
below the plane), each point's anchor and its patch's stick or slip state (the friction's
memory changes at the end of a control period, not within it), and which side of the
Hunt-Crossley max(0, .) the point is on (a point where 1 + d delta_dot <= 0 pulls no force
and has none of its derivative). A new contact anchors where it is: its stretch is zero
whatever the state, and so is its derivative. Where the active set or a max changes the
force has a kink; the derivative of the side the state is on is returned.

A sphere on a plane (coal's one point of the pair: the midpoint of the deepest points,
x = c - (R - delta/2) n, delta = R - (c - p_0) . n) slides on the sphere: dx = (I - n n^T/2) dc,
d delta = -n . dc, its velocity is the body's at x (d v gains w x (dx - the material
point's dx)) and the wrench's arm in the joint frame moves by R^T (dx - material dx).

Not differentiated (ParameterError): an ellipsoid's deepest point, a contact with a solid
object (coal's GJK/EPA point), free objects and self-collision.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.vector import skew
from uvms_pin.physics.derivatives.fluid import point_force_dq
from uvms_pin.physics.derivatives.motion import JointMotion, joint_motions
from uvms_pin.physics.world.world import ContactForces, FrictionMemory, World


def world_contact_jacobians(
    world: World,
    q: np.ndarray,
    v: np.ndarray,
    forces: ContactForces,
    memory: FrictionMemory,
) -> tuple[np.ndarray, np.ndarray]:
    """(d tau_world/dq, d tau_world/dv) (nv, nv) at (q, v) of the contact ``forces`` (found
    there with ``memory``'s anchors), q along the tangent (see the module)."""
    touch = forces.touch
    uvms = world.uvms
    model, nv = uvms.model, uvms.nv
    out_q, out_v = np.zeros((nv, nv)), np.zeros((nv, nv))
    if len(touch) == 0:
        return out_q, out_v
    for p, o, corner in touch.keys():
        sphere = isinstance(world.pieces[p].shape, coal.Sphere)
        if not world.objects[o].is_plane or (corner < 0 and not sphere):
            raise ParameterError(
                "the derivatives of a world contact cover a piece's corners or a sphere on a "
                f"plane; the contact of piece {p} with '{world.objects[o].name}' (coal's "
                "deepest point of an ellipsoid, or a solid object) is not differentiated"
            )
    data = model.createData()
    joints = sorted({world.pieces[int(p)].joint_id for p in touch.piece})
    motions = joint_motions(model, data, q, v, np.zeros(nv), joints)
    force_dq, force_dv, arms, slide = _force_jacobians(world, forces, memory, motions)
    # the projection J_j^T moving with q, the joint wrenches held (Pinocchio's RNEA)
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for i, p in enumerate(touch.piece):
        j = world.pieces[int(p)].joint_id
        motion = motions[j]
        force_body = motion.rotation.T @ forces.force_world_N[i]
        fext[j] += pin.Force(np.r_[force_body, np.cross(arms[i], force_body)])
    zero = np.zeros(nv)
    with_wrenches = np.array(pin.computeRNEADerivatives(model, data, q, zero, zero, fext)[0])
    gravity = np.array(pin.computeGeneralizedGravityDerivatives(model, data, q))
    out_q += gravity - with_wrenches
    # the wrenches' own change: the force turning into the joint's axes, and dF
    for i, p in enumerate(touch.piece):
        motion = motions[world.pieces[int(p)].joint_id]
        jac_t = motion.jacobian.T
        out_q += jac_t @ point_force_dq(forces.force_world_N[i], force_dq[i], arms[i], motion)
        # a sphere's point slides on it: its arm in the joint frame moves by R^T slide
        force_body = motion.rotation.T @ forces.force_world_N[i]
        out_q += jac_t[:, 3:] @ (-skew(force_body) @ motion.rotation.T @ slide[i])
        by_force = np.vstack([motion.rotation.T, skew(arms[i]) @ motion.rotation.T])
        out_v += jac_t @ by_force @ force_dv[i]
    return out_q, out_v


def _force_jacobians(
    world: World,
    forces: ContactForces,
    memory: FrictionMemory,
    motions: dict[int, JointMotion],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(dF_i/dq, dF_i/dv (m, 3, nv), r_i (m, 3) the points in their joints' frames, and
    how each point slides on its body (m, 3, nv): dx_i minus the material point's motion)."""
    touch, law = forces.touch, world.law
    m, nv = len(touch), world.uvms.nv
    normal = touch.normal_world
    arms = np.zeros((m, 3))
    point_dq, velocity_dq = np.zeros((m, 3, nv)), np.zeros((m, 3, nv))
    point_dv, slide = np.zeros((m, 3, nv)), np.zeros((m, 3, nv))
    measured_dq = np.zeros((m, 3, nv))  # where the stretch is measured from
    depth_dq = np.zeros((m, nv))
    for i, p in enumerate(touch.piece):
        piece = world.pieces[int(p)]
        motion = motions[piece.joint_id]
        rotation = motion.rotation
        arms[i] = rotation.T @ (touch.point_world_m[i] - motion.translation)
        r_hat = skew(arms[i])
        point_velocity = motion.velocity[:3] + np.cross(motion.velocity[3:], arms[i])
        material = motion.point_dq(arms[i])
        point_dv[i] = material  # d v / dv = J_i, the body's point there
        velocity_dq[i] = rotation @ (
            motion.velocity_dq[:3]
            - r_hat @ motion.velocity_dq[3:]
            - skew(point_velocity) @ motion.rotation_dq
        )
        if touch.corner[i] >= 0:  # a corner: a material point
            point_dq[i] = measured_dq[i] = material
            depth_dq[i] = -normal[i] @ material
            continue
        # a sphere: delta = R - (c - p_0) . n, x = c - (R - delta / 2) n
        center_dq = motion.point_dq(piece.placement_in_joint.translation)
        depth_dq[i] = -normal[i] @ center_dq
        point_dq[i] = center_dq - 0.5 * np.outer(normal[i], normal[i] @ center_dq)
        slide[i] = point_dq[i] - material
        velocity_dq[i] += skew(rotation @ motion.velocity[3:]) @ slide[i]
        # the stretch from the material point of the period's start (none: the point)
        held = memory.material.get((int(p), int(touch.obj[i]), -1))
        measured_dq[i] = point_dq[i] if held is None else motion.point_dq(held)
    # normal force: f_n = k delta max(0, 1 + d rate)
    rate = -np.einsum("ij,ij->i", touch.velocity_world_m_s, normal)
    damping = 1.0 + law.dissipation_s_m * rate
    pushing = (damping > 0.0)[:, None]
    k = law.stiffness_N_m
    rate_dq = -np.einsum("ik,ikn->in", normal, velocity_dq)
    rate_dv = -np.einsum("ik,ikn->in", normal, point_dv)
    normal_dq = np.where(
        pushing,
        k * damping[:, None] * depth_dq
        + k * touch.depth_m[:, None] * law.dissipation_s_m * rate_dq,
        0.0,
    )
    normal_dv = np.where(pushing, k * touch.depth_m[:, None] * law.dissipation_s_m * rate_dv, 0.0)
    # the trial friction: -k_t P (x - a) - c_t P v; a new contact's anchor moves with it
    projector = np.eye(3)[None] - normal[:, :, None] * normal[:, None, :]
    anchored = np.array([key in memory.anchors for key in touch.keys()], dtype=bool)
    stretch_dq = np.where(anchored[:, None, None], projector @ measured_dq, 0.0)
    trial_dq = -law.tangential_stiffness_N_m * stretch_dq - law.tangential_damping_N_s_m * (
        projector @ velocity_dq
    )
    trial_dv = -law.tangential_damping_N_s_m * (projector @ point_dv)
    friction_dq, friction_dv = _slipping_scaled(
        world, forces, (trial_dq, trial_dv), (normal_dq, normal_dv)
    )
    force_dq = normal[:, :, None] * normal_dq[:, None, :] + friction_dq
    force_dv = normal[:, :, None] * normal_dv[:, None, :] + friction_dv
    return force_dq, force_dv, arms, slide


def _slipping_scaled(
    world: World,
    forces: ContactForces,
    trial: tuple[np.ndarray, np.ndarray],
    normal: tuple[np.ndarray, np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """(dF_t,i/dq, dF_t,i/dv) (m, 3, nv): the trial friction's derivatives ``trial``, those of
    a slipping patch's points scaled: f_t,i = sigma f_trial,i, sigma = mu_k L / |T| (L the
    patch's normal load, T its summed trial force), d sigma from ``normal`` (df_n/dq, df_n/dv)."""
    touch = forces.touch
    trial_dq, trial_dv = trial
    normal_dq, normal_dv = normal
    friction_dq, friction_dv = trial_dq.copy(), trial_dv.copy()
    patch = touch.piece * len(world.objects) + touch.obj
    for group in np.unique(patch[~forces.sticking]):
        mine = np.flatnonzero(patch == group)
        mu = world._mu[int(touch.obj[mine[0]]), 1]
        load = float(forces.normal_N[mine].sum())
        trial_raw = _unscaled_trial(world, forces, mine)
        total = trial_raw.sum(axis=0)
        size = float(np.linalg.norm(total))
        if size == 0.0:
            continue
        sigma = mu * load / size
        for out, d_trial, d_normal in (
            (friction_dq, trial_dq, normal_dq),
            (friction_dv, trial_dv, normal_dv),
        ):
            d_total = d_trial[mine].sum(axis=0)
            d_sigma = mu * (d_normal[mine].sum(axis=0) / size - load * total @ d_total / size**3)
            for row, i in enumerate(mine):
                out[i] = sigma * d_trial[i] + np.outer(trial_raw[row], d_sigma)
    return friction_dq, friction_dv


def _unscaled_trial(world: World, forces: ContactForces, points: np.ndarray) -> np.ndarray:
    """f_trial = -k_t s - c_t P v (k, 3) at the given points (before a slip's scaling), s
    the stretch the forces were found with."""
    touch, law = forces.touch, world.law
    out = np.zeros((len(points), 3))
    for row, i in enumerate(points):
        n = touch.normal_world[i]
        v = touch.velocity_world_m_s[i]
        out[row] = -law.tangential_stiffness_N_m * forces.stretch_m[i] - (
            law.tangential_damping_N_s_m * (v - n * (v @ n))
        )
    return out
