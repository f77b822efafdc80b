"""The derivatives of the plant's acceleration with its joint stops and joint friction
(`Plant.acceleration_derivatives`, `uvms_pin.physics.derivatives.joint_limits`): against
4-point central differences of `Plant.acceleration` (the reference backend), with joints
past their limits (the stops pushing) and inside them, the drives' Coulomb friction in its
steep part; the reference arm and a mounted UR5; the compiled backend equal to the
reference; a world nothing touches changes nothing."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, mount_on_reference_vehicle

import uvms_pin as up
from uvms_pin.flow import UniformCurrent
from uvms_pin.physics.derivatives.joint_limits import joint_stop_jacobians
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.sim.plant import Plant

FD_REL = 1e-6
STEP = 1e-6


@pytest.fixture(scope="module", params=["reference", "ur5"])
def uvms(request, reference_uvms, tmp_path_factory) -> up.UVMS:
    if request.param == "reference":
        return reference_uvms
    return mount_on_reference_vehicle("ur5", tmp_path_factory.mktemp("ur5"))


def _plant(uvms, backend="python", **kw) -> Plant:
    n = uvms.nv - 6
    friction = JointFriction(np.full(n, 0.8), np.full(n, 1.5), np.full(n, 0.2))
    return Plant(
        uvms,
        current_world_m_s=np.array([0.2, -0.1, 0.0]),
        joint_stops=JointStops.of_model(uvms.model, 300.0, 3.0),
        joint_friction=friction,
        backend=backend,
        **kw,
    )


def _past_the_limits(uvms, rng):
    """Deep, every other arm joint 0.02-0.05 rad past a limit moving further out (its stop
    pushing), the others inside their range; joint rates within the Coulomb ramp."""
    model = uvms.model
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.normal(scale=0.3, size=3))).coeffs()
    v = rng.normal(scale=0.3, size=uvms.nv)
    stops = JointStops.of_model(model)
    for k, (iq, iv) in enumerate(zip(stops.q_index, stops.v_index, strict=True)):
        lo, hi = stops.lower_rad[k], stops.upper_rad[k]
        if k % 2 == 0 and np.isfinite(hi):
            q[iq] = hi + rng.uniform(0.02, 0.05)
            v[iv] = abs(v[iv])  # further out: k e + c e_dot > 0
        else:
            q[iq] = rng.uniform(max(lo, -np.pi) + 0.1, min(hi, np.pi) - 0.1)
    return q, v, rng.normal(scale=5.0, size=uvms.nv)


def _relative_error(got, expected) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


def _finite_differences(plant, q, v, tau, time_s=0.2):
    uvms = plant.uvms
    integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
    accel = plant.acceleration
    return (
        central_difference(lambda x: accel(time_s, x, v, tau), q, uvms.nv, STEP, integrate),
        central_difference(lambda x: accel(time_s, q, x, tau), v, uvms.nv, STEP),
        central_difference(lambda x: accel(time_s, q, v, x), tau, uvms.nv, 1e-3),
    )


def test_stops_and_friction_match_finite_differences(uvms):
    rng = np.random.default_rng(51)
    plant = _plant(uvms)
    for _ in range(2):
        q, v, tau = _past_the_limits(uvms, rng)
        pushing = joint_stop_jacobians(plant.joint_stops, q, v)[0]
        assert np.count_nonzero(pushing) >= 2  # the stops are in the test
        got = plant.acceleration_derivatives(0.2, q, v, tau)
        expected = _finite_differences(plant, q, v, tau)
        errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
        assert max(errors) < FD_REL, errors


def test_a_stop_pulled_away_from_does_not_act_and_a_lower_one_pushes_up(reference_uvms):
    """Each stop's four cases against the finite differences: the first joint 0.03 rad past
    its upper limit moving back faster than its spring pushes (k e + c e_dot < 0: the stop
    lets go, no derivative), the second past its lower limit moving further out (pushing
    up), the third past its lower limit moving back fast (letting go), the fourth inside."""
    uvms, rng = reference_uvms, np.random.default_rng(54)
    plant = _plant(uvms)
    stops = plant.joint_stops
    q, v, tau = _past_the_limits(uvms, rng)
    k, c = stops.stiffness_Nm_rad, stops.damping_Nm_s_rad
    cases = [(stops.upper_rad, 0.03, -2.0), (stops.lower_rad, -0.03, -0.2),
             (stops.lower_rad, -0.03, 2.0)]  # fmt: skip
    for j, (limit, past, rate_scale) in enumerate(cases):
        q[stops.q_index[j]] = limit[j] + past
        v[stops.v_index[j]] = rate_scale * k * abs(past) / c
    q[stops.q_index[3]] = 0.5 * (stops.lower_rad[3] + stops.upper_rad[3])
    by_q, by_v = joint_stop_jacobians(stops, q, v)
    diagonal = np.diag(by_q)[stops.v_index[:4]]
    np.testing.assert_array_equal(diagonal, [0.0, -k, 0.0, 0.0])
    np.testing.assert_array_equal(np.diag(by_v)[stops.v_index[:4]], [0.0, -c, 0.0, 0.0])
    got = plant.acceleration_derivatives(0.2, q, v, tau)
    expected = _finite_differences(plant, q, v, tau)
    errors = [_relative_error(g, e) for g, e in zip(got, expected, strict=True)]
    assert max(errors) < FD_REL, errors
    core = _plant(uvms, "core").acceleration_derivatives(0.2, q, v, tau)  # the same cases
    for a, b in zip(core, got, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())


def test_without_the_terms_the_derivatives_miss(uvms):
    """The stops' and the friction's terms are needed: the water's alone differ."""
    rng = np.random.default_rng(52)
    plant = _plant(uvms)
    q, v, tau = _past_the_limits(uvms, rng)
    got = plant.acceleration_derivatives(0.2, q, v, tau)
    water = up.forward_dynamics_derivatives(
        uvms,
        q,
        v,
        tau,
        flow=plant.water,
        time_s=0.2,
        backend="python",
        free_surface=True,
        tau_ext=plant.external_torque(q, v)
        + np.r_[np.zeros(6), plant.joint_friction.torque_Nm(v[6:])],
    )
    assert _relative_error(water[0], got[0]) > 1e-3
    assert _relative_error(water[1], got[1]) > 1e-3
    np.testing.assert_array_equal(water[2], got[2])


