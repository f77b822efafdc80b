"""Physics of the dynamics: structure of M and C, Jacobians, energy, analytic cases."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF, RHO, body_urdf, hydro_xml, random_configuration

import uvms_pin as up
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.uvms import UVMS, HydroBody
from uvms_pin.sim.integrators import RK4


def _rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def test_mass_matrix_symmetric_positive_definite(reference_uvms):
    rng = _rng(1)
    for _ in range(50):
        q = random_configuration(reference_uvms, rng)
        mass = up.mass_matrix(reference_uvms, q)
        # symmetric to round-off of the 6x6 congruences (entries are O(10) kg)
        np.testing.assert_allclose(mass, mass.T, rtol=0, atol=1e-12)
        assert np.min(np.linalg.eigvalsh(mass)) > 0.0


def test_added_mass_is_inside_mass_matrix(reference_uvms):
    """M - M_RB = sum_i J_i^T M_A,i J_i is positive semi-definite and not zero."""
    q = random_configuration(reference_uvms, _rng(2))
    model, data = reference_uvms.model, reference_uvms.model.createData()
    rigid = pin.crba(model, data, q)
    rigid = np.triu(rigid) + np.triu(rigid, 1).T
    added = up.mass_matrix(reference_uvms, q) - rigid
    assert np.min(np.linalg.eigvalsh(added)) > -1e-10
    assert np.linalg.norm(added) > 1.0  # kg: the hull alone entrains several kg of water


def test_rigid_mdot_minus_2c_is_skew(reference_uvms):
    """Mdot - 2C is skew-symmetric for Pinocchio's rigid-body C (Christoffel form).

    Mdot by central differences along q(t) = integrate(q, t v), step 1e-6: truncation
    O(h^2 |d3M|) ~ 1e-12 and round-off ~ 1e-16 |M| / h ~ 1e-9 relative to |M| ~ 20.
    """
    model = reference_uvms.model
    data = model.createData()
    rng = _rng(3)
    h = 1e-6
    for _ in range(10):
        q = random_configuration(reference_uvms, rng)
        v = rng.normal(size=model.nv)

        def rigid_mass(qq):
            m = pin.crba(model, data, qq)
            return np.triu(m) + np.triu(m, 1).T

        mdot = (
            rigid_mass(pin.integrate(model, q, h * v)) - rigid_mass(pin.integrate(model, q, -h * v))
        ) / (2 * h)
        coriolis = pin.computeCoriolisMatrix(model, data, q, v)
        skew = mdot - 2.0 * coriolis
        np.testing.assert_allclose(skew, -skew.T, atol=1e-6)


def test_added_mass_velocity_terms_are_power_consistent(reference_uvms):
    """zeta^T (1/2 Mdot zeta - c(q, zeta)) = 0 with the full M (added mass included).

    c = h(q, zeta) - h(q, 0) with damping off: the rigid Coriolis, the added-mass bias
    M_A a_bias and the Kirchhoff term C_A. The identity is what makes 1/2 zeta^T M zeta the
    conserved energy. Mdot by central differences (step 1e-6, error ~1e-8 relative).
    """
    uvms = reference_uvms.with_hydro(
        lambda b: HydroParams(
            b.params.volume_m3,
            b.params.center_of_buoyancy_m,
            b.params.added_mass,
            np.zeros(6),
            np.zeros(6),
        )
    )
    model = uvms.model
    rng = _rng(4)
    h = 1e-6
    for _ in range(10):
        q = random_configuration(uvms, rng)
        v = rng.normal(size=model.nv)
        mdot = (
            up.mass_matrix(uvms, pin.integrate(model, q, h * v))
            - up.mass_matrix(uvms, pin.integrate(model, q, -h * v))
        ) / (2 * h)
        velocity_terms = up.bias_forces(uvms, q, v) - up.bias_forces(uvms, q, np.zeros(model.nv))
        power = v @ (0.5 * mdot @ v - velocity_terms)
        scale = abs(v @ velocity_terms) + abs(0.5 * v @ mdot @ v) + 1.0
        assert abs(power) < 1e-6 * scale


def test_body_jacobians_match_finite_differences(reference_uvms):
    """LOCAL Jacobian column k = log6(oMf(q)^-1 oMf(q + e_k h)) / h; central differences,
    h = 1e-6, error O(h^2) ~ 1e-12 plus round-off ~ 1e-10."""
    model = reference_uvms.model
    data = model.createData()
    rng = _rng(5)
    frames = [reference_uvms.ee_frame_id, reference_uvms.sensor_frame_id] + [
        model.getFrameId(name) for name in ("base_link", "arm_link2", "arm_link4")
    ]
    h = 1e-6
    for _ in range(5):
        q = random_configuration(reference_uvms, rng)
        for fid in frames:
            jac = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL)
            pin.framesForwardKinematics(model, data, q)
            placement = data.oMf[fid].copy()
            fd = np.empty_like(jac)
            for k in range(model.nv):
                e = np.zeros(model.nv)
                e[k] = h
                pin.framesForwardKinematics(model, data, pin.integrate(model, q, e))
                plus = pin.log6(placement.inverse() * data.oMf[fid]).vector
                pin.framesForwardKinematics(model, data, pin.integrate(model, q, -e))
                minus = pin.log6(placement.inverse() * data.oMf[fid]).vector
                fd[:, k] = (plus - minus) / (2 * h)
            np.testing.assert_allclose(jac, fd, atol=1e-7)


def _balanced_undamped(uvms: UVMS) -> UVMS:
    """Same rigid body and added mass; buoyancy = weight at each body's CoG; no damping."""
    model = uvms.model
    bodies = []
    added = uvms.added_mass_per_joint
    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        params = HydroParams(
            inertia.mass / uvms.water_density_kg_m3,
            inertia.lever,
            added[j],
            np.zeros(6),
            np.zeros(6),
        )
        bodies.append(HydroBody(model.names[j], j, pin.SE3.Identity(), params))
    return dataclasses.replace(uvms, hydro_bodies=tuple(bodies))


