"""Bodies in a non-uniform, unsteady flow: Morison inertia (Froude-Krylov + added mass on
the relative acceleration), drag on the relative velocity, the current shorthand."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import RHO, body_urdf, hydro_xml, random_configuration

import uvms_pin as up
from uvms_pin.errors import CoreFallbackWarning, ParameterError
from uvms_pin.flow import AiryWave, FlowField, GaussMarkovCurrent, UniformCurrent
from uvms_pin.sim.integrators import RK4

RADIUS = 0.1
VOLUME = 4.0 / 3.0 * np.pi * RADIUS**3
CA = 0.5  # sphere: added mass 0.5 rho V
G_WORLD = np.array([0.0, 0.0, -9.81])


def _sphere(load_body, density_ratio: float, damping: bool = False):
    mass = density_ratio * RHO * VOLUME
    added = (CA * RHO * VOLUME,) * 3 + (0.0,) * 3
    lin = (2.0, 2.0, 2.0, 0.1, 0.1, 0.1) if damping else (0,) * 6
    quad = (15.0, 15.0, 15.0, 0.1, 0.1, 0.1) if damping else (0,) * 6
    inertia = (0.4 * mass * RADIUS**2,) * 3
    return load_body(
        body_urdf(
            mass=mass, inertia=inertia, hydro=hydro_xml(VOLUME, added=added, lin=lin, quad=quad)
        )
    )


def test_current_shorthand_is_a_uniform_flow(reference_uvms):
    rng = np.random.default_rng(3)
    current = np.array([0.3, -0.2, 0.1])
    for _ in range(5):
        q = random_configuration(reference_uvms, rng)
        v = rng.normal(size=reference_uvms.nv)
        h_short = up.bias_forces(reference_uvms, q, v, current_world=current)
        h_flow = up.bias_forces(reference_uvms, q, v, flow=UniformCurrent(current), time_s=4.2)
        np.testing.assert_allclose(h_flow, h_short, rtol=1e-12, atol=1e-12)
        assert not np.allclose(h_short, up.bias_forces(reference_uvms, q, v))  # it does act
    with pytest.raises(up.ParameterError, match="either current_world or flow"):
        up.bias_forces(reference_uvms, q, v, current_world=current, flow=UniformCurrent(current))
    with pytest.raises(up.ParameterError, match="FlowField"):
        up.bias_forces(reference_uvms, q, v, flow=[0.1, 0, 0])


@pytest.mark.parametrize("density_ratio", [2.0, 0.7])
def test_sphere_at_rest_in_accelerating_flow(load_body, density_ratio):
    """(s + Ca) rho V a_body = (1 + Ca) rho V Du/Dt + (s - 1) rho V g at zero relative
    velocity... and at zero body velocity the relative velocity is -u, which for a sphere
    (isotropic added mass, no rotation) adds no Kirchhoff force."""
    uvms = _sphere(load_body, density_ratio)
    wave = AiryWave(0.4, 4.0, heading_rad=0.3, water_depth_m=12.0)
    q = uvms.neutral_configuration()
    q[:3] = [1.0, -2.0, -2.5]
    for t in (0.0, 0.7, 2.9):
        acc = up.forward_dynamics(uvms, q, np.zeros(6), np.zeros(6), flow=wave, time_s=t)
        a_fluid = wave.acceleration(t, q[:3])[0]
        expected = ((1 + CA) * a_fluid + (density_ratio - 1) * G_WORLD) / (density_ratio + CA)
        np.testing.assert_allclose(acc[:3], expected, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(acc[3:], 0.0, atol=1e-12)


def test_neutral_sphere_rides_with_the_water(load_body):
    """A neutrally buoyant sphere released with the water's velocity follows a fluid
    particle (p_ddot = Du/Dt along the path), drag or no drag: this needs the Froude-Krylov
    force, the added mass on the relative acceleration, drag on the relative velocity and
    the convective part of Du/Dt, all four."""
    uvms = _sphere(load_body, 1.0, damping=True)
    wave = AiryWave(0.5, 5.0, heading_rad=0.0) + AiryWave(0.2, 3.0, heading_rad=1.0)
    p0 = np.array([0.0, 0.0, -3.0])
    q = uvms.neutral_configuration()
    q[:3] = p0
    v = np.zeros(6)
    v[:3] = wave.velocity(0.0, p0)[0]

    def rhs(t, qq, vv):
        return up.forward_dynamics(uvms, qq, vv, np.zeros(6), flow=wave, time_s=t)

    dt, steps = 0.01, 500
    p = p0.copy()
    integrator = RK4(step_s=dt)
    for k in range(steps):
        t = k * dt
        q, v = integrator.advance(uvms.model, rhs, t, q, v, t + dt)
        f = lambda s, x: wave.velocity(s, x)[0]  # noqa: E731
        k1 = f(t, p)
        k2 = f(t + dt / 2, p + dt / 2 * k1)
        k3 = f(t + dt / 2, p + dt / 2 * k2)
        k4 = f(t + dt, p + dt * k3)
        p = p + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    np.testing.assert_allclose(q[:3], p, atol=1e-7)
    assert np.linalg.norm(p - p0) > 0.1  # it did travel an orbit's worth
    np.testing.assert_allclose(v[3:], 0.0, atol=1e-9)


def test_time_varying_current_drives_a_neutral_sphere_like_the_water(load_body):
    """In a uniform current that changes in time, a neutral sphere's acceleration at zero
    relative velocity equals the current's: F = (rho V + m_a) dU/dt = (m + m_a) a."""
    uvms = _sphere(load_body, 1.0, damping=True)
    gm = GaussMarkovCurrent([0.2, 0.0, 0.0], 0.1, 5.0, 0.2, seed=1, sample_period_s=0.2)
    q = uvms.neutral_configuration()
    for t in (0.1, 3.3, 7.9):
        v = np.zeros(6)
        v[:3] = gm.velocity(t, q[:3])[0]
        acc = up.forward_dynamics(uvms, q, v, np.zeros(6), flow=gm, time_s=t)
        np.testing.assert_allclose(acc[:3], gm.acceleration(t, q[:3])[0], rtol=1e-10, atol=1e-13)


class _OnePointFlow(FlowField):
    """A user's field that returns one point's values whatever the number of points."""

    def velocity(self, time_s, points_world):
        return np.array([0.1, 0.0, 0.0])

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(points_world), 3))

    def velocity_gradient(self, time_s, points_world):
        return np.zeros((len(points_world), 3, 3))

    def gradient_kinematics(self, time_s, points_world):
        return np.zeros((len(points_world), 3, 3)), np.zeros((3, 3, 3))  # Hessian one point's


def test_a_user_flow_of_the_wrong_shape_is_named_not_a_numpy_error(reference_uvms):
    """velocity of shape (3,) for n points, or a Hessian of one point: a ParameterError
    naming the field's method and the shapes (a numpy einsum error before)."""
    uvms = reference_uvms
    q = uvms.neutral_configuration()
    q[2] = -3.0
    zero = np.zeros(uvms.nv)
    flow = _OnePointFlow()
    with pytest.warns(CoreFallbackWarning):
        with pytest.raises(ParameterError, match=r"velocity returned shape \(3,\), expected"):
            up.forward_dynamics(uvms, q, zero, zero, flow=flow)
    flow.velocity = lambda time_s, points: np.zeros((len(points), 3))
    with pytest.warns(CoreFallbackWarning):
        with pytest.raises(ParameterError, match=r"gradient_kinematics\[1\] returned shape"):
            up.forward_dynamics_derivatives(uvms, q, zero, zero, flow=flow)
