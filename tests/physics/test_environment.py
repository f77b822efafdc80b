"""Environment: the paper's linear spring, the unilateral compliant plane, disturbances."""

from __future__ import annotations

import dataclasses
import math
import textwrap

import numpy as np
import pytest
from conftest import REFERENCE_URDF

import uvms_pin as up
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

K = np.array([2.0, 3.0, 5.0])


# ---- linear spring ----------------------------------------------------------------------


def test_spring_anchors_at_attach_and_gives_k_times_displacement():
    spring = LinearSpring(K)
    p0 = np.array([0.1, -0.2, -2.0])
    spring.attach(p0)
    np.testing.assert_array_equal(spring.wrench_on_environment_world(p0, np.ones(3)), np.zeros(6))
    p = p0 + np.array([0.05, -0.01, 0.2])
    wrench = spring.wrench_on_environment_world(p, np.zeros(3))
    np.testing.assert_allclose(wrench[:3], K * (p - p0), rtol=1e-15)
    np.testing.assert_array_equal(wrench[3:], np.zeros(3))  # a point contact: no torque
    # pushing along +x raises f_x (docs/controller.md, errata): K positive definite
    assert spring.wrench_on_environment_world(p0 + np.array([0.01, 0, 0]), np.zeros(3))[0] > 0


def test_spring_reanchors_on_a_second_attach():
    spring = LinearSpring(K)
    spring.attach(np.zeros(3))
    p1 = np.array([1.0, 2.0, 3.0])
    spring.attach(p1)
    np.testing.assert_array_equal(spring.wrench_on_environment_world(p1, np.zeros(3)), np.zeros(6))
    np.testing.assert_allclose(
        spring.wrench_on_environment_world(p1 + 0.1, np.zeros(3))[:3], 0.1 * K, rtol=1e-12
    )


def test_spring_with_a_given_anchor_keeps_it():
    anchor = np.array([0.5, 0.0, -1.0])
    spring = LinearSpring(K, anchor_world_m=anchor)
    spring.attach(np.zeros(3))  # the tip position does not move a given anchor
    np.testing.assert_allclose(
        spring.wrench_on_environment_world(np.zeros(3), np.zeros(3))[:3], K * (0 - anchor)
    )


_SPRING_SCENARIO = """
[scenario]
name = "spring_twice"
model = "{model}"
duration_s = 0.04
[initial]
position_world_m = [0.0, 0.0, -2.0]
velocity = [0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
[environment]
type = "spring"
stiffness_N_m = [2.0, 3.0, 5.0]
[integrator]
method = "rk4"
step_s = 0.01
[control]
period_s = 0.01
[output]
log_period_s = 0.02
"""


def test_scenario_simulated_twice_does_not_reuse_the_old_anchor(tmp_path):
    """The same Scenario (one Plant, one LinearSpring object) run from two start positions:
    each run starts with f_e(0) = 0, and its force is K (p - p0) with its own p0. Short runs
    (0.04 s, RK4 at 10 ms) keep this under a second."""
    path = tmp_path / "spring.toml"
    path.write_text(textwrap.dedent(_SPRING_SCENARIO.format(model=REFERENCE_URDF.as_posix())))
    scenario = load_scenario(path)
    first = simulate(scenario)
    q0 = scenario.q0.copy()
    q0[:3] += [0.3, -0.2, 0.5]  # start somewhere else
    moved = dataclasses.replace(scenario, q0=q0)
    assert moved.plant.contact is scenario.plant.contact  # the very same spring object
    second = simulate(moved)
    for rollout in (first, second):
        np.testing.assert_array_equal(rollout.wrench_contact_world[0], np.zeros(6))
        assert np.abs(rollout.wrench_contact_world[-1, :3]).max() > 1e-4  # it did move
    # and the first start, run again, reproduces the first run exactly
    third = simulate(scenario)
    np.testing.assert_array_equal(third.wrench_contact_world, first.wrench_contact_world)
    np.testing.assert_array_equal(third.q, first.q)


