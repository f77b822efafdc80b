"""Integrators on the free-flyer Lie group: convergence order, unit quaternion, parameters,
splitting an interval.

Test system: a torque-free rigid body (no hydrodynamics, gravity switched off) with an
anisotropic inertia, spinning and translating, started at a generic position and attitude.
Its body velocity obeys Euler's equations and its pose couples rotation and translation,
so the SE(3) chart and the velocity update are both exercised. The reference is RK4 with a
step 20x below the finest tested one (error ~ 20^4 = 1.6e5 times smaller than the finest
RK4 error, ~1e-13), itself checked against the two invariants of the motion.

Errors are measured on the manifold: |difference(q_ref, q)| (6 numbers, in the tangent
space) plus |v - v_ref|.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import body_urdf

import uvms_pin as up
from uvms_pin.sim.integrators import RK4, Adaptive, SemiImplicitEuler

DURATION_S = 1.0
INERTIA = (0.1, 0.2, 0.3)
MASS = 2.0


@pytest.fixture(scope="module")
def free_body(tmp_path_factory):
    path = tmp_path_factory.mktemp("free") / "free.urdf"
    path.write_text(body_urdf(mass=MASS, inertia=INERTIA))
    uvms = up.load_uvms(path, ee_frame="body", sensor_frame="body", allow_dry_links=True)
    uvms.model.gravity = pin.Motion.Zero()
    return uvms


def _rhs(uvms):
    tau = np.zeros(uvms.nv)

    def rhs(t, q, v):
        return up.forward_dynamics(uvms, q, v, tau)

    return rhs


def _initial_state(uvms):
    q0 = uvms.neutral_configuration()
    q0[:3] = [0.3, -0.2, 1.0]
    q0[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.4, -0.7, 2.0)).coeffs()
    v0 = np.array([0.3, -0.1, 0.2, 1.0, 0.5, 1.5])
    return q0, v0


def _error(model, state, reference) -> float:
    (q, v), (q_ref, v_ref) = state, reference
    return float(
        np.linalg.norm(pin.difference(model, q_ref, q)) + np.linalg.norm(np.asarray(v) - v_ref)
    )


@pytest.fixture(scope="module")
def reference(free_body):
    q0, v0 = _initial_state(free_body)
    return RK4(DURATION_S / 2000).advance(free_body.model, _rhs(free_body), 0.0, q0, v0, DURATION_S)


def _world_momentum(uvms, q, v):
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q, v)
    return data.oMi[1].act(pin.Force(uvms.model.inertias[1].matrix() @ v)).vector


def test_reference_solution_conserves_energy_and_momentum(free_body, reference):
    """Torque-free: kinetic energy and world momentum (linear and angular about the world
    origin) are invariants; the reference keeps them to 1e-12 (RK4 error ~1e-13)."""
    q0, v0 = _initial_state(free_body)
    q1, v1 = reference
    e0, e1 = up.kinetic_energy(free_body, q0, v0), up.kinetic_energy(free_body, q1, v1)
    assert e1 == pytest.approx(e0, rel=1e-12)
    np.testing.assert_allclose(
        _world_momentum(free_body, q1, v1), _world_momentum(free_body, q0, v0), atol=1e-12
    )
    assert np.linalg.norm(v1[3:] - v0[3:]) > 0.1  # the spin really precesses


def _errors(integrator_class, steps, free_body, reference):
    q0, v0 = _initial_state(free_body)
    rhs = _rhs(free_body)
    return [
        _error(
            free_body.model,
            integrator_class(h).advance(free_body.model, rhs, 0.0, q0, v0, DURATION_S),
            reference,
        )
        for h in steps
    ]


def test_rk4_is_fourth_order(free_body, reference):
    """Halving the step divides the error by 2^4 = 16 (measured 16.0); assert > 12. The
    finest error (~5e-8) is far above the reference's (~1e-13)."""
    errors = _errors(RK4, [0.1, 0.05, 0.025], free_body, reference)
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    assert errors[-1] > 1e-10
    assert all(r > 12.0 for r in ratios), (errors, ratios)
    assert all(r < 20.0 for r in ratios), (errors, ratios)  # not accidentally super-convergent


def test_semi_implicit_euler_is_first_order(free_body, reference):
    """Halving the step halves the error (measured 2.00); assert 1.5 < ratio < 2.6."""
    errors = _errors(SemiImplicitEuler, [0.01, 0.005, 0.0025], free_body, reference)
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    assert all(1.5 < r < 2.6 for r in ratios), (errors, ratios)