def _integrate(uvms, q, v, duration, dt, current=None, tau=None, samples=100):
    tau = np.zeros(uvms.nv) if tau is None else tau
    current = np.zeros(3) if current is None else current

    def rhs(t, qq, vv):
        return up.forward_dynamics(uvms, qq, vv, tau, current)

    integrator = RK4(dt)
    out = [(0.0, q, v)]
    t = 0.0
    chunk = duration / samples
    for _ in range(samples):
        q, v = integrator.advance(uvms.model, rhs, t, q, v, t + chunk)
        t += chunk
        out.append((t, q, v))
    return out


def test_energy_conserved_without_damping(reference_uvms):
    """No damping, no current, buoyancy = weight at the CoG, no input: 1/2 zeta^T M zeta is
    constant; 10 s of RK4 at 1 ms with the arm swinging, relative drift < 1e-6."""
    uvms = _balanced_undamped(reference_uvms)
    q = uvms.neutral_configuration()
    q[7:] = [0.3, 0.4, -0.6, 0.2]
    v = np.array([0.2, -0.1, 0.05, 0.1, -0.2, 0.3, 1.0, -0.8, 1.2, 2.0])
    trajectory = _integrate(uvms, q, v, 10.0, 1e-3)
    energies = np.array([up.kinetic_energy(uvms, qq, vv) for _, qq, vv in trajectory])
    arm_travel = np.ptp([qq[7:] for _, qq, _ in trajectory], axis=0)
    assert np.all(arm_travel > 0.3)  # the arm really moves
    drift = np.max(np.abs(energies - energies[0])) / energies[0]
    assert drift < 1e-6, drift