def test_continuous_control_with_a_fixed_step_integrator_runs(tmp_path):
    """Same scenario, continuous-time control (no [control] period) with RK4."""
    text = _SPRING_SCENARIO.replace("[control]\nperiod_s = 0.01\n", "")
    assert "[control]" not in text
    path = tmp_path / "spring.toml"
    path.write_text(textwrap.dedent(text.format(model=REFERENCE_URDF.as_posix())))
    rollout = simulate(load_scenario(path))
    assert len(rollout) == 3
    np.testing.assert_array_equal(rollout.wrench_contact_world[0], np.zeros(6))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"stiffness_N_m": [1.0, 2.0]},
        {"stiffness_N_m": [1.0, -2.0, 3.0]},
        {"stiffness_N_m": [1.0, np.nan, 3.0]},
        {"stiffness_N_m": K, "anchor_world_m": [0.0, 1.0]},
        {"stiffness_N_m": K, "anchor_world_m": [0.0, np.inf, 1.0]},
    ],
)
def test_spring_bad_parameters(kwargs):
    with pytest.raises(up.ParameterError):
        LinearSpring(**kwargs)


# ---- compliant plane --------------------------------------------------------------------

NORMAL = np.array([0.0, 0.0, 1.0])  # a floor; outward normal up, towards the robot


def _plane(k=100.0, c=10.0, normal=NORMAL, point=(0.0, 0.0, -3.0)):
    plane = CompliantPlane(
        normal_world=normal, stiffness_N_m=k, damping_N_s_m=c, point_world_m=point
    )
    plane.attach(np.zeros(3))  # a given point stays
    return plane


def test_plane_pushes_only_when_penetrating():
    plane = _plane()
    above = np.array([0.2, 0.1, -2.99])
    for velocity in (np.zeros(3), np.array([0, 0, -1.0]), np.array([0, 0, 1.0])):
        np.testing.assert_array_equal(
            plane.wrench_on_environment_world(above, velocity), np.zeros(6)
        )
    on_surface = np.array([0.2, 0.1, -3.0])
    np.testing.assert_array_equal(
        plane.wrench_on_environment_world(on_surface, np.zeros(3)), np.zeros(6)
    )


def test_plane_kelvin_voigt_force_along_minus_normal():
    """Depth d = 0.01 m, approaching at 0.2 m/s: lambda = -n (k d + c d_dot), exactly."""
    plane = _plane(k=100.0, c=10.0)
    p = np.array([0.3, -0.4, -3.01])
    wrench = plane.wrench_on_environment_world(p, np.array([0.5, 0.0, -0.2]))
    np.testing.assert_allclose(wrench[:3], -(100.0 * 0.01 + 10.0 * 0.2) * NORMAL, rtol=1e-12)
    np.testing.assert_array_equal(wrench[3:], np.zeros(3))
    # tangential velocity does not matter (frictionless)
    np.testing.assert_allclose(
        plane.wrench_on_environment_world(p, np.array([3.0, -2.0, -0.2])), wrench, rtol=1e-15
    )


def test_plane_never_pulls():
    """Leaving fast (d_dot very negative) the damping term would make k d + c d_dot < 0: the
    force is clipped at zero, never an attraction."""
    plane = _plane(k=100.0, c=10.0)
    p = np.array([0.0, 0.0, -3.01])  # inside by 1 cm
    leaving_fast = np.array([0.0, 0.0, 1.0])  # k d = 1 N < c d_dot = 10 N
    np.testing.assert_array_equal(plane.wrench_on_environment_world(p, leaving_fast), np.zeros(6))
    leaving_slowly = np.array([0.0, 0.0, 0.05])  # 1 - 0.5 = 0.5 N, still pushing
    np.testing.assert_allclose(
        plane.wrench_on_environment_world(p, leaving_slowly)[:3], -0.5 * NORMAL, rtol=1e-12
    )
    rng = np.random.default_rng(0)
    for _ in range(200):
        position = rng.normal(size=3) * 0.05 + [0, 0, -3.0]
        velocity = rng.normal(size=3)
        force = plane.wrench_on_environment_world(position, velocity)[:3]
        assert force @ NORMAL <= 0.0  # the tip only ever pushes into the wall
        np.testing.assert_allclose(np.cross(force, NORMAL), 0.0, atol=1e-15)


