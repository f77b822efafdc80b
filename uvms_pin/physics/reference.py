"""The Python reference of the underwater dynamics: M, h and the forward dynamics of a UVMS
written out term by term, the readable specification the compiled core is held to
(docs/physics.md, after Schjolberg & Fossen 1994):

    M(q)      = M_RB(q) + sum_i J_i^T M_A,i J_i                    (added mass inside M)
    h(q,zeta) = C_RB zeta + g_RB
              - sum_i J_i^T [ -M_A,i (a_i^bias - nu_c_dot,i) - C_A,i(nu_r,i) nu_r,i
                              - D_i(nu_r,i) nu_r,i + w_buoy,i ]

with J_i the LOCAL body Jacobian of joint i, nu_r,i = nu_i - nu_c,i the current-relative
body velocity and a_i^bias the body acceleration at zero joint acceleration. Every function
works in the UVMS's Pinocchio data buffer; none allocates a model.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import FlowField, UniformCurrent
from uvms_pin.hydro.added_mass import kirchhoff_wrench
from uvms_pin.hydro.current import current_velocity_body, flow_twist_rate_body
from uvms_pin.hydro.damping import damping_wrench
from uvms_pin.hydro.restoring import buoyancy_wrench, froude_krylov_wrench
from uvms_pin.hydro.vector import mat_t_vec, mat_vec
from uvms_pin.model.hulls import SurfaceBodies
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.surface import WetState, wet_state


def check_time(time_s: float) -> float:
    """``time_s`` as a float, or ParameterError if it is not a finite number."""
    try:
        time_s = float(time_s)
    except (TypeError, ValueError):  # None, a string, an array of several
        raise ParameterError(f"time_s must be a finite number, got {time_s!r}") from None
    if not math.isfinite(time_s):  # math, not numpy: this check is on every dynamics call
        raise ParameterError(f"time_s must be finite, got {time_s}")
    return time_s


def _fluid_wrenches(
    uvms: UVMS, flow: FlowField | None, time_s: float, wet: WetState | None = None
) -> list[pin.Force]:
    """Wrench of the water on each joint body (LOCAL frame), all terms but M_A zeta_dot.

    Needs ``forwardKinematics(model, data, q, v, 0)`` in ``uvms.data`` (placements, body
    velocities and bias accelerations). The flow is sampled at each joint body's centre of
    buoyancy (its origin if it has no volume) for added mass and Froude-Krylov, and at each
    damped link's origin for damping. Under a free surface (``wet``, `physics.surface`) the
    volumes, centres of buoyancy and added masses are the wet ones, damping is scaled by the
    wet fraction and the added mass's change with it adds `wet_fraction_wrenches`. Vectorized
    over bodies: the per-body physics is the pure functions of `uvms_pin.hydro`, called once
    on stacks.
    """
    model, data = uvms.model, uvms.data
    nj = model.njoints
    rotation = np.array([data.oMi[j].rotation for j in range(nj)])  # (nj, 3, 3)
    velocity = np.array([data.v[j].vector for j in range(nj)])  # (nj, 6), LOCAL
    wrench = np.zeros((nj, 6))
    volumes = uvms.volume_per_joint_m3 if wet is None else wet.volume_per_joint_m3
    cobs = (
        uvms.center_of_buoyancy_per_joint_m if wet is None else wet.center_of_buoyancy_per_joint_m
    )
    if flow is not None:
        cob_world = np.array([data.oMi[j].act(cobs[j]) for j in range(nj)])
        flow_velocity_world, flow_acceleration_world = flow.velocity_and_acceleration(
            time_s, cob_world
        )

    joints = list(uvms.joints_with_added_mass)
    if joints:
        nu = velocity[joints]
        acc = np.array([data.a[j].vector for j in joints])
        if flow is not None:
            nu_c = current_velocity_body(rotation[joints], flow_velocity_world[joints])
            acc = acc - flow_twist_rate_body(
                rotation[joints], nu[:, 3:], nu_c[:, :3], flow_acceleration_world[joints]
            )
            nu = nu - nu_c
        added = (uvms.added_mass_per_joint if wet is None else wet.added_mass_per_joint)[joints]
        wrench[joints] -= mat_vec(added, acc) + kirchhoff_wrench(added, nu)
        if wet is not None:
            relative = velocity.copy()
            relative[joints] = nu
            wrench += wet_fraction_wrenches(uvms.surface_bodies, wet, velocity, relative)

    joints = list(uvms.joints_with_volume)
    if joints:
        volume, cob = volumes[joints], cobs[joints]
        wrench[joints] += buoyancy_wrench(
            volume, cob, rotation[joints], uvms.water_density_kg_m3, model.gravity.linear
        )
        if flow is not None:
            wrench[joints] += froude_krylov_wrench(
                volume,
                cob,
                rotation[joints],
                uvms.water_density_kg_m3,
                flow_acceleration_world[joints],
            )

    ids = uvms.damping_joint_ids
    if ids.size:
        nu_r = mat_vec(uvms.damping_action, velocity[ids])  # body velocity of each link
        if flow is not None:
            body_rotation = np.matmul(rotation[ids], uvms.damping_rotation_in_joint)
            origin_world = np.einsum(
                "kij,kj->ki", rotation[ids], uvms.damping_origin_in_joint_m
            ) + np.array([data.oMi[int(j)].translation for j in ids])
            nu_r = nu_r - current_velocity_body(body_rotation, flow.velocity(time_s, origin_world))
        wrench_body = damping_wrench(uvms.damping_linear, uvms.damping_quadratic, nu_r)
        if wet is not None:  # drag of the wet part: scaled by the wet fraction
            hull = uvms.surface_bodies.hull_of_damped
            wrench_body *= np.where(hull >= 0, wet.fraction[hull], 1.0)[:, None]
        # back to the joint frame: f_joint = X^T f_body
        np.add.at(wrench, ids, mat_t_vec(uvms.damping_action, wrench_body))
    return [pin.Force(w) for w in wrench]


def wet_fraction_wrenches(
    bodies: SurfaceBodies, wet: WetState, velocity: np.ndarray, relative_velocity: np.ndarray
) -> np.ndarray:
    """The wrench (nj, 6) on each joint of an added mass that changes with the wet fraction.

    Body i's fluid kinetic energy is T_i = f_i(q, t) 1/2 nu_r^T M_A,i nu_r; the Kirchhoff
    terms are those of the constant M_A,i, scaled by f_i. Lagrange's equations add, per body,

        w_i = -(df_i/dt) M_A,i nu_r + (1/2 nu_r^T M_A,i nu_r) g_i,   df_i/dt = g_i . nu + f_t,i

    (g_i = df_i / d(pose) over the joint's twist), which makes the exchange of energy with
    the entrained water exact: with the surface at rest and no damping, kinetic + potential
    energy is conserved. ``velocity`` and ``relative_velocity`` (nj, 6): each joint's twist
    nu and nu_r = nu - nu_c (LOCAL).
    """
    j = bodies.joint_ids
    momentum = mat_vec(bodies.added_mass_in_joint, relative_velocity[j])
    energy = 0.5 * np.einsum("hi,hi->h", relative_velocity[j], momentum)
    rate = np.einsum("hi,hi->h", wet.fraction_gradient, velocity[j]) + wet.fraction_rate
    out = np.zeros((len(velocity), 6))
    np.add.at(out, j, energy[:, None] * wet.fraction_gradient - rate[:, None] * momentum)
    return out


def _mass_matrix(uvms: UVMS, q: np.ndarray, wet: WetState | None = None) -> np.ndarray:
    model, data = uvms.model, uvms.data
    pin.crba(model, data, q)
    mass = np.triu(data.M)
    mass = mass + np.triu(mass, 1).T  # crba fills the upper triangle only
    added = uvms.added_mass_per_joint if wet is None else wet.added_mass_per_joint
    if uvms.joints_with_added_mass:
        pin.computeJointJacobians(model, data, q)
        for j in uvms.joints_with_added_mass:
            jac = pin.getJointJacobian(model, data, j, pin.LOCAL)
            mass += jac.T @ added[j] @ jac
    return mass


def _wet(uvms: UVMS, flow: FlowField | None, time_s: float, free_surface: bool) -> WetState | None:
    """The wet state after forward kinematics (None without a free surface or all deep)."""
    return wet_state(uvms, uvms.data, flow, time_s) if free_surface else None


def _bias_forces(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    flow: FlowField | None,
    time_s: float,
    free_surface: bool = False,
) -> tuple[np.ndarray, WetState | None]:
    """(h, the wet state it was computed in)."""
    model, data = uvms.model, uvms.data
    zero = np.zeros(model.nv)
    pin.forwardKinematics(model, data, q, v, zero)
    wet = _wet(uvms, flow, time_s, free_surface)
    fext = _fluid_wrenches(uvms, flow, time_s, wet)
    # rnea(q, v, 0, fext) = C_RB v + g_RB - sum_i J_i^T fext_i
    return pin.rnea(model, data, q, v, zero, fext).copy(), wet


def _solve(uvms: UVMS, q: np.ndarray, rhs: np.ndarray, wet: WetState | None) -> np.ndarray:
    """M(q)^-1 rhs by a Cholesky factorisation (no inverse)."""
    return mass_solve(_mass_matrix(uvms, q, wet), q, rhs)


def mass_solve(mass: np.ndarray, q: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``mass``^-1 rhs by a Cholesky factorisation (SimulationError naming q if the mass
    matrix at q is not positive definite)."""
    # scipy.linalg is imported where it is used: a compiled run never calls this, and would
    # otherwise pay a sixth of a second at start-up
    from scipy.linalg import cho_factor, cho_solve

    try:
        factor = cho_factor(mass, lower=False, check_finite=False)
    except np.linalg.LinAlgError as exc:
        raise SimulationError(f"mass matrix is not positive definite at q = {q}") from exc
    return cho_solve(factor, rhs, check_finite=False)


class ReferenceDynamics:
    """M, h and the forward dynamics of one UVMS, in Python: the readable reference.

    The ``*_in`` methods take any `uvms_pin.flow.FlowField` evaluated at ``time_s``; the
    others a uniform, constant current (3,) [m/s] in the world frame. ``free_surface``:
    the bodies are cut by the free surface (`uvms_pin.physics.surface`); without it the
    water has no top (every body is wholly wet).
    """

    def __init__(self, uvms: UVMS):
        self.uvms = uvms

    def _q(self, q) -> np.ndarray:
        return finite_vector("q", q, self.uvms.nq)

    def _state(self, q, v) -> tuple[np.ndarray, np.ndarray]:
        """(q, v) checked: v too whenever a call takes one (None is refused by name)."""
        return self._q(q), finite_vector("v", v, self.uvms.nv)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return _mass_matrix(self.uvms, self._q(q))

    def mass_matrix_in(
        self, q: np.ndarray, flow: FlowField | None, time_s: float, free_surface: bool = False
    ) -> np.ndarray:
        q = self._q(q)
        pin.forwardKinematics(self.uvms.model, self.uvms.data, q)
        wet = _wet(self.uvms, flow, check_time(time_s), free_surface)
        return _mass_matrix(self.uvms, q, wet)

    def bias_forces(self, q: np.ndarray, v: np.ndarray, current_world: np.ndarray) -> np.ndarray:
        return self.bias_forces_in(q, v, _uniform(current_world), 0.0)

    def bias_forces_in(
        self,
        q: np.ndarray,
        v: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        free_surface: bool = False,
    ) -> np.ndarray:
        q, v = self._state(q, v)
        return _bias_forces(self.uvms, q, v, flow, check_time(time_s), free_surface)[0]

    def forward_dynamics(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        current_world: np.ndarray,
        tau_ext: np.ndarray | None = None,
    ) -> np.ndarray:
        return self.forward_dynamics_in(q, v, tau, _uniform(current_world), 0.0, tau_ext)

    def forward_dynamics_in(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        tau_ext: np.ndarray | None = None,
        free_surface: bool = False,
    ) -> np.ndarray:
        q, v = self._state(q, v)
        bias, wet = _bias_forces(self.uvms, q, v, flow, check_time(time_s), free_surface)
        rhs = finite_vector("tau", tau, self.uvms.nv) - bias
        if tau_ext is not None:
            rhs += finite_vector("tau_ext", tau_ext, self.uvms.nv)
        return _solve(self.uvms, q, rhs, wet)


def _uniform(current_world: np.ndarray) -> UniformCurrent | None:
    """The flow of a uniform current (None in still water)."""
    current = finite_vector("current_world", current_world, 3)
    return UniformCurrent(current) if np.any(current) else None
