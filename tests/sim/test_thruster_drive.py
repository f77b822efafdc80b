"""Thruster dynamics: the first-order lag and the rate limit, solved exactly per period."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.thrust_curve import QuadraticThrustCurve
from uvms_pin.sim.thruster_drive import ThrusterDrives, first_order_step


def _ode_solution(f0, steady, tau, rate, t_end, n=200_000):
    """df/dt = clip((T_ss - f)/tau, -r, r) by small explicit steps (the oracle)."""
    h = t_end / n
    f, integral = f0, 0.0
    for _ in range(n):
        slope = (steady - f) / tau if tau > 0 else math.copysign(rate, steady - f)
        slope = max(-rate, min(rate, slope))
        f_next = f + h * slope
        if tau == 0 and (f_next - steady) * (f - steady) < 0:
            f_next = steady
        integral += 0.5 * (f + f_next) * h
        f = f_next
    return f, integral / t_end


@pytest.mark.parametrize("period_s", [0.001, 0.005, 0.025])
def test_63_percent_of_a_step_at_the_time_constant(period_s):
    tau = 0.1
    drives = ThrusterDrives([QuadraticThrustCurve(50.0, 40.0)], [tau], [math.inf])
    drives.start(period_s)
    for _ in range(round(tau / period_s)):
        drives.advance(np.array([1.0]))
    assert drives.thrust_N[0] == pytest.approx(50.0 * (1.0 - math.exp(-1.0)), rel=1e-12)


@pytest.mark.parametrize(
    ("f0", "steady", "tau", "rate"),
    [
        (0.0, 10.0, 0.05, math.inf),
        (0.0, 10.0, 0.05, 60.0),
        (5.0, -8.0, 0.02, 300.0),
        (0.0, 10.0, 0.0, 250.0),
        # no lag and a rate too slow to reach the steady thrust in the period: it ramps the
        # whole period (4 N of 10) and stays there
        (0.0, 10.0, 0.0, 100.0),
        (2.0, -10.0, 0.0, 100.0),
    ],
)
def test_one_period_matches_the_ode(f0, steady, tau, rate):
    dt = 0.04
    end, mean = first_order_step(
        np.array([f0]), np.array([steady]), np.array([tau]), np.array([rate]), dt
    )
    f_ref, mean_ref = _ode_solution(f0, steady, tau, rate, dt)
    assert end[0] == pytest.approx(f_ref, abs=1e-4)
    assert mean[0] == pytest.approx(mean_ref, abs=1e-4)


def test_rate_limit_is_the_slope():
    end, mean = first_order_step(
        np.zeros(1), np.array([100.0]), np.array([0.01]), np.array([50.0]), 0.1
    )
    assert end[0] == pytest.approx(5.0, rel=1e-14)
    assert mean[0] == pytest.approx(2.5, rel=1e-14)


def test_no_dynamics_gives_the_steady_thrust_at_once():
    drives = ThrusterDrives([QuadraticThrustCurve(50.0, 40.0)], [0.0], [math.inf])
    drives.start(0.01)
    assert drives.advance(np.array([-1.0]))[0] == -40.0


def test_dynamics_need_a_sampled_loop():
    drives = ThrusterDrives([QuadraticThrustCurve(50.0, 40.0)], [0.1], [math.inf])
    with pytest.raises(ParameterError, match=r"\[control\] period_s"):
        drives.start(None)


@pytest.mark.parametrize(("tau", "rate"), [(-0.1, math.inf), (0.1, 0.0), (math.nan, 1.0)])
def test_bad_parameters_are_refused(tau, rate):
    with pytest.raises(ParameterError):
        ThrusterDrives([QuadraticThrustCurve(1.0, 1.0)], [tau], [rate])


def test_the_direct_path_equals_linear_drives():
    from uvms_pin.model.thruster import Thruster
    from uvms_pin.sim.actuation import ThrustersAndJointLimits, ideal_drives

    thrusters = [
        Thruster("a", np.array([0.1, 0.2, 0.0]), np.array([1.0, 0.0, 0.0]), 20.0, 15.0),
        Thruster("b", np.array([0.0, -0.2, 0.1]), np.array([0.0, 1.0, 0.2]), 10.0, 0.0),
        Thruster("c", np.array([-0.3, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), 12.0, 12.0),
    ]
    direct = ThrustersAndJointLimits(thrusters, None)
    explicit = ThrustersAndJointLimits(thrusters, None, drives=ideal_drives(thrusters))
    for actuation in (direct, explicit):
        actuation.start(0.01)
    rng = np.random.default_rng(0)
    for tau in rng.normal(scale=20.0, size=(50, 6)):
        np.testing.assert_allclose(direct.apply(tau), explicit.apply(tau), rtol=1e-12, atol=1e-12)
        for name in ("thrust", "thruster_command"):
            np.testing.assert_allclose(direct.signals()[name], explicit.signals()[name], atol=1e-12)


@pytest.mark.parametrize("dt", [0.004, 0.02, 0.5])
def test_an_instant_drive_jumps_to_its_steady_thrust_beside_lagged_ones(dt):
    """tau = 0 and r = inf: f = T_ss at once, whatever the period, also in a vehicle whose
    other drives do have dynamics (the drives are then stepped one by one): its end value
    and its mean over the period are both T_ss, its neighbour's follow the lag."""
    end, mean = first_order_step(
        np.array([3.0, 0.0]),
        np.array([-12.0, 10.0]),
        np.array([0.0, 0.05]),
        np.array([math.inf, math.inf]),
        dt,
    )
    assert end[0] == -12.0 and mean[0] == -12.0
    assert end[1] == pytest.approx(10.0 * (1.0 - math.exp(-dt / 0.05)), rel=1e-12)
    drives = ThrusterDrives(
        [QuadraticThrustCurve(50.0, 40.0)] * 2, [0.0, 0.05], [math.inf, math.inf]
    )
    drives.start(dt)
    mean = drives.advance(np.array([1.0, 1.0]))
    assert drives.thrust_N[0] == 50.0 and mean[0] == 50.0


def test_instant_drives_have_no_dynamics_and_run_in_a_continuous_loop():
    """tau = 0 and r = inf for every thruster: no dynamics, so a continuous loop (no control
    period) is fine and each advance gives the steady thrust; one finite rate limit or one
    positive time constant is dynamics."""
    curve = QuadraticThrustCurve(50.0, 40.0)
    drives = ThrusterDrives([curve, curve], [0.0, 0.0], [math.inf, math.inf])
    assert not drives.has_dynamics
    drives.start(None)
    np.testing.assert_array_equal(drives.advance(np.array([1.0, -1.0])), [50.0, -40.0])
    assert ThrusterDrives([curve, curve], [0.0, 0.0], [math.inf, 100.0]).has_dynamics
    assert ThrusterDrives([curve, curve], [0.0, 0.1], [math.inf, math.inf]).has_dynamics


@pytest.mark.parametrize(("taus", "rates"), [([0.1], [1.0, 1.0]), ([0.1, 0.1], [1.0])])
def test_one_time_constant_and_one_rate_limit_per_thruster(taus, rates):
    """Two thrusters need two time constants and two rate limits: one list short is refused."""
    curve = QuadraticThrustCurve(1.0, 1.0)
    with pytest.raises(ParameterError, match="one time constant and one rate limit"):
        ThrusterDrives([curve, curve], taus, rates)
