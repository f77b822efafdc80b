"""The derivatives of the free surface's wet-fraction terms, for the hulls the surface cuts.

Under a free surface (`uvms_pin.physics.surface`) hull i on joint j has a wet volume V_i,
a wet moment m_i = V_i r_i, a wet fraction f_i, its gradient g_i (6,) over the joint's twist
and its rate f_t,i: the wetting x_i = (V_i, m_i, f_i, g_i, f_t,i), a function of the
joint's pose alone (and of the time). The fluid wrench of joint j depends on them through

    V_j = sum_i V_i,   r_j = sum_i m_i / V_j                 (buoyancy, Froude-Krylov)
    M_A,j = M_A,j^no hull + sum_i f_i M_A,i                  (added mass, Kirchhoff)
    w_i = E_i g_i - (g_i . nu + f_t,i) p_i,  p_i = M_A,i nu_r,  E_i = 1/2 nu_r . p_i
    damping of a damped body with a hull: f_i D(nu_r)

`fluid.fluid_wrench_jacobians` differentiates every term with x held (at its wet value);
this module adds the rest, each term's partial derivative in x chained through

    dx_i/dq = (dx_i/d delta) J_j          (delta: the joint's LOCAL twist, R -> R exp6(delta))

and the derivative of the wet-fraction wrench w_i through nu and nu_r (it is not in
`fluid`). The centre of buoyancy's move also moves the point where the flow is sampled:
dU = R^T G R dr_j, dA = R^T G_A R dr_j.

dx_i/d delta is the hull geometry's own Jacobian: the wet part's volume and moment, the
waterplane's area and moment (and, with waves, the surface over the hull's reference point)
as the body frame turns and moves. It is taken by 4-point central differences of
`Hull.wet` over the six pose directions (step 1e-6 of the hull's bounding radius: the
truncation error is negligible, the rounding ~1e-10 of the entry), not in closed form: the
waterplane's own derivatives (second moments, perimeter integrals) are not written.
Everything else is analytic.

Kinks. x is smooth while the surface cuts the hull and the waterplane crosses no edge or
vertex of a piece; where a hull starts to touch the surface, becomes fully wet or dry, or
(a polyhedron: a box, a mesh; a cylinder's rim) the waterplane crosses a vertex or an edge,
the dynamics have a kink (the waterplane's area and moment, hence g, are only continuous
there). A mesh has such kinks at the spacing of its vertices. There the derivative returned
is that of the side the state is on: a hull with f = 0 or f = 1 contributes none (its
wetting is held); a cut hull's differences span 2e-6 of its radius either side, and give
the smooth piece the state is on unless a kink lies within that span.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.flow import FlowField
from uvms_pin.hydro.added_mass import kirchhoff_jacobian, kirchhoff_wrench
from uvms_pin.hydro.damping import damping_wrench
from uvms_pin.hydro.hull import Hull, SurfaceAt
from uvms_pin.hydro.vector import skew
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.derivatives.fluid import FlowAtPoint, flow_at, flow_in_body
from uvms_pin.physics.derivatives.motion import JointMotion
from uvms_pin.physics.surface import WetState

#: the pose step of the hull geometry's differences, per metre of bounding radius
POSE_STEP = 1e-6
#: rows of the wetting vector x = (V, m (3), f, g (6), f_t)
VOLUME, MOMENT, FRACTION, GRADIENT, RATE = 0, slice(1, 4), 4, slice(5, 11), 11


def surface_over(flow: FlowField | None, time_s: float, point_world_m: np.ndarray) -> SurfaceAt:
    """The surface over a world point, as `uvms_pin.physics.surface` samples it."""
    if flow is None:
        return SurfaceAt()
    eta, rate, slope = flow.surface_kinematics(time_s, point_world_m[None, :2])
    return SurfaceAt(float(eta[0]), float(rate[0]), float(slope[0, 0]), float(slope[0, 1]))


def wetting_vector(hull: Hull, placement: pin.SE3, flow: FlowField | None, time_s: float):
    """x = (V [m^3], m [m^4] (3), f, g (6), f_t [1/s]) (12,) of a hull on a joint at
    ``placement`` (world <- joint), the surface sampled over its reference point."""
    center = placement.act(hull.bound_center_m)
    wetting = hull.wet(
        placement.rotation, placement.translation, surface_over(flow, time_s, center)
    )
    return np.r_[
        wetting.volume_m3,
        wetting.moment_m4,
        wetting.fraction,
        wetting.fraction_gradient,
        wetting.fraction_rate,
    ]


def wetting_jacobian(
    hull: Hull, bound_radius_m: float, placement: pin.SE3, flow: FlowField | None, time_s: float
) -> np.ndarray:
    """dx/d delta (12, 6) over the joint's LOCAL twist delta = [v; w] (placement ->
    placement exp6(delta)), by 4-point central differences (see the module docstring)."""
    step = POSE_STEP * max(bound_radius_m, 1e-3)
    out = np.zeros((12, 6))
    for k in range(6):
        delta = np.zeros(6)
        delta[k] = step

        def at(scale: float, delta=delta) -> np.ndarray:
            return wetting_vector(hull, placement * pin.exp6(scale * delta), flow, time_s)

        out[:, k] = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * step)
    return out


def _cut(wet: WetState) -> np.ndarray:
    """The hulls the surface cuts (0 < f < 1): the others' wetting is held."""
    return np.flatnonzero((wet.fraction > 0.0) & (wet.fraction < 1.0))