@pytest.mark.parametrize("backend", ["core", "python"])
def test_kinetic_energy_is_the_bodies_plus_the_entrained_water(reference_uvms, backend):
    """T = T_RB + sum_i 1/2 nu_i^T M_A,i nu_i: Pinocchio's rigid-body kinetic energy plus
    the fluid kinetic energy of each body's added mass at its body velocity nu_i (LOCAL),
    at random states (1e-12 relative); doubling the velocities quadruples it."""
    uvms = reference_uvms
    model, data = uvms.model, uvms.model.createData()
    rng = np.random.default_rng(31)
    for _ in range(5):
        q = random_configuration(uvms, rng)
        v = rng.normal(scale=0.5, size=uvms.nv)
        rigid = pin.computeKineticEnergy(model, data, q, v)
        fluid = sum(
            0.5 * data.v[j].vector @ uvms.added_mass_per_joint[j] @ data.v[j].vector
            for j in range(1, model.njoints)
        )
        energy = up.kinetic_energy(uvms, q, v, backend=backend)
        assert fluid > 0.05 * rigid  # the water's share is not negligible
        assert energy == pytest.approx(rigid + fluid, rel=1e-12)
        assert up.kinetic_energy(uvms, q, 2.0 * v, backend=backend) == pytest.approx(
            4.0 * energy, rel=1e-12
        )


