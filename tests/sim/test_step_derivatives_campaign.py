"""A test campaign on one control period's Jacobians (`up.step_derivatives`), the thrusters'
input matrix and `Plant.acceleration_derivatives`, on models the other tests do not use: a
bare vehicle (nv = 6), the uuv_simulator RexROV and the gz-sim LRAUV through
`up.import_model`, and the reference arm with continuous joints (nq != nv).

The period's Jacobians are held to 4-point central differences of the plant's own compiled
period (`Plant.advance`, the start moved with `pin.integrate`, the end read in the tangent
at the end state) and the compiled period to the reference's. Pinocchio 4.1's
`pin.difference` of a continuous joint returns 0 for an angle below ~1e-8 rad (its SO(2) log
reads a rotation whose trace rounds above 2 as the identity), which is what a central
difference of these tiny entries meets: the end is read with atan2 for those joints.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, model_beyond_the_reference, random_state

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import AiryWave, UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy
from uvms_pin.sim.actuation import ThrustersAndJointLimits
from uvms_pin.sim.integrators import RK4, SemiImplicitEuler
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

FD_REL, CORE_REL = 1e-7, 1e-10
WAVE = AiryWave(0.4, 5.0, heading_rad=0.5, water_depth_m=15.0) + UniformCurrent([0.2, 0.0, 0.0])


@pytest.fixture(scope="module", params=["bluerov2_heavy", "rexrov", "lrauv", "continuous"])
def model(request, tmp_path_factory) -> up.UVMS:
    return model_beyond_the_reference(request.param, tmp_path_factory.mktemp(request.param))


def tangent_difference(model: pin.Model, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """q1 (-) q0 in the tangent at q0: pin.difference, with continuous joints by atan2 (see
    the module docstring)."""
    out = pin.difference(model, q0, q1)
    for joint in list(model.joints)[1:]:
        if joint.nq == 2 and joint.nv == 1:
            c0, s0 = q0[joint.idx_q : joint.idx_q + 2]
            c1, s1 = q1[joint.idx_q : joint.idx_q + 2]
            out[joint.idx_v] = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
    return out


def _relative_error(got: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(got - expected)) / max(np.max(np.abs(expected)), 1e-300))


@pytest.mark.parametrize("integrator", [RK4(0.005), SemiImplicitEuler(0.005)], ids=["rk4", "euler"])
def test_period_jacobians_match_the_plants_period(model, integrator):
    q, v, tau = random_state(model, np.random.default_rng(340), depth_m=-3.0)
    t0, period = 0.3, 0.02
    kw = {"integrator": integrator, "flow": WAVE, "time_s": t0}
    expected = up.step_derivatives(model, q, v, tau, period, backend="python", **kw)
    got = up.step_derivatives(model, q, v, tau, period, backend="core", **kw)
    plant = Plant(model, flow=WAVE, free_surface=False)
    q1, v1 = System(plant).advance(integrator, t0, q, v, tau, t0 + period)
    np.testing.assert_allclose(expected.q, q1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(expected.v, v1, rtol=0, atol=1e-10)
    nv, pin_model = model.nv, model.model

    def end(qq, vv, tt):
        qe, ve = System(plant).advance(integrator, t0, qq, vv, tt, t0 + period)
        return np.r_[tangent_difference(pin_model, q1, qe), ve]

    step = 1e-4 if nv == 8 else 1e-5  # the LRAUV's fins: rounding below
    integrate = lambda x, dx: pin.integrate(pin_model, x, dx)  # noqa: E731
    fd_x = np.hstack(
        [
            central_difference(lambda x: end(x, v, tau), q, nv, step, integrate),
            central_difference(lambda x: end(q, x, tau), v, nv, step),
        ]
    )
    fd_tau = central_difference(lambda x: end(q, v, x), tau, nv, 1e-3 * np.abs(tau).max())
    errors = (_relative_error(expected.dx_dx, fd_x), _relative_error(expected.dx_dtau, fd_tau))
    assert max(errors) < FD_REL, errors
    assert _relative_error(got.dx_dx, expected.dx_dx) < CORE_REL
    assert _relative_error(got.dx_dtau, expected.dx_dtau) < CORE_REL


def test_thrust_inputs_of_a_bare_vehicle(tmp_path):
    """nv = 6: B_u is the allocation matrix itself; the plant's allocation applies B_u u for
    thrusts inside the limits (input_matrix is its inverse there), and dx+/du = dx+/dtau B_u
    against central differences in u."""
    uvms = model_beyond_the_reference("bluerov2_heavy", tmp_path)
    thrusters = bluerov2_heavy.thrusters()
    b_u = up.input_matrix(thrusters, uvms.nv)
    assert b_u.shape == (6, 8)
    u = np.random.default_rng(341).uniform(-5.0, 5.0, 8)
    u = np.linalg.pinv(b_u) @ (b_u @ u)  # the least-norm thrusts of its wrench
    actuation = ThrustersAndJointLimits(thrusters, None)
    np.testing.assert_allclose(actuation.apply(b_u @ u), b_u @ u, rtol=0, atol=1e-12)
    np.testing.assert_allclose(actuation.thrusts(b_u @ u), u, rtol=0, atol=1e-12)
    q, v, _ = random_state(uvms, np.random.default_rng(342), depth_m=-3.0)
    kw = {"integrator": RK4(0.01), "flow": WAVE}
    got = up.step_derivatives(uvms, q, v, b_u @ u, 0.02, **kw)

    def end_velocity(uu):
        return up.step_derivatives(uvms, q, v, b_u @ uu, 0.02, **kw).v

    fd = central_difference(end_velocity, u, 8, 1e-3)
    assert _relative_error(got.dx_du(b_u)[6:], fd) < FD_REL


def test_an_input_matrix_of_the_wrong_shape_is_named(reference_uvms):
    """B_u must have nv rows (was numpy's matmul ValueError about 'core dimension 0')."""
    q = reference_uvms.neutral_configuration()
    q[2] = -3.0
    zero = np.zeros(reference_uvms.nv)
    step = up.step_derivatives(reference_uvms, q, zero, zero, 0.01, step_s=0.005)
    b_u = up.input_matrix(bluerov2_heavy.thrusters(), reference_uvms.nv)
    assert step.dx_du(b_u).shape == (20, 12)
    for bad in (b_u[:6], b_u.T, b_u[:, 0], np.full_like(b_u, np.nan)):
        with pytest.raises(ParameterError, match="input matrix"):
            step.dx_du(bad)


def test_plant_derivatives_with_a_current_a_wave_and_a_hull_cut_by_the_surface(tmp_path):
    """The RexROV's box hull a third wet (the plant's default free surface), in the plant's
    uniform current plus a wave: both backends against central differences of
    Plant.acceleration."""
    uvms = model_beyond_the_reference("rexrov", tmp_path)
    q, v, tau = random_state(uvms, np.random.default_rng(343), depth_m=0.05)
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.1, -0.05, 0.3)).coeffs()
    current = np.array([0.2, -0.1, 0.05])
    for backend in ("core", "python"):
        plant = Plant(uvms, current_world_m_s=current, flow=WAVE, backend=backend)
        wet = plant.wet_fractions(0.3, q)
        assert 0.2 < wet[0] < 0.5
        got = plant.acceleration_derivatives(0.3, q, v, tau)

        def accel(qq, vv, tt, plant=plant):
            return plant.acceleration(0.3, qq, vv, tt)

        integrate = lambda x, dx: pin.integrate(uvms.model, x, dx)  # noqa: E731
        fd = (
            central_difference(lambda x: accel(x, v, tau), q, 6, 1e-5, integrate),
            central_difference(lambda x: accel(q, x, tau), v, 6, 1e-5),
            central_difference(lambda x: accel(q, v, x), tau, 6, 1e-3 * np.abs(tau).max()),
        )
        errors = [_relative_error(g, f) for g, f in zip(got, fd, strict=True)]
        assert max(errors) < 1e-6, (backend, errors)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_plant_derivatives_refuse_a_quaternion_off_the_unit_sphere(tmp_path, backend):
    uvms = model_beyond_the_reference("bluerov2_heavy", tmp_path)
    q = uvms.neutral_configuration()
    q[2], q[6] = -3.0, 1.001
    plant = Plant(uvms, backend=backend)
    with pytest.raises(ParameterError, match=r"q.*root_joint.*norm"):
        plant.acceleration_derivatives(0.0, q, np.zeros(6), np.zeros(6))