def wet_term_jacobians(
    uvms: UVMS,
    motions: dict[int, JointMotion],
    flow: FlowField | None,
    time_s: float,
    wet: WetState,
) -> tuple[np.ndarray, np.ndarray]:
    """(dw/dq, dw/dv) (njoints, 6, nv): what the free surface adds to
    `fluid.fluid_wrench_jacobians(..., wet)` (see the module docstring). Needs the joint
    placements at q in ``uvms.data`` (any forward kinematics at q)."""
    nj, nv = uvms.model.njoints, uvms.model.nv
    dw_dq, dw_dv = np.zeros((nj, 6, nv)), np.zeros((nj, 6, nv))
    bodies = uvms.surface_bodies
    cut = set(_cut(wet).tolist())
    # dx_i/dq of each cut hull: its geometry's Jacobian over the joint's twist, times J_j
    wetting_dq = {
        h: wetting_jacobian(
            bodies.hulls[h],
            float(bodies.bound_radius_m[h]),
            uvms.data.oMi[int(bodies.joint_ids[h])],
            flow,
            time_s,
        )
        @ motions[int(bodies.joint_ids[h])].jacobian
        for h in cut
    }
    for j in sorted({int(bodies.joint_ids[h]) for h in range(len(bodies))}):
        mine = [h for h in range(len(bodies)) if int(bodies.joint_ids[h]) == j]
        _joint_terms(uvms, j, mine, wetting_dq, motions[j], flow, time_s, wet, dw_dq, dw_dv)
    for body, j in enumerate(uvms.damping_joint_ids):
        hull = int(bodies.hull_of_damped[body])
        if hull in wetting_dq:
            dw_dq[int(j)] += np.outer(
                _damping_wrench_in_joint(uvms, body, motions[int(j)], flow, time_s),
                wetting_dq[hull][FRACTION],
            )
    return dw_dq, dw_dv


def _damping_wrench_in_joint(
    uvms: UVMS, body: int, motion: JointMotion, flow: FlowField | None, time_s: float
) -> np.ndarray:
    """X^T d(nu_r) (6,): damped body ``body``'s full (unscaled) drag, in its joint frame."""
    action = uvms.damping_action[body]
    origin = uvms.damping_origin_in_joint_m[body]
    seen = flow_in_body(
        motion,
        uvms.damping_rotation_in_joint[body],
        origin,
        flow_at(flow, time_s, motion.point(origin)),
    )
    relative = action @ motion.velocity - np.r_[seen.velocity, 0.0, 0.0, 0.0]
    return action.T @ damping_wrench(
        uvms.damping_linear[body], uvms.damping_quadratic[body], relative
    )