@pytest.mark.parametrize("method", ["LSODA", "Radau"])
def test_adaptive_meets_its_tolerance(free_body, reference, method):
    """Over 1 s the global error stays within 10 rtol |state| (|state| ~ 2; measured
    5.8e-7 for LSODA at rtol 1e-6 and 9e-11 at rtol 1e-9), and a tighter tolerance gives a
    smaller error."""
    q0, v0 = _initial_state(free_body)
    rhs = _rhs(free_body)
    errors = []
    for rtol in (1e-6, 1e-9):
        state = Adaptive(method, rtol=rtol, atol=rtol * 1e-2).advance(
            free_body.model, rhs, 0.0, q0, v0, DURATION_S
        )
        errors.append(_error(free_body.model, state, reference))
        assert errors[-1] < 10.0 * rtol * 2.0, (rtol, errors[-1])
    assert errors[1] < errors[0]


def test_quaternion_stays_unit(free_body):
    """pin.integrate keeps the quaternion on the unit sphere: after 1000 steps of each
    integrator its norm is 1 to 1e-12 (round-off grows ~ sqrt(n) eps)."""
    q0, v0 = _initial_state(free_body)
    q0[3:7] = q0[3:7] / np.linalg.norm(q0[3:7])
    rhs = _rhs(free_body)
    for integrator in (RK4(1e-3), SemiImplicitEuler(1e-3), Adaptive("LSODA")):
        q, v = q0, v0
        for k in range(10):
            q, v = integrator.advance(free_body.model, rhs, 0.1 * k, q, v, 0.1 * (k + 1))
        assert abs(np.linalg.norm(q[3:7]) - 1.0) < 1e-12, type(integrator).__name__


@pytest.mark.parametrize("integrator_class", [RK4, SemiImplicitEuler])
@pytest.mark.parametrize("step", [0.0, -1e-3, math.nan, math.inf])
def test_fixed_step_rejects_bad_step(integrator_class, step):
    with pytest.raises(up.ParameterError, match="step_s must be positive"):
        integrator_class(step)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "Euler"}, "adaptive method must be one of"),
        ({"method": "lsoda"}, "adaptive method must be one of"),
        ({"rtol": 0.0}, "adaptive rtol must be finite and > 0"),
        ({"atol": -1e-8}, "adaptive atol must be finite and > 0"),
        ({"rtol": math.nan}, "adaptive rtol must be finite and > 0"),
        ({"rtol": math.inf}, "adaptive rtol must be finite and > 0"),
        ({"atol": math.inf}, "adaptive atol must be finite and > 0"),
        ({"max_step_s": 0.0}, "max_step_s must be > 0"),
        ({"max_step_s": math.nan}, "max_step_s must be > 0"),
    ],
)
def test_adaptive_rejects_bad_parameters(kwargs, message):
    with pytest.raises(up.ParameterError, match=message):
        Adaptive(**kwargs)


def _forced_rhs(uvms):
    """A time-dependent input, so that a wrong substep time would show."""

    def rhs(t, q, v):
        tau = np.array([math.sin(3 * t), 0.2, -0.1, 0.05 * math.cos(5 * t), 0.0, 0.02])
        return up.forward_dynamics(uvms, q, v, tau)

    return rhs


@pytest.mark.parametrize("integrator", [RK4(2.0**-7), SemiImplicitEuler(2.0**-7)])
def test_split_interval_equals_one_call_for_fixed_steps(free_body, integrator):
    """With dyadic times and step (exact in binary) the substeps of [0, 1/4] in one call and
    of [0, 1/8] + [1/8, 1/4] coincide exactly, and so must the result (bit for bit)."""
    q0, v0 = _initial_state(free_body)
    model, rhs = free_body.model, _forced_rhs(free_body)
    one = integrator.advance(model, rhs, 0.0, q0, v0, 0.25)
    q, v = integrator.advance(model, rhs, 0.0, q0, v0, 0.125)
    two = integrator.advance(model, rhs, 0.125, q, v, 0.25)
    np.testing.assert_array_equal(one[0], two[0])
    np.testing.assert_array_equal(one[1], two[1])
    # and four calls, too
    q, v = q0, v0
    for k in range(4):
        q, v = integrator.advance(model, rhs, k / 16, q, v, (k + 1) / 16)
    np.testing.assert_array_equal(q, one[0])
    np.testing.assert_array_equal(v, one[1])


def test_adaptive_split_interval_agrees_within_tolerance(free_body):
    """The adaptive chart is re-based at every call: splitting changes round-off and step
    choices, not the answer beyond the tolerance (rtol 1e-9 -> agreement to 1e-7)."""
    q0, v0 = _initial_state(free_body)
    model, rhs = free_body.model, _forced_rhs(free_body)
    integrator = Adaptive("LSODA", rtol=1e-9, atol=1e-11)
    one = integrator.advance(model, rhs, 0.0, q0, v0, 0.5)
    q, v = integrator.advance(model, rhs, 0.0, q0, v0, 0.25)
    two = integrator.advance(model, rhs, 0.25, q, v, 0.5)
    assert _error(model, two, one) < 1e-7


