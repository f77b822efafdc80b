"""Underwater dynamics of a UVMS (docs/physics.md, after Schjolberg & Fossen 1994).

    M(q) zeta_dot + h(q, zeta) = tau + tau_ext

    M(q)      = M_RB(q) + sum_i J_i^T M_A,i J_i                    (added mass inside M)
    h(q,zeta) = C_RB zeta + g_RB
              - sum_i J_i^T [ -M_A,i (a_i^bias - nu_c_dot,i) - C_A,i(nu_r,i) nu_r,i
                              - D_i(nu_r,i) nu_r,i + w_buoy,i ]

with J_i the LOCAL body Jacobian of joint i, nu_r,i = nu_i - nu_c,i the current-relative
body velocity and a_i^bias the body acceleration at zero joint acceleration. tau_ext is the
generalized force of external wrenches (contact, disturbances): for a wrench w applied at a
frame, tau_ext = J_frame^T w.

Two implementations with one interface: `ReferenceDynamics` (`uvms_pin.physics.reference`),
the readable Python reference (``backend="python"``), and `CompiledDynamics`
(`uvms_pin.physics.compiled.dynamics`, ``backend="core"``, the default), the same quantities
in one C++ call, held to the reference by the tests. `dynamics_of` gives a UVMS's one; the
functions below are the public API on it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector, flag
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import FlowField, UniformCurrent
from uvms_pin.hydro.restoring import buoyancy_potential_energy
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import backend_named
from uvms_pin.physics.compiled.dynamics import CompiledDynamics
from uvms_pin.physics.configuration import OFF_MANIFOLD, checked_configuration
from uvms_pin.physics.derivatives.reference import (
    forward_dynamics_derivatives as reference_derivatives,
)
from uvms_pin.physics.kinematics import check_frame_id
from uvms_pin.physics.reference import ReferenceDynamics, check_time
from uvms_pin.physics.surface import WetState, wet_state

_NO_CURRENT = np.zeros(3)


def dynamics_of(uvms: UVMS, backend: str = "core") -> CompiledDynamics | ReferenceDynamics:
    """The dynamics of ``uvms`` in ``backend`` ("core": compiled, "python": the reference),
    built on first use and kept with it (``uvms.cache``)."""
    built = uvms.cache.get("dynamics")
    # a name, or refused by name in _build_dynamics (an array is not even a key)
    dynamics = None if built is None or not isinstance(backend, str) else built.get(backend)
    return _build_dynamics(uvms, backend) if dynamics is None else dynamics


def _build_dynamics(uvms: UVMS, backend: str) -> CompiledDynamics | ReferenceDynamics:
    compiled = backend_named(backend).compiled  # ParameterError for an unknown name
    reference = ReferenceDynamics(uvms)
    dynamics = CompiledDynamics(uvms, reference) if compiled else reference
    uvms.cache.setdefault("dynamics", {})[backend] = dynamics
    return dynamics


def _checked_flow(flow: FlowField | None) -> FlowField | None:
    if flow is not None and not isinstance(flow, FlowField):
        raise ParameterError(f"flow must be a uvms_pin.flow.FlowField, got {type(flow).__name__}")
    return flow


def _flow_of_call(current_world: np.ndarray, flow: FlowField | None) -> FlowField | None:
    """``flow`` when a call gives one: the current is then one of its fields, not an extra;
    without one, the uniform current (None: still water)."""
    current = finite_vector("current_world", current_world, 3)
    if flow is None:
        return UniformCurrent(current) if np.any(current) else None
    _checked_flow(flow)
    if np.any(current):
        raise ParameterError("give either current_world or flow, not both (add the fields)")
    return flow


def _on_manifold(
    dynamics: CompiledDynamics | ReferenceDynamics, uvms: UVMS, q: np.ndarray
) -> np.ndarray:
    """``q`` as the call takes it: on the configuration manifold (a quaternion of norm 0 or 2
    is a rotation that is none, and M, h of it would be returned silently). The reference's
    q is checked here; the core checks its own in its call (its refusal, caught by the
    caller, is checked again here to name the joint), at no cost on the way."""
    if isinstance(dynamics, CompiledDynamics):
        return q
    return checked_configuration("q", q, uvms.model)


def _named(uvms: UVMS, q: np.ndarray, call: Callable, *args):
    """``call(*args)``, a dynamics call on ``q``: the core's refusal of a q off the
    configuration manifold is raised again naming the joint (the reference's check); any
    other refusal as it is."""
    try:
        return call(*args)
    except ParameterError as refusal:
        if str(refusal) == OFF_MANIFOLD:
            checked_configuration("q", q, uvms.model)
        raise


def _finite_result(what: str, value: np.ndarray, uvms: UVMS, q, v=None) -> np.ndarray:
    """``value``, or an error when finite inputs gave a non-finite result (checked after,
    at no cost on the way of every call): ParameterError for a q off the configuration
    manifold (a quaternion of norm 1e300), else SimulationError for a speed whose square
    (quadratic damping, Coriolis) leaves the floating-point range."""
    flat = value.reshape(-1)
    # the product first: all finite unless it overflows (then the entries are looked at);
    # ndarray.dot, not @: 0.3 us for ten entries where the matmul ufunc takes 0.9
    if math.isfinite(flat.dot(flat)) or np.all(np.isfinite(flat)):
        return value
    checked_configuration("q", q, uvms.model)
    fastest = 0.0 if v is None else float(np.max(np.abs(np.asarray(v, dtype=float))))
    farthest = float(np.max(np.abs(np.asarray(q, dtype=float)[:3])))  # the vehicle's p
    raise SimulationError(
        f"{what} is not finite for finite inputs: the fastest entry of zeta, {fastest:.3g}, "
        f"or the vehicle's position, {farthest:.3g} m from the origin, is beyond what its "
        "products hold in floating point"
    )


def mass_matrix(
    uvms: UVMS,
    q: np.ndarray,
    *,
    backend: str = "core",
    free_surface: bool = False,
    flow: FlowField | None = None,
    time_s: float = 0.0,
) -> np.ndarray:
    """M(q) = M_RB(q) + sum_i J_i^T M_A,i J_i (nv x nv, symmetric positive definite).

    ``backend``: "core" (compiled, default) or "python" (the reference). ``free_surface``:
    each body's added mass scaled by its wet fraction under the surface of ``flow`` (z = 0
    in still water) at ``time_s``."""
    dynamics = dynamics_of(uvms, backend)
    free_surface = flag("free_surface", free_surface)
    q = _on_manifold(dynamics, uvms, q)
    if not free_surface:
        return _finite_result("M(q)", _named(uvms, q, dynamics.mass_matrix, q), uvms, q)
    at = (_checked_flow(flow), check_time(time_s), True)
    return _finite_result("M(q)", _named(uvms, q, dynamics.mass_matrix_in, q, *at), uvms, q)


def bias_forces(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    current_world: np.ndarray = _NO_CURRENT,
    *,
    flow: FlowField | None = None,
    time_s: float = 0.0,
    backend: str = "core",
    free_surface: bool = False,
) -> np.ndarray:
    """h(q, zeta): rigid Coriolis and gravity, added-mass bias and Coriolis, damping, buoyancy,
    and, in an accelerating flow, the Froude-Krylov and added-mass loads of the flow.

    Args:
        q: configuration (nq,). v: generalized velocity zeta (nv,).
        current_world: constant, uniform current velocity in the world frame [m/s]
            (shorthand for ``flow=UniformCurrent(current_world)``).
        flow: any `uvms_pin.flow.FlowField` (waves, sea states, varying currents).
        time_s: the time at which the flow is evaluated [s].
        backend: "core" (compiled, default) or "python" (the reference).
        free_surface: cut the bodies by the free surface (z = 0, or the waves' elevation):
            buoyancy and Froude-Krylov of the wet part, added mass and damping scaled by the
            wet fraction (`uvms_pin.physics.surface`). False: water without a top.
    """
    dynamics = dynamics_of(uvms, backend)
    free_surface = flag("free_surface", free_surface)
    q = _on_manifold(dynamics, uvms, q)
    if flow is None and not free_surface:
        h = _named(uvms, q, dynamics.bias_forces, q, v, current_world)
    else:
        at = (_flow_of_call(current_world, flow), check_time(time_s), free_surface)
        h = _named(uvms, q, dynamics.bias_forces_in, q, v, *at)
    return _finite_result("h(q, zeta)", h, uvms, q, v)


def forward_dynamics(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    current_world: np.ndarray = _NO_CURRENT,
    tau_ext: np.ndarray | None = None,
    *,
    flow: FlowField | None = None,
    time_s: float = 0.0,
    backend: str = "core",
    free_surface: bool = False,
) -> np.ndarray:
    """zeta_dot = M(q)^-1 (tau + tau_ext - h(q, zeta)), by a Cholesky solve (no inverse).

    Args:
        tau: generalized input (nv,): body wrench on the vehicle [N; N m], joint torques.
        current_world: uniform constant current [m/s] (shorthand for a UniformCurrent).
        tau_ext: generalized force of external wrenches (nv,), e.g. from
            `frame_wrench_to_generalized`; None for none.
        flow, time_s: a `uvms_pin.flow.FlowField` and the time it is evaluated at [s].
        backend: "core" (compiled, default) or "python" (the reference).
        free_surface: cut the bodies by the free surface (see `bias_forces`).

    Raises:
        ParameterError: wrong shape or non-finite input.
        SimulationError: M not positive definite (e.g. a degenerate model).
    """
    dynamics = dynamics_of(uvms, backend)
    free_surface = flag("free_surface", free_surface)
    q = _on_manifold(dynamics, uvms, q)
    if flow is None and not free_surface:
        zeta_dot = _named(uvms, q, dynamics.forward_dynamics, q, v, tau, current_world, tau_ext)
    else:
        at = (_flow_of_call(current_world, flow), check_time(time_s), tau_ext, free_surface)
        zeta_dot = _named(uvms, q, dynamics.forward_dynamics_in, q, v, tau, *at)
    return _finite_result("zeta_dot", zeta_dot, uvms, q, v)


def forward_dynamics_derivatives(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    *,
    current_world: np.ndarray | None = None,
    flow: FlowField | None = None,
    time_s: float = 0.0,
    tau_ext: np.ndarray | None = None,
    backend: str = "core",
    free_surface: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(da/dq, da/dv, da/dtau) of zeta_dot = forward_dynamics(q, v, tau), each nv x nv.

    da/dq is taken along the tangent of the configuration manifold, a(q (+) dq) with
    ``pin.integrate`` (Pinocchio's `computeABADerivatives` convention), so it is nv x nv
    also when nq != nv. Every term is differentiated: added mass (inside M and in the bias
    accelerations), Kirchhoff C_A, linear and quadratic damping on the relative velocity,
    weight and buoyancy, the Froude-Krylov and added-mass loads of an accelerating flow, the
    flow sampled where the dynamics sample it (docs/derivatives.md). ``tau_ext`` (a
    generalized force) is held fixed; da/dtau = M^-1 is also d a / d tau_ext.

    Args:
        current_world: uniform constant current [m/s] (shorthand for a UniformCurrent).
        flow, time_s: a `uvms_pin.flow.FlowField` (it must give `gradient_kinematics`) and
            the time it is evaluated at [s].
        backend: "core" (compiled, default) or "python" (the reference).
        free_surface: the water has a top (see `bias_forces`). Where the surface cuts a
            hull, its wet-fraction terms are differentiated too (wet volume and centroid,
            scaled added mass and damping, the wet-fraction wrenches; the hull geometry's
            own pose Jacobian by differences of its wetting): docs/derivatives.md. Where a
            hull starts to touch the surface or becomes wholly wet or dry the dynamics have
            a kink: the derivative of the side the state is on is returned.
    """
    dynamics = dynamics_of(uvms, backend)
    water = water_of_call(uvms, current_world, flow)
    time_s, free_surface = check_time(time_s), flag("free_surface", free_surface)
    if isinstance(dynamics, CompiledDynamics):  # one compiled call, the checks in it
        out = dynamics.public_derivatives(q, v, tau, water, time_s, tau_ext, free_surface)
        if out is not None:
            return out
    # q on the manifold here (the core checks shapes and finiteness only); v, tau and
    # tau_ext are checked (shape, finite) by the reference and by the core
    q = checked_configuration("q", q, uvms.model)
    if isinstance(dynamics, ReferenceDynamics):
        out = reference_derivatives(uvms, q, v, tau, water, time_s, tau_ext, free_surface)
    else:
        out = dynamics.forward_dynamics_derivatives(q, v, tau, water, time_s, tau_ext, free_surface)
    for name, jacobian in zip(("da/dq", "da/dv", "da/dtau"), out, strict=True):
        _finite_result(name, jacobian, uvms, q, v)
    return out


def water_of_call(
    uvms: UVMS, current_world: np.ndarray | None, flow: FlowField | None
) -> FlowField | None:
    """The flow of a call given ``current_world`` or ``flow`` (or neither: still water, None):
    ``flow`` (checked), or the uniform current.

    The same current gives the same `UniformCurrent` (kept in ``uvms.cache``): the compiled
    dynamics convert a flow once and keep it by identity, so a call repeated in one current
    (a rollout's derivatives, an optimal-control node) pays for no conversion."""
    if current_world is None:
        return _checked_flow(flow)
    if flow is not None:
        return _flow_of_call(current_world, flow)
    last = uvms.cache.get("uniform_current")
    # the bytes of a current checked before (finite, not zero): the same current, no check
    if (
        last is not None
        and type(current_world) is np.ndarray
        and current_world.dtype == np.float64
        and current_world.shape == (3,)
        and current_world.tobytes() == last[0]
    ):
        return last[1]
    current = finite_vector("current_world", current_world, 3)
    if not current.any():
        return None
    key = current.tobytes()
    if last is None or last[0] != key:
        last = (key, UniformCurrent(current.copy()))
        uvms.cache["uniform_current"] = last
    return last[1]


def frame_wrench_to_generalized(
    uvms: UVMS, q: np.ndarray, frame_id: int, wrench_world_aligned: np.ndarray
) -> np.ndarray:
    """tau_ext = J^T w for a wrench at a frame origin, in world-aligned axes [N; N m].

    Raises:
        ParameterError: q not a finite configuration, frame_id not a frame, the wrench not
            6 finite numbers.
    """
    model, data = uvms.model, uvms.data
    q = checked_configuration("q", q, model)
    frame_id = check_frame_id(model, frame_id)
    wrench = finite_vector("wrench_world_aligned", wrench_world_aligned, 6)
    jac = pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL_WORLD_ALIGNED)
    return jac.T @ wrench