def _world_impulse(uvms: UVMS, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Sum over bodies of (I_i + M_A,i) nu_i mapped to the world frame [N s; N m s]."""
    model, data = uvms.model, uvms.model.createData()
    pin.forwardKinematics(model, data, q, v)
    total = pin.Force.Zero()
    for j in range(1, model.njoints):
        nu = data.v[j].vector
        total += data.oMi[j].act(
            pin.Force((model.inertias[j].matrix() + uvms.added_mass_per_joint[j]) @ nu)
        )
    return total.vector


def test_impulse_conserved_without_external_wrench(reference_uvms):
    """Body momentum plus fluid impulse (Kirchhoff) is constant in the world frame when no
    net external wrench acts. Energy alone cannot see a wrong C_A (it does no work); this
    can: without C_A the impulse drifts by O(1) N s in 2 s. RK4 at 1 ms keeps it to 1e-9."""
    uvms = _balanced_undamped(reference_uvms)
    q = uvms.neutral_configuration()
    q[7:] = [0.3, 0.4, -0.6, 0.2]
    v = np.array([0.2, -0.1, 0.05, 0.1, -0.2, 0.3, 1.0, -0.8, 1.2, 2.0])
    trajectory = _integrate(uvms, q, v, 2.0, 1e-3, samples=20)
    impulses = np.array([_world_impulse(uvms, qq, vv) for _, qq, vv in trajectory])
    assert np.linalg.norm(impulses[0]) > 1.0
    np.testing.assert_allclose(impulses, np.broadcast_to(impulses[0], impulses.shape), atol=1e-9)


def test_energy_never_increases_with_damping(reference_uvms):
    """With damping (and the model's own buoyancy and gravity), T + U is non-increasing;
    between 10 ms samples it may rise only by integration error (< 1e-9 J)."""
    uvms = reference_uvms
    q = uvms.neutral_configuration()
    q[7:] = [0.3, 0.4, -0.6, 0.2]
    v = np.array([0.4, -0.2, 0.1, 0.2, -0.3, 0.3, 1.0, -0.8, 1.2, 2.0])
    trajectory = _integrate(uvms, q, v, 5.0, 1e-3, samples=500)
    energies = np.array(
        [
            up.kinetic_energy(uvms, qq, vv) + up.potential_energy(uvms, qq)
            for _, qq, vv in trajectory
        ]
    )
    assert np.max(np.diff(energies)) < 1e-9
    assert energies[-1] < energies[0] - 0.01  # and it really dissipates


def test_damping_dissipates_at_random_states(reference_uvms):
    """zeta^T (h(q, zeta) - h_conservative) >= 0: damping removes power at any state."""
    undamped = reference_uvms.with_hydro(
        lambda b: HydroParams(
            b.params.volume_m3,
            b.params.center_of_buoyancy_m,
            b.params.added_mass,
            np.zeros(6),
            np.zeros(6),
        )
    )
    rng = _rng(6)
    for _ in range(50):
        q = random_configuration(reference_uvms, rng)
        v = rng.normal(size=reference_uvms.nv)
        dissipation = v @ (up.bias_forces(reference_uvms, q, v) - up.bias_forces(undamped, q, v))
        assert dissipation >= 0.0


# ---- analytic single-body cases ---------------------------------------------------------

MASS = 10.0
XU = 4.0
DL = 3.0
DQ = 20.0


def _neutral_body(
    load_body,
    *,
    cob=(0, 0, 0),
    added=(XU, 6, 8, 0.1, 0.2, 0.3),
    lin=(DL, 5, 5, 1, 1, 1),
    quad=(DQ, 30, 30, 1, 1, 1),
):
    return load_body(body_urdf(mass=MASS, hydro=hydro_xml(MASS / RHO, cob, added, lin, quad)))


def test_push_accelerates_by_total_mass(load_body):
    """At rest, F along surge gives u_dot = F / (m + X_udot), from the very first instant:
    added mass is inertia, not a force lagging one step behind."""
    uvms = _neutral_body(load_body)
    q = uvms.neutral_configuration()
    tau = np.zeros(6)
    tau[0] = 7.0
    acc = up.forward_dynamics(uvms, q, np.zeros(6), tau)
    np.testing.assert_allclose(acc[0], 7.0 / (MASS + XU), rtol=1e-12)
    np.testing.assert_allclose(acc[1:], 0.0, atol=1e-12)
    # and the same answer again: no hidden state carried between calls
    np.testing.assert_array_equal(up.forward_dynamics(uvms, q, np.zeros(6), tau), acc)
    dry = load_body(body_urdf(mass=MASS, hydro=hydro_xml(MASS / RHO)))
    np.testing.assert_allclose(
        up.forward_dynamics(dry, q, np.zeros(6), tau)[0], 7.0 / MASS, rtol=1e-12
    )


def test_free_decay_matches_closed_form(load_body):
    """(m + X_u) u_dot = -D_l u - D_q |u| u has, for u0 > 0,
    u(t) = D_l u0 / ((D_l + D_q u0) exp(D_l t / m_eff) - D_q u0).
    RK4 at 1 ms: local error ~ (dt / time constant)^5, agreement to 1e-8 relative."""
    uvms = _neutral_body(load_body)
    u0 = 1.5
    v = np.zeros(6)
    v[0] = u0
    trajectory = _integrate(uvms, uvms.neutral_configuration(), v, 5.0, 1e-3, samples=50)
    m_eff = MASS + XU
    for t, _q, vv in trajectory:
        expected = DL * u0 / ((DL + DQ * u0) * np.exp(DL * t / m_eff) - DQ * u0)
        np.testing.assert_allclose(vv[0], expected, rtol=1e-8)
        np.testing.assert_allclose(vv[1:], 0.0, atol=1e-12)
    # the position is the integral: x(t) = m_eff / D_q ln(1 + D_q u0 (1 - exp(-D_l t / m_eff)) / D_l)
    t_end, q_end, _ = trajectory[-1]
    x_expected = m_eff / DQ * np.log(1 + DQ * u0 * (1 - np.exp(-DL * t_end / m_eff)) / DL)
    np.testing.assert_allclose(q_end[0], x_expected, rtol=1e-8)


@pytest.mark.parametrize("angle", [0.1, 0.5, 1.2])
def test_restoring_moment(load_body, angle):
    """Centre of buoyancy d above the CoG, rolled by phi: the restoring moment is
    rho g V d sin(phi), so p_dot = -rho g V d sin(phi) / (I_xx + K_p) at rest."""
    d = 0.02
    uvms = _neutral_body(load_body, cob=(0, 0, d))
    q = uvms.neutral_configuration()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(angle, 0, 0)).coeffs()
    h = up.bias_forces(uvms, q, np.zeros(6))
    moment = RHO * 9.81 * (MASS / RHO) * d * np.sin(angle)
    np.testing.assert_allclose(h[3], moment, rtol=1e-12)  # h holds -w_buoy: +moment
    np.testing.assert_allclose(h[:3], 0.0, atol=1e-10)  # neutral: no net force
    acc = up.forward_dynamics(uvms, q, np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(acc[3], -moment / (0.1 + 0.1), rtol=1e-12)


def test_body_rights_itself(load_body):
    """Released at 0.8 rad of roll, the damped body returns upright (|roll| < 1e-3 rad after 20 s)."""
    uvms = _neutral_body(load_body, cob=(0, 0, 0.05))
    q = uvms.neutral_configuration()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.8, 0, 0)).coeffs()
    _, q_end, v_end = _integrate(uvms, q, np.zeros(6), 20.0, 2e-3, samples=10)[-1]
    roll = pin.rpy.matrixToRpy(pin.Quaternion(q_end[3:7]).toRotationMatrix())[0]
    assert abs(roll) < 1e-3
    assert np.linalg.norm(v_end) < 1e-3


def test_body_drifts_with_current(load_body):
    """A neutral body at rest in a uniform current 0.3 m/s reaches the current's velocity
    (world velocity within 1e-4 m/s after 30 s; time constant m_eff / D_l ~ 5 s)."""
    uvms = _neutral_body(load_body)
    current = np.array([0.3, -0.1, 0.05])
    q = uvms.neutral_configuration()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.1, -0.2, 0.7)).coeffs()  # any heading
    _, q_end, v_end = _integrate(uvms, q, np.zeros(6), 30.0, 5e-3, current=current, samples=10)[-1]
    rotation = pin.Quaternion(q_end[3:7]).toRotationMatrix()
    np.testing.assert_allclose(rotation @ v_end[:3], current, atol=1e-4)
    np.testing.assert_allclose(v_end[3:], 0.0, atol=1e-4)


def test_derivatives_follow_the_current_of_each_call(reference_uvms):
    """forward_dynamics_derivatives in current c2 right after a call in c1 are those of c2
    (what a fresh model gives in c2), and c1 again gives c1's: the uniform current kept
    between calls (to convert it once) is only reused for the very same current."""
    uvms = reference_uvms
    rng = np.random.default_rng(8)
    q = random_configuration(uvms, rng)
    v = rng.normal(scale=0.3, size=uvms.nv)
    tau = rng.normal(size=uvms.nv)
    c1, c2 = np.array([0.4, -0.2, 0.1]), np.array([-0.3, 0.5, 0.0])
    first = up.forward_dynamics_derivatives(uvms, q, v, tau, current_world=c1)
    second = up.forward_dynamics_derivatives(uvms, q, v, tau, current_world=c2)
    again = up.forward_dynamics_derivatives(uvms, q, v, tau, current_world=c1.copy())
    fresh = up.forward_dynamics_derivatives(
        up.load_uvms(REFERENCE_URDF), q, v, tau, current_world=c2
    )
    for k in range(2):  # da/dq and da/dv depend on the current
        assert not np.allclose(first[k], second[k], rtol=1e-6, atol=0.0)
        np.testing.assert_allclose(second[k], fresh[k], rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(again[k], first[k])


def test_a_frame_wrench_does_the_virtual_power_of_its_frame_twist(reference_uvms):
    """tau_ext = J^T w: its power on any zeta equals the wrench's power on the frame's
    twist, zeta . tau_ext = w . [v_frame; omega_frame] (world-aligned axes at the frame
    origin), for the end-effector and the vehicle's base frame."""
    uvms = reference_uvms
    model, data = uvms.model, uvms.model.createData()
    rng = np.random.default_rng(12)
    for frame in (uvms.ee_frame_id, model.getFrameId(model.frames[2].name)):
        q = random_configuration(uvms, rng)
        v = rng.normal(size=uvms.nv)
        wrench = rng.normal(size=6)
        tau_ext = up.frame_wrench_to_generalized(uvms, q, frame, wrench)
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        twist = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).vector
        assert v @ tau_ext == pytest.approx(wrench @ twist, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("backend", ["core", "python"])
@pytest.mark.parametrize(
    "quaternion", [[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 2.0], [0.1, 0.2, 0.3, 0.9]]
)
def test_a_quaternion_off_the_unit_sphere_is_refused_by_every_dynamics_call(
    reference_uvms, backend, quaternion
):
    """M, h, forward dynamics, the energies and the plant's right-hand side, in still water
    and under the free surface, refuse a q whose quaternion is not a rotation, naming the
    joint, as the derivatives do (a quaternion of zeros gave finite M, h of a rotation that
    is none, returned silently; of norm 2 a rotation scaled by 4). The core checks it in its
    call at no cost on the way (NORM_TOLERANCE, the same number on both sides)."""
    from uvms_pin.physics.compiled.extension import core_module
    from uvms_pin.physics.configuration import NORM_TOLERANCE, OFF_MANIFOLD

    assert core_module().NORM_TOLERANCE == NORM_TOLERANCE
    off = pin.neutral(reference_uvms.model)
    off[3:7] = quaternion
    with pytest.raises(ParameterError) as refused:  # the core's own words, named in Python
        up.physics.dynamics.dynamics_of(reference_uvms, "core").mass_matrix(off)
    assert str(refused.value) == OFF_MANIFOLD
    uvms = reference_uvms
    q = pin.neutral(uvms.model)
    q[2] = -3.0
    q[3:7] = quaternion
    v = tau = np.zeros(uvms.nv)
    calls = {
        "M": lambda: up.mass_matrix(uvms, q, backend=backend),
        "M wet": lambda: up.mass_matrix(uvms, q, backend=backend, free_surface=True),
        "h": lambda: up.bias_forces(uvms, q, v, backend=backend),
        "a": lambda: up.forward_dynamics(uvms, q, v, tau, backend=backend),
        "a wet": lambda: up.forward_dynamics(uvms, q, v, tau, backend=backend, free_surface=True),
        "T": lambda: up.kinetic_energy(uvms, q, v, backend=backend),
        "U": lambda: up.potential_energy(uvms, q),
        "plant": lambda: up.Plant(uvms, backend=backend).acceleration(0.0, q, v, tau),
    }
    for name, call in calls.items():
        with pytest.raises(ParameterError, match=r"'root_joint' has a quaternion of norm"):
            call()
            pytest.fail(f"{name} took q[3:7] = {quaternion}")
    q[3:7] = (
        np.asarray(quaternion) / np.linalg.norm(quaternion) if any(quaternion) else [0, 0, 0, 1]
    )
    for call in calls.values():
        call()  # normalised: taken


@pytest.mark.parametrize("backend", ["core", "python"])
def test_speeds_whose_products_overflow_are_an_error_naming_them_not_an_inf(
    reference_uvms, backend
):
    """Finite speeds of 1e200 (their squares, in the damping and the kinetic energy, leave
    the floating-point range): h, the forward dynamics and T are a SimulationError naming
    the fastest entry of zeta, on both backends. Was: T returned inf silently; the core's
    forward dynamics blamed the articulated-body inertia (not positive definite)."""
    uvms = reference_uvms
    q = pin.neutral(uvms.model)
    q[2] = -3.0
    fast, tau = np.full(uvms.nv, 1e200), np.zeros(uvms.nv)
    calls = {
        "h": lambda: up.bias_forces(uvms, q, fast, backend=backend),
        "a": lambda: up.forward_dynamics(uvms, q, fast, tau, backend=backend),
        "T": lambda: up.kinetic_energy(uvms, q, fast, backend=backend),
    }
    for name, call in calls.items():
        with (
            np.errstate(all="ignore"),
            pytest.raises(SimulationError, match=r"not finite for finite inputs: the fastest"),
        ):
            call()
            pytest.fail(f"{name} returned for speeds of 1e200")
    slow = np.full(uvms.nv, 0.1)  # the same calls at ordinary speeds: finite numbers
    assert math.isfinite(up.kinetic_energy(uvms, q, slow, backend=backend))
    assert np.all(np.isfinite(up.forward_dynamics(uvms, q, slow, tau, backend=backend)))