def test_at_a_stop_s_kink_the_inside_side_is_returned(reference_uvms):
    """A joint exactly at its limit: the stop does not push (e = 0), the derivative is that
    of the inside, which the one-sided difference from inside matches."""
    uvms = reference_uvms
    plant = _plant(uvms)
    rng = np.random.default_rng(53)
    q, v, tau = _past_the_limits(uvms, rng)
    stops = plant.joint_stops
    iq, iv = int(stops.q_index[0]), int(stops.v_index[0])
    q[iq] = stops.upper_rad[0]
    by_q, by_v = joint_stop_jacobians(stops, q, v)
    assert by_q[iv, iv] == 0.0 and by_v[iv, iv] == 0.0
    da_dq = plant.acceleration_derivatives(0.2, q, v, tau)[0]
    h = 1e-6
    e = np.zeros(uvms.nv)
    e[iv] = h
    inside = (
        plant.acceleration(0.2, q, v, tau)
        - plant.acceleration(0.2, pin.integrate(uvms.model, q, -e), v, tau)
    ) / h
    np.testing.assert_allclose(da_dq[:, iv], inside, rtol=0, atol=1e-4 * np.abs(inside).max())


def test_the_core_backend_gives_the_reference(reference_uvms):
    rng = np.random.default_rng(54)
    q, v, tau = _past_the_limits(reference_uvms, rng)
    python = _plant(reference_uvms, "python").acceleration_derivatives(0.2, q, v, tau)
    core = _plant(reference_uvms, "core").acceleration_derivatives(0.2, q, v, tau)
    for a, b in zip(core, python, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())


def test_a_world_nothing_touches_gives_the_water_s_derivatives(reference_uvms):
    world = World(reference_uvms, [plane("seafloor", [0, 0, -3.0], [0, 0, 1], 0.6, 0.5)])
    plant = Plant(reference_uvms, world=world, backend="python", flow=UniformCurrent([0.1, 0, 0]))
    q = reference_uvms.neutral_configuration()
    zero = np.zeros(reference_uvms.nv)
    q[2] = -2.0  # clear of the seafloor: the water's derivatives
    expected = up.forward_dynamics_derivatives(
        reference_uvms,
        q,
        zero,
        zero,
        flow=plant.water,
        backend="python",
        free_surface=True,
    )
    for a, b in zip(plant.acceleration_derivatives(0.0, q, zero, zero), expected, strict=True):
        np.testing.assert_array_equal(a, b)