def _joint_terms(
    uvms: UVMS,
    j: int,
    hulls: list[int],
    wetting_dq: dict[int, np.ndarray],
    motion: JointMotion,
    flow: FlowField | None,
    time_s: float,
    wet: WetState,
    dw_dq: np.ndarray,
    dw_dv: np.ndarray,
) -> None:
    """Adds joint j's terms: hydrostatics and added mass through x, and the wet-fraction
    wrenches of its hulls (through x, nu and nu_r)."""
    bodies = uvms.surface_bodies
    nv = uvms.model.nv
    rotation = motion.rotation
    volume = float(wet.volume_per_joint_m3[j])
    cob = wet.center_of_buoyancy_per_joint_m[j]
    at_cob = flow_at(flow, time_s, motion.point(cob))
    seen = flow_in_body(motion, np.eye(3), cob, at_cob)
    # the joint's wet volume and centre of buoyancy: dV_j, dr_j = (dm_j - r_j dV_j) / V_j
    volume_dq, moment_dq = np.zeros(nv), np.zeros((3, nv))
    for h in hulls:
        if h in wetting_dq:
            volume_dq += wetting_dq[h][VOLUME]
            moment_dq += wetting_dq[h][MOMENT]
    cob_dq = (moment_dq - np.outer(cob, volume_dq)) / volume if volume > 0.0 else moment_dq * 0.0
    moves_water = flow is not None
    # the flow at the moved centre of buoyancy (body axes): dU, dA
    flow_dq = rotation.T @ at_cob.gradient @ rotation @ cob_dq
    flow_rate_dq = rotation.T @ at_cob.acceleration_gradient @ rotation @ cob_dq
    if j in uvms.joints_with_volume:
        _hydrostatic_terms(uvms, rotation, volume, cob, at_cob, volume_dq, cob_dq, dw_dq[j])
    if j not in uvms.joints_with_added_mass:
        return
    omega = motion.velocity[3:]
    relative = motion.velocity - np.r_[seen.velocity, 0.0, 0.0, 0.0]
    flow_twist_rate = np.r_[seen.acceleration - np.cross(omega, seen.velocity), 0.0, 0.0, 0.0]
    added = wet.added_mass_per_joint[j]
    if moves_water:  # M_A,j held, the flow sampled at the moved r_j
        dw_dq[j] += added @ np.vstack([flow_rate_dq - skew(omega) @ flow_dq, np.zeros((3, nv))])
        dw_dq[j] += kirchhoff_jacobian(added, relative) @ np.vstack([flow_dq, np.zeros((3, nv))])
    # d nu_r / dq with the flow sampled at the moving r_j (seen: r_j fixed in the joint)
    relative_dq = motion.velocity_dq - np.vstack([seen.velocity_dq + flow_dq, np.zeros((3, nv))])
    for h in hulls:
        added_h = bodies.added_mass_in_joint[h]
        if h in wetting_dq:  # M_A,j through f_h
            load = added_h @ (motion.acceleration - flow_twist_rate) + kirchhoff_wrench(
                added_h, relative
            )
            dw_dq[j] -= np.outer(load, wetting_dq[h][FRACTION])
        gradient, rate_t = wet.fraction_gradient[h], wet.fraction_rate[h]
        if not (np.any(gradient) or rate_t or h in wetting_dq):
            continue
        # w_h = E g - (g . nu + f_t) p,  p = M_A,h nu_r,  E = 1/2 nu_r . p
        momentum = added_h @ relative
        energy = 0.5 * relative @ momentum
        rate = gradient @ motion.velocity + rate_t
        dw_dq[j] += (
            np.outer(gradient, momentum @ relative_dq)
            - np.outer(momentum, gradient @ motion.velocity_dq)
            - rate * added_h @ relative_dq
        )
        dw_dv[j] += (
            np.outer(gradient, momentum @ motion.jacobian)
            - np.outer(momentum, gradient @ motion.jacobian)
            - rate * added_h @ motion.jacobian
        )
        if h in wetting_dq:
            gradient_dq, rate_t_dq = wetting_dq[h][GRADIENT], wetting_dq[h][RATE]
            dw_dq[j] += energy * gradient_dq - np.outer(
                momentum, motion.velocity @ gradient_dq + rate_t_dq
            )


def _hydrostatic_terms(
    uvms: UVMS,
    rotation: np.ndarray,
    volume: float,
    cob: np.ndarray,
    at_cob: FlowAtPoint,
    volume_dq: np.ndarray,
    cob_dq: np.ndarray,
    out: np.ndarray,
) -> None:
    """Adds d[f; r x f]/dq through V_j and r_j (6, nv) to ``out``: f = R^T F,
    F = rho V (-g + Du/Dt(p_r)), the flow sampled at the centre of buoyancy p_r."""
    density = uvms.water_density_kg_m3
    per_volume = density * (at_cob.acceleration - uvms.model.gravity.linear)  # world [N/m^3]
    force_dq = np.outer(per_volume, volume_dq) + density * volume * (
        at_cob.acceleration_gradient @ rotation @ cob_dq
    )
    force_body = rotation.T @ (volume * per_volume)
    force_body_dq = rotation.T @ force_dq
    out[:3] += force_body_dq
    out[3:] += skew(cob) @ force_body_dq - skew(force_body) @ cob_dq