def test_plane_normal_is_normalised_and_any_direction_works():
    normal = np.array([-3.0, 4.0, 0.0])  # a wall, |n| = 5
    plane = _plane(k=50.0, c=0.0, normal=normal, point=(1.0, 1.0, 0.0))
    unit = normal / 5.0
    np.testing.assert_allclose(plane.normal_world, unit, rtol=1e-15)
    p = np.array([1.0, 1.0, 0.0]) - 0.02 * unit  # 2 cm inside
    np.testing.assert_allclose(
        plane.wrench_on_environment_world(p, np.zeros(3))[:3], -50.0 * 0.02 * unit, rtol=1e-12
    )


def test_plane_without_point_uses_the_tip_at_attach_and_reattaches():
    plane = CompliantPlane(normal_world=NORMAL, stiffness_N_m=100.0)
    plane.attach(np.array([0.0, 0.0, -1.0]))
    inside = np.array([0.0, 0.0, -1.02])
    assert plane.wrench_on_environment_world(inside, np.zeros(3))[2] == pytest.approx(-2.0)
    plane.attach(np.array([0.0, 0.0, -2.0]))  # a second run starting elsewhere
    np.testing.assert_array_equal(
        plane.wrench_on_environment_world(inside, np.zeros(3)), np.zeros(6)
    )


@pytest.mark.parametrize(
    "kwargs",
    [
        {"normal_world": [0.0, 0.0, 0.0], "stiffness_N_m": 1.0},
        {"normal_world": [0.0, 1.0], "stiffness_N_m": 1.0},
        {"normal_world": [0.0, np.nan, 1.0], "stiffness_N_m": 1.0},
        {"normal_world": NORMAL, "stiffness_N_m": 0.0},
        {"normal_world": NORMAL, "stiffness_N_m": -5.0},
        {"normal_world": NORMAL, "stiffness_N_m": math.inf},
        {"normal_world": NORMAL, "stiffness_N_m": 1.0, "damping_N_s_m": -0.1},
        {"normal_world": NORMAL, "stiffness_N_m": 1.0, "damping_N_s_m": math.nan},
        {"normal_world": NORMAL, "stiffness_N_m": 1.0, "point_world_m": [0.0, 0.0]},
    ],
)
def test_plane_bad_parameters(kwargs):
    with pytest.raises(up.ParameterError):
        CompliantPlane(**kwargs)


# ---- disturbances -----------------------------------------------------------------------


def test_sinusoidal_disturbance_paper_values():
    """Default: the paper's 0.15 sin(2 pi t / 7) N on x, y, z, no moment (1e-15)."""
    d = SinusoidalDisturbance()
    np.testing.assert_allclose(d(0.0), np.zeros(6), atol=1e-15)
    np.testing.assert_allclose(d(7.0 / 4.0), [0.15, 0.15, 0.15, 0, 0, 0], rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(d(3 * 7.0 / 4.0), [-0.15, -0.15, -0.15, 0, 0, 0], rtol=1e-14)
    for t in np.linspace(0, 20, 41):
        np.testing.assert_allclose(d(t), d(t + 7.0), atol=1e-14)  # periodic
        expected = 0.15 * math.sin(2 * math.pi * t / 7.0)
        np.testing.assert_allclose(d(t)[:3], expected, atol=1e-15)


def test_sinusoidal_disturbance_amplitude_and_phase():
    amplitude = np.array([1.0, -2.0, 0.0, 0.1, 0.0, 0.3])
    d = SinusoidalDisturbance(amplitude=amplitude, period_s=2.0, phase_rad=math.pi / 2)
    np.testing.assert_allclose(d(0.0), amplitude, rtol=1e-15)  # a cosine
    np.testing.assert_allclose(d(1.0), -amplitude, rtol=1e-14)
    np.testing.assert_allclose(d(0.5), np.zeros(6), atol=1e-15)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"period_s": 0.0},
        {"period_s": -7.0},
        {"period_s": math.inf},
        {"period_s": math.nan},
        {"amplitude": [0.15, 0.15, 0.15]},
        {"amplitude": [0.15, 0.15, math.nan, 0, 0, 0]},
    ],
)
def test_sinusoidal_disturbance_bad_parameters(kwargs):
    with pytest.raises(up.ParameterError):
        SinusoidalDisturbance(**kwargs)


@pytest.mark.parametrize("phase", [math.nan, math.inf])
def test_sinusoidal_disturbance_rejects_non_finite_phase(phase):
    with pytest.raises(up.ParameterError):
        SinusoidalDisturbance(phase_rad=phase)