def kinetic_energy(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    *,
    backend: str = "core",
    free_surface: bool = False,
    flow: FlowField | None = None,
    time_s: float = 0.0,
) -> float:
    """T = 1/2 zeta^T M(q) zeta [J], added mass (the entrained fluid) included (scaled by
    the wet fractions with ``free_surface``)."""
    v = finite_vector("v", v, uvms.nv)
    mass = mass_matrix(
        uvms, q, backend=backend, free_surface=free_surface, flow=flow, time_s=time_s
    )
    # the quadratic form of finite entries may still overflow (a speed of 1e200)
    return float(_finite_result("T", np.array(0.5 * v @ mass @ v), uvms, q, v))


def potential_energy(
    uvms: UVMS,
    q: np.ndarray,
    *,
    free_surface: bool = False,
    flow: FlowField | None = None,
    time_s: float = 0.0,
) -> float:
    """U = U_gravity + U_buoyancy [J] (zero at z = 0): U_buoyancy = rho g . (V r_b) summed
    over the joints, with the wet volumes and centroids under a ``free_surface`` (then, in
    still water, U is the potential of the exact hydrostatic load: its negative gradient is
    rho g V_sub at r_sub; under waves the water does work and U is the same formula at
    ``time_s``)."""
    q = checked_configuration("q", q, uvms.model)
    free_surface = flag("free_surface", free_surface)
    model, data = uvms.model, uvms.data
    pin.forwardKinematics(model, data, q)
    wet = wet_state(uvms, data, _checked_flow(flow), check_time(time_s)) if free_surface else None
    energy = potential_energy_placed(uvms, data, q, wet)
    return float(_finite_result("U", np.array(energy), uvms, q))


def potential_energy_placed(
    uvms: UVMS, data: pin.Data, q: np.ndarray, wet: WetState | None
) -> float:
    """`potential_energy` at ``q`` once the forward kinematics are in ``data`` and the wet
    state is known (``wet``: `wet_state` there, None deep or without a free surface): a log
    that also records the wet fractions computes them once."""
    model = uvms.model
    energy = float(pin.computePotentialEnergy(model, data, q))
    volumes = uvms.volume_per_joint_m3 if wet is None else wet.volume_per_joint_m3
    cobs = (
        uvms.center_of_buoyancy_per_joint_m if wet is None else wet.center_of_buoyancy_per_joint_m
    )
    for j in uvms.joints_with_volume:
        cob_world = data.oMi[j].act(cobs[j])
        energy += buoyancy_potential_energy(
            volumes[j], cob_world, uvms.water_density_kg_m3, model.gravity.linear
        )
    return energy
