"""Floating bodies against the analytic cases: a box's draft and heave period, a sphere's
cap-volume root, the small-angle roll moment rho g V GM, a long cylinder lying; energy with
and without damping; the heave of a floating body in long waves."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, G, body_urdf, hydro_xml

import uvms_pin as up
from uvms_pin.flow import AiryWave
from uvms_pin.physics.floating import floating_equilibrium
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

A, B, C = 1.0, 0.6, 0.4  # box [m]
BOX_MASS = 0.4 * RHO * A * B * C  # floats at 40 % of its height
A33 = 150.0  # heave added mass of the whole box [kg]


def _box(load_body, *, damping=(0,) * 6, added=(60.0, 90.0, A33, 4.0, 5.0, 6.0)):
    m = BOX_MASS
    inertia = (m * (B * B + C * C) / 12, m * (A * A + C * C) / 12, m * (A * A + B * B) / 12)
    hydro = hydro_xml(A * B * C, added=added, lin=damping)
    return load_body(
        body_urdf(mass=m, inertia=inertia, hydro=hydro, collision=f'<box size="{A} {B} {C}"/>')
    )


def _at(uvms, z=0.0, rpy=(0.0, 0.0, 0.0)) -> np.ndarray:
    q = uvms.neutral_configuration()
    q[2] = z
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    return q


def _run(uvms, q, v, duration_s, step_s=1e-3, flow=None, every=10):
    """(t, q, v) sampled every ``every`` steps, the compiled plant, no input."""
    plant = Plant(uvms, flow=flow, free_surface=True)
    plant.attach(q)
    tau = np.zeros(uvms.nv)
    period = step_s * every
    out = [(0.0, q, v)]
    for k in range(round(duration_s / period)):
        q, v = System(plant).advance(RK4(step_s), k * period, q, v, tau, (k + 1) * period)
        out.append(((k + 1) * period, q, v))
    return out


def _energy(uvms, q, v, flow=None, time_s=0.0) -> float:
    kw = {"free_surface": True, "flow": flow, "time_s": time_s}
    return up.kinetic_energy(uvms, q, v, **kw) + up.potential_energy(uvms, q, **kw)


def test_a_floating_box_settles_at_its_draft(load_body):
    """d = m / (rho a b): the static equilibrium to 1e-9, a damped drop to 0.1 %."""
    draft = BOX_MASS / (RHO * A * B)
    uvms = _box(load_body, damping=(50, 50, 400, 40, 40, 40))
    q_eq = floating_equilibrium(uvms, _at(uvms, 0.1, (0.05, -0.03, 0.2)))
    assert C / 2 - q_eq[2] == pytest.approx(draft, rel=1e-9)
    np.testing.assert_allclose(
        pin.rpy.matrixToRpy(pin.Quaternion(q_eq[3:7]).toRotationMatrix())[:2], 0, atol=1e-7
    )
    samples = _run(uvms, _at(uvms, 0.3, (0.1, 0.05, 0.0)), np.zeros(6), 30.0, step_s=2e-3)
    assert C / 2 - samples[-1][1][2] == pytest.approx(draft, rel=1e-3)
    assert np.linalg.norm(samples[-1][2]) < 1e-3


def test_a_floating_sphere_settles_at_the_root_of_its_cap_cubic(load_body):
    """pi h^2 (3 r - h) / 3 = m / rho for the immersion h (numpy's roots of the cubic)."""
    r, m = 0.25, 0.3 * RHO * 4 / 3 * math.pi * 0.25**3
    inertia = (0.4 * m * r * r,) * 3
    uvms = load_body(
        body_urdf(
            mass=m,
            inertia=inertia,
            hydro=hydro_xml(4 / 3 * math.pi * r**3, lin=(300, 300, 300, 1, 1, 1)),
            collision=f'<sphere radius="{r}"/>',
        )
    )
    roots = np.roots([-math.pi / 3, math.pi * r, 0.0, -m / RHO])
    h = next(x.real for x in roots if abs(x.imag) < 1e-12 and 0 < x.real < 2 * r)
    q_eq = floating_equilibrium(uvms, _at(uvms, 0.2), free_attitude=False)
    assert r - q_eq[2] == pytest.approx(h, rel=1e-9)
    samples = _run(uvms, _at(uvms, -0.5), np.zeros(6), 20.0, step_s=2e-3)
    assert r - samples[-1][1][2] == pytest.approx(h, rel=1e-3)


def test_the_heave_period_of_a_floating_box(load_body):
    """T = 2 pi sqrt((m + f A33) / (rho g a b)), f the wet fraction at rest (added mass
    scaled by it), measured from the zero crossings of a 1 mm heave, to 0.1 %."""
    uvms = _box(load_body)
    q_eq = floating_equilibrium(uvms, _at(uvms), free_attitude=False)
    fraction = (C / 2 - q_eq[2]) / C
    expected = 2 * math.pi * math.sqrt((BOX_MASS + fraction * A33) / (RHO * G * A * B))
    q0 = q_eq.copy()
    q0[2] += 1e-3
    samples = _run(uvms, q0, np.zeros(6), 4.2 * expected, step_s=5e-4, every=1)
    t = np.array([s[0] for s in samples])
    z = np.array([s[1][2] for s in samples]) - q_eq[2]
    up_crossings = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    times = t[up_crossings] - z[up_crossings] * (t[up_crossings + 1] - t[up_crossings]) / (
        z[up_crossings + 1] - z[up_crossings]
    )
    assert len(times) >= 3
    assert np.mean(np.diff(times)) == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("axis", [0, 1], ids=["roll", "pitch"])
def test_the_small_angle_restoring_moment_is_rho_g_v_gm(load_body, axis):
    """M = -rho g V GM phi with GM = KB + BM - KG, BM = I_wp / V (the waterplane's second
    moment about the heel axis): a box heeled by 1e-4 rad at its draft, within 0.1 %."""
    uvms = _box(load_body)
    draft = BOX_MASS / (RHO * A * B)
    q_eq = _at(uvms, C / 2 - draft)
    volume = BOX_MASS / RHO
    second_moment = (A * B**3 if axis == 0 else B * A**3) / 12
    gm = draft / 2 + second_moment / volume - C / 2  # keel at the bottom, G at the centre
    assert gm > 0
    phi = 1e-4
    rpy = [0.0, 0.0, 0.0]
    rpy[axis] = phi
    h = up.bias_forces(uvms, _at(uvms, q_eq[2], rpy), np.zeros(6), free_surface=True)
    assert h[3 + axis] == pytest.approx(RHO * G * volume * gm * phi, rel=1e-3)
    assert abs(h[2]) < 1e-6 * BOX_MASS * G  # no heave force at first order


def test_a_long_cylinder_floats_lying_not_standing(load_body):
    """A cylinder L = 10 r of half the water's density, released nearly upright, ends lying;
    lying is the lower potential."""
    r, length = 0.1, 1.0
    m = 0.5 * RHO * math.pi * r * r * length
    inertia = (m * (3 * r * r + length**2) / 12,) * 2 + (m * r * r / 2,)
    uvms = load_body(
        body_urdf(
            mass=m,
            inertia=inertia,
            hydro=hydro_xml(
                math.pi * r * r * length, added=(8, 8, 1, 0.5, 0.5, 0.01), lin=(20, 20, 20, 2, 2, 2)
            ),
            collision=f'<cylinder radius="{r}" length="{length}"/>',
        )
    )
    samples = _run(uvms, _at(uvms, -0.2, (0.2, 0.15, 0.0)), np.zeros(6), 40.0, step_s=2e-3)
    axis = pin.Quaternion(samples[-1][1][3:7]).toRotationMatrix()[:, 2]
    assert abs(axis[2]) < 1e-2  # the body's z axis (the cylinder's) is horizontal
    standing = floating_equilibrium(uvms, _at(uvms), free_attitude=False)
    lying = floating_equilibrium(uvms, _at(uvms, 0.0, (math.pi / 2, 0.0, 0.0)), free_attitude=False)
    assert up.potential_energy(uvms, lying, free_surface=True) < up.potential_energy(
        uvms, standing, free_surface=True
    )


def test_energy_is_conserved_without_damping_and_never_grows_with_it(load_body):
    """A box bobbing, rolling and pitching through the surface: kinetic (added mass scaled
    by the wet fraction) + gravity + hydrostatic energy is constant without damping (to the
    integrator's error, which falls with the step), and never increases with damping."""
    uvms = _box(load_body)
    q0 = _at(uvms, 0.12, (0.25, -0.15, 0.3))
    v0 = np.array([0.2, -0.1, -0.6, 0.4, 0.3, -0.2])
    e0 = _energy(uvms, q0, v0)
    kinetic0 = up.kinetic_energy(uvms, q0, v0, free_surface=True)
    drift = []
    for step in (2e-3, 1e-3):
        samples = _run(uvms, q0, v0, 3.0, step_s=step, every=round(0.02 / step))
        drift.append(max(abs(_energy(uvms, q, v) - e0) for _, q, v in samples))
    assert drift[1] < 1e-5 * kinetic0
    assert drift[1] < drift[0] / 3  # an integration error, not a model's
    damped = _box(load_body, damping=(20, 20, 60, 3, 3, 3))
    samples = _run(damped, q0, v0, 3.0, step_s=1e-3, every=10)
    energies = np.array([_energy(damped, q, v) for _, q, v in samples])
    assert np.max(np.diff(energies)) < 1e-7 * kinetic0
    assert energies[-1] < energies[0] - 0.5 * kinetic0


def test_a_floating_body_follows_long_waves(load_body):
    """Heave RAO -> 1 at long periods: the body rides a 30 s swell with its amplitude (1 %)."""
    uvms = _box(load_body, damping=(40, 40, 200, 5, 5, 5))
    q_eq = floating_equilibrium(uvms, _at(uvms), free_attitude=False)
    amplitude, period = 0.05, 30.0
    wave = AiryWave(amplitude, period)
    samples = _run(uvms, q_eq, np.zeros(6), 4 * period, step_s=4e-3, flow=wave, every=5)
    t = np.array([s[0] for s in samples])
    z = np.array([s[1][2] for s in samples]) - q_eq[2]
    late = t >= 2 * period
    omega = 2 * math.pi / period
    basis = np.column_stack([np.cos(omega * t[late]), np.sin(omega * t[late]), np.ones(late.sum())])
    coefficients = np.linalg.lstsq(basis, z[late], rcond=None)[0]
    assert math.hypot(*coefficients[:2]) / amplitude == pytest.approx(1.0, abs=1e-2)
    # in phase with eta = A cos(k x - w t) at the body (x stays near 0)
    assert coefficients[0] / amplitude == pytest.approx(1.0, abs=2e-2)


def test_a_body_heavier_than_its_water_does_not_float(load_body):
    """floating_equilibrium says so instead of returning a depth."""
    uvms = load_body(
        body_urdf(
            mass=2.0 * RHO * 0.001, hydro=hydro_xml(0.001), collision='<sphere radius="0.062"/>'
        )
    )
    with pytest.raises(up.SimulationError, match="does not float"):
        floating_equilibrium(uvms, _at(uvms))


def test_energy_is_conserved_as_arm_links_cross_the_surface(reference_uvms):
    """The LBV150 + arm upside down near the surface, damping off, its links swinging in and
    out of the water: the energy error is the integrator's (it falls with the step)."""
    uvms = reference_uvms.with_hydro(
        lambda b: dataclasses.replace(
            b.params, linear_damping=np.zeros((6, 6)), quadratic_damping=np.zeros(6)
        )
    )
    q0 = _at(uvms, -0.45, (2.9, -0.2, 0.1))
    q0[7:] = [0.3, 0.9, -0.6, 0.2]
    v0 = np.array([0.1, 0.05, -0.2, 0.3, -0.3, 0.2, 1.0, -1.0, 1.5, 2.0])
    e0, kinetic0 = _energy(uvms, q0, v0), up.kinetic_energy(uvms, q0, v0, free_surface=True)
    drift, crossed = [], set()
    for step in (1e-3, 5e-4):
        samples = _run(uvms, q0, v0, 2.0, step_s=step, every=round(0.01 / step))
        drift.append(max(abs(_energy(uvms, q, v) - e0) for _, q, v in samples))
        plant = Plant(uvms, free_surface=True)
        for _, q, _ in samples:
            fractions = plant.wet_fractions(0.0, q)
            crossed |= set(np.flatnonzero((fractions > 0) & (fractions < 1)).tolist())
    assert len(crossed) >= 4  # the hull and three arm links
    assert drift[1] < 2e-5 * kinetic0
    assert drift[1] < drift[0] / 3


def test_the_net_hydrostatic_load_is_the_world_force_and_moments_on_the_body(load_body):
    """`net_hydrostatic_load` (F_z, M_x, M_y), world axes at the vehicle's origin: the box
    at its draft, heeled by 0.05 rad about x, then about y: F_z = 0 to first order and the
    moment rights it, -rho g V GM phi on the heel's own axis (the sign of each, and which
    axis, are what the equilibrium search does not see: it finds zeros)."""
    from uvms_pin.physics.floating import net_hydrostatic_load

    uvms = _box(load_body)
    draft = BOX_MASS / (RHO * A * B)
    z = C / 2 - draft
    volume = BOX_MASS / RHO
    np.testing.assert_allclose(net_hydrostatic_load(uvms, _at(uvms, z)), 0.0, atol=1e-9)
    deep = net_hydrostatic_load(uvms, _at(uvms, -5.0))
    assert deep[0] == pytest.approx((RHO * A * B * C - BOX_MASS) * G, rel=1e-9)  # buoyant
    phi = 0.05
    for axis, second_moment in ((0, A * B**3 / 12), (1, B * A**3 / 12)):
        gm = draft / 2 + second_moment / volume - C / 2
        rpy = [0.0, 0.0, 0.0]
        rpy[axis] = phi
        force_z, *moments = net_hydrostatic_load(uvms, _at(uvms, z, rpy))
        assert moments[axis] == pytest.approx(-RHO * G * volume * gm * phi, rel=0.03)
        assert abs(moments[1 - axis]) < 1e-6 * abs(moments[axis])
        assert abs(force_z) < 0.01 * BOX_MASS * G