@pytest.mark.parametrize(
    "integrator, t1, calls",
    [
        (RK4(0.01), 0.1, 40),  # 0.1 / 0.01 = 10.000000000000002 in floats: still 10 steps
        (RK4(0.03), 0.1, 16),  # 4 equal steps of 0.025, none longer than 0.03
        (SemiImplicitEuler(0.01), 0.1, 10),
        (SemiImplicitEuler(1.0), 0.1, 1),
    ],
)
def test_fixed_step_substep_count(free_body, integrator, t1, calls):
    """Equal substeps no longer than step_s; 4 rhs calls per RK4 step, 1 per Euler step."""
    q0, v0 = _initial_state(free_body)
    times = []
    rhs = _rhs(free_body)

    def counting(t, q, v):
        times.append(t)
        return rhs(t, q, v)

    integrator.advance(free_body.model, counting, 0.0, q0, v0, t1)
    assert len(times) == calls
    assert min(times) == 0.0 and max(times) == pytest.approx(
        t1 if isinstance(integrator, RK4) else t1 - t1 / calls, rel=1e-12
    )


def test_adaptive_failure_carries_the_states_it_reached(free_body):
    """A finite-time blow-up (v_x' = 1 / (0.05 - t)^2) makes RK45's step vanish near
    t = 0.05 s: the SimulationError carries the states at the output times before it, which
    are the exact solution v_x = 1 / (0.05 - t) - 20 (1e-4 relative), and no later ones."""
    model = free_body.model

    def rhs(t, q, v):
        a = np.zeros(model.nv)
        a[0] = 1.0 / (0.05 - t) ** 2
        return a

    times = np.arange(1, 11) * 0.01
    with pytest.raises(up.SimulationError, match="RK45 failed") as info:
        Adaptive("RK45", rtol=1e-8, atol=1e-10).advance_through(
            model, rhs, 0.0, pin.neutral(model), np.zeros(model.nv), times
        )
    states = info.value.states
    reached = [t for t, _, _ in states]
    np.testing.assert_allclose(reached, times[: len(reached)])
    assert 4 <= len(reached) <= 5  # 0.01 ... 0.04 (0.05 itself is the singularity)
    for t, _, v in states:
        assert v[0] == pytest.approx(1.0 / (0.05 - t) - 20.0, rel=1e-4)


def test_adaptive_event_before_the_first_output_time(free_body):
    """An event that fires before the first output time returns just the event state (the
    solver then has no output rows: it used to fail on them)."""
    model = free_body.model
    v0 = np.zeros(model.nv)
    v0[0] = 1.0
    states = Adaptive("RK45").advance_through(
        model,
        lambda t, q, v: np.zeros(model.nv),
        0.0,
        pin.neutral(model),
        v0,
        np.array([0.1, 0.2]),
        event=lambda t, q, v: 0.05 - q[0],  # crosses zero downwards at x = 0.05 m
    )
    assert len(states) == 1
    t, q, _ = states[0]
    assert t == pytest.approx(0.05, rel=1e-6) and q[0] == pytest.approx(0.05, rel=1e-6)


def test_rk4_is_fourth_order_on_a_time_varying_force(free_body):
    """A force that depends on time, F(t) = m (cos t, sin 2t / 2, 0) in the body frame,
    on the body without spin (it keeps its attitude R0): v(t) = v0 + (sin t,
    (1 - cos 2t) / 4, 0) and p(t) = p0 + R0 (v0 t + (1 - cos t, t / 4 - sin 2t / 8, 0)).
    RK4 reads the force at t, t + h/2 (twice) and t + h: halving the step divides the
    error by 2^4 = 16 (assert 12..20)."""
    model = free_body.model

    def rhs(t, q, v):
        tau = np.zeros(6)
        tau[:3] = MASS * np.array([np.cos(t), 0.5 * np.sin(2.0 * t), 0.0])
        return up.forward_dynamics(free_body, q, v, tau)

    q0, _ = _initial_state(free_body)
    v0 = np.array([0.3, -0.1, 0.2, 0.0, 0.0, 0.0])
    rotation = pin.Quaternion(q0[3:7]).matrix()
    t = DURATION_S
    v_exact = v0 + np.r_[np.sin(t), (1.0 - np.cos(2.0 * t)) / 4.0, 0.0, 0.0, 0.0, 0.0]
    q_exact = q0.copy()
    shift = v0[:3] * t + np.array([1.0 - np.cos(t), t / 4.0 - np.sin(2.0 * t) / 8.0, 0.0])
    q_exact[:3] += rotation @ shift
    errors = [
        _error(model, RK4(h).advance(model, rhs, 0.0, q0, v0, t), (q_exact, v_exact))
        for h in (0.1, 0.05, 0.025)
    ]
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    assert errors[-1] > 1e-12
    assert all(12.0 < r < 20.0 for r in ratios), (errors, ratios)
