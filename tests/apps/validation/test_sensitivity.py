"""Parameter sensitivities of the prescribed-arm simulation: against finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT
from scipy.interpolate import CubicSpline, PPoly

import uvms_pin as up
from uvms_pin.apps.validation.identify import HULL
from uvms_pin.apps.validation.parameters import (
    generalized_force_sensitivity,
    parameter_values,
    parse_parameters,
    with_parameters,
)
from uvms_pin.apps.validation.pool import trial_uvms
from uvms_pin.apps.validation.prescribed import JointTrajectory, simulate_prescribed_arm
from uvms_pin.apps.validation.sensitivity import (
    SensitiveModel,
    roll_pitch_tangent,
    simulate_with_sensitivity,
)
from uvms_pin.apps.validation.trials import roll_pitch_rad
from uvms_pin.errors import ParameterError

DATA_DIR = ROOT / "data" / "hinsdale2023"
ANALYTIC = (
    "linear_damping.roll",
    "linear_damping.y",
    "quadratic_damping.pitch",
    "quadratic_damping.z",
    "center_of_buoyancy.x",
    "center_of_buoyancy.y",
    "center_of_buoyancy.z",
)


@pytest.fixture(scope="module")
def uvms():
    return trial_uvms()


def synthetic_arm(duration_s: float = 3.0) -> JointTrajectory:
    """A smooth, lively arm motion (each joint a sum of two sines)."""
    t = np.linspace(-0.5, duration_s + 0.5, 301)
    phases = np.arange(4)[None, :]
    q = 0.6 * np.sin(1.3 * t[:, None] + phases) + 0.3 * np.sin(2.9 * t[:, None] - phases)
    q[:, 1] += 1.2  # keep the shoulder and elbow away from their stops
    q[:, 2] += 0.8
    return JointTrajectory(CubicSpline(t, q, axis=0))


def initial_state() -> tuple[np.ndarray, np.ndarray]:
    rotation = pin.rpy.rpyToMatrix(0.08, -0.05, 0.3)
    quat = pin.Quaternion(rotation).coeffs()
    return np.concatenate([[0.1, -0.2, -1.0], quat]), np.array([0.05, -0.02, 0.01, 0.2, -0.1, 0.05])


def test_force_sensitivity_is_the_derivative_of_the_bias_forces(uvms):
    """dF/dp (F = -h's dependence on p) against differences of bias_forces, at a random
    moving state: damping and centre of buoyancy, where F is linear in p."""
    rng = np.random.default_rng(3)
    parameters = parse_parameters(ANALYTIC)
    q = pin.randomConfiguration(uvms.model, -np.ones(uvms.nq), np.ones(uvms.nq))
    q[7:] = np.clip(q[7:], uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:])
    v = rng.normal(scale=0.4, size=uvms.nv)
    analytic = generalized_force_sensitivity(uvms, q, v, parameters, HULL)
    values = parameter_values(uvms, parameters, HULL)
    h0 = up.bias_forces(uvms, q, v)
    for k in range(len(parameters)):
        # F is linear in these parameters: a one-sided difference is exact up to rounding
        # (and keeps a zero damping from going negative)
        step = 1e-2 * max(abs(values[k]), 1e-1)
        plus = values.copy()
        plus[k] += step
        h_plus = up.bias_forces(with_parameters(uvms, parameters, plus, HULL), q, v)
        numeric = -(h_plus - h0) / step
        assert np.linalg.norm(numeric) > 1e-6  # each parameter acts at this state
        np.testing.assert_allclose(
            analytic[:, k], numeric, rtol=1e-7, atol=1e-9 * np.abs(numeric).max()
        )


def test_states_are_those_of_the_validation_simulation(uvms):
    arm = synthetic_arm(1.0)
    q0, nu0 = initial_state()
    times = np.linspace(0.0, 1.0, 11)
    model = SensitiveModel(uvms, parse_parameters(["linear_damping.roll"]), HULL)
    trajectory = simulate_with_sensitivity(model, arm, q0, nu0, times, 0.05)
    q, nu = simulate_prescribed_arm(uvms, arm, q0, nu0, times, 0.05)
    np.testing.assert_allclose(trajectory.q_vehicle, q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(trajectory.nu_vehicle, nu, rtol=0, atol=1e-12)


def test_roll_pitch_sensitivity_matches_finite_differences_of_the_simulation(uvms):
    """d(roll, pitch)/dp propagated along 3 s of simulation against central differences of
    whole simulations, for every kind of parameter (added mass and the arm's delay through
    their own differences)."""
    names = (
        "linear_damping.roll",
        "linear_damping.pitch",
        "quadratic_damping.roll",
        "quadratic_damping.pitch",
        "center_of_buoyancy.x",
        "center_of_buoyancy.y",
        "center_of_buoyancy.z",
        "added_mass.roll",
        "added_mass.pitch",
        "arm_delay",
    )
    parameters = parse_parameters(names)
    arm = synthetic_arm(3.0)
    q0, nu0 = initial_state()
    times = np.linspace(0.0, 3.0, 31)
    base = parameter_values(uvms, parameters, HULL)
    base[:2] += 0.5  # a zero damping would leave the valid set at -step
    model = SensitiveModel(uvms, parameters, HULL, base)
    trajectory = simulate_with_sensitivity(model, arm, q0, nu0, times, 0.02)
    roll_pitch = roll_pitch_rad(trajectory.q_vehicle[:, 3:7])
    analytic = roll_pitch_tangent(roll_pitch) @ trajectory.sensitivity[:, :6, :]
    values = model.values
    for k, parameter in enumerate(parameters):
        step = 1e-4 * max(abs(values[k]), 1e-2)
        ends = []
        for sign in (1.0, -1.0):
            shifted = values.copy()
            shifted[k] += sign * step
            perturbed = with_parameters(uvms, parameters, shifted, HULL)
            # the same spline, at t + delay
            moved_arm = JointTrajectory(PPoly(arm.spline.c, arm.spline.x - shifted[-1]))
            q, _ = simulate_prescribed_arm(perturbed, moved_arm, q0, nu0, times, 0.02)
            ends.append(roll_pitch_rad(q[:, 3:7]))
        numeric = (ends[0] - ends[1]) / (2 * step)
        scale = np.abs(numeric).max()
        assert scale > 1e-4, parameter.name  # the parameter moves roll or pitch
        np.testing.assert_allclose(
            analytic[:, :, k], numeric, rtol=0, atol=2e-4 * scale, err_msg=parameter.name
        )


@pytest.mark.parametrize(
    ("names", "match"),
    [
        (["damping.roll"], "unknown parameter 'damping.roll'"),
        (["linear_damping.roll", "linear_damping.roll"], "given twice"),
        (["center_of_buoyancy.roll"], "center_of_buoyancy has x, y, z"),
        (["quadratic_damping.spin"], "unknown parameter"),
        ([], "no parameter"),
    ],
)
def test_bad_parameter_names_are_refused(names, match):
    with pytest.raises(ParameterError, match=match):
        parse_parameters(names)


def test_an_unknown_body_is_refused(uvms):
    with pytest.raises(ParameterError, match="no hydrodynamic body 'hull'"):
        parameter_values(uvms, parse_parameters(["linear_damping.x"]), "hull")


def test_a_negative_damping_is_refused(uvms):
    with pytest.raises(ParameterError, match="dissipative"):
        with_parameters(uvms, parse_parameters(["quadratic_damping.roll"]), np.array([-1.0]), HULL)
