"""The contact law at a point (`uvms_pin.physics.world.contact_law`), as pure functions: the
Hunt-Crossley normal force and the patch-wise Coulomb friction held by a tangential spring.

The world tests check these through whole contacts (the compiled core by default); here each
property of the law is checked on its own, on the Python reference the core is held to.
Tolerances: the identities hold exactly in real arithmetic; 1e-12 relative to the forces.
"""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.contact_law import (
    ContactLaw,
    check_friction,
    friction_force_N,
    normal_force_N,
)

LAW = ContactLaw(
    stiffness_N_m=3.0e4,
    dissipation_s_m=0.8,
    friction_static=0.7,
    friction_kinetic=0.4,
    tangential_stiffness_N_m=1.5e4,
    tangential_damping_N_s_m=150.0,
)


def test_normal_force_is_hunt_crossley_k_delta_times_one_plus_d_delta_dot():
    """f_n = k delta (1 + d delta_dot) while 1 + d delta_dot > 0: at rest it is the spring
    k delta, pressing in (delta_dot > 0) stiffens it, separating softens it."""
    depth = np.array([1e-3, 2e-3, 5e-3, 5e-3, 5e-3])
    rate = np.array([0.0, 0.0, 0.0, 0.3, -0.3])
    k, d = LAW.stiffness_N_m, LAW.dissipation_s_m
    expected = k * depth * (1.0 + d * rate)
    np.testing.assert_allclose(normal_force_N(LAW, depth, rate), expected, rtol=1e-14)
    # the spring at rest is linear in the depth, and pressing in pushes harder than pulling out
    f = normal_force_N(LAW, depth, rate)
    assert f[1] == pytest.approx(2.0 * f[0], rel=1e-14)
    assert f[3] > f[2] > f[4] > 0.0


def test_normal_force_never_pulls_and_is_zero_at_first_touch():
    """f_n >= 0 for any rate: separating faster than 1/d gives zero, not a pull; zero depth
    (first touch) gives zero whatever the rate (no jump in the force)."""
    d = LAW.dissipation_s_m
    depth = np.full(5, 4e-3)
    rate = np.array([-1.0 / d, -2.0 / d, -10.0, -1.0 / d - 1e-9, -1.0 / d + 0.01])
    f = normal_force_N(LAW, depth, rate)
    np.testing.assert_array_equal(f[:4], np.zeros(4))
    assert f[4] == pytest.approx(LAW.stiffness_N_m * 4e-3 * d * 0.01, rel=1e-9)
    np.testing.assert_array_equal(
        normal_force_N(LAW, np.zeros(3), np.array([-5.0, 0.0, 5.0])), np.zeros(3)
    )


def _friction(normal, slip, velocity, patch, mu_stick, mu_kinetic=None):
    n = len(normal)
    mu_kinetic = np.full(n, LAW.friction_kinetic) if mu_kinetic is None else mu_kinetic
    return friction_force_N(
        LAW,
        np.asarray(normal, dtype=float),
        np.asarray(slip, dtype=float),
        np.asarray(velocity, dtype=float),
        np.asarray(patch),
        np.full(n, mu_stick),
        mu_kinetic,
    )


def test_a_sticking_point_gets_the_tangential_spring_and_damper_force():
    """Inside the cone, f_t = -k_t s - c_t v_t exactly (the spring holds the load): the
    spring opposes the stretch and the damper the tangential velocity."""
    slip = np.array([[1e-4, -2e-4, 0.0]])
    velocity = np.array([[0.0, 0.0, 1e-3]])
    force, stick = _friction([100.0], slip, velocity, [0], LAW.friction_static)
    expected = -LAW.tangential_stiffness_N_m * slip - LAW.tangential_damping_N_s_m * velocity
    assert stick.tolist() == [True]
    np.testing.assert_allclose(force, expected, rtol=1e-14)
    assert np.linalg.norm(expected) < LAW.friction_static * 100.0  # the case is inside the cone


@pytest.mark.parametrize("scale", [1.0, 1e-4])
def test_a_slipping_patch_gets_kinetic_friction_along_its_trial_force(scale):
    """Outside the cone (|sum f_trial| > mu_s sum f_n) the patch slips: its friction is
    mu_k sum f_n, along sum f_trial (opposing the stretch), spread over its points in
    proportion to their trial forces; at any scale of the forces (also below 1 N: a light
    touch)."""
    normal = np.array([10.0, 30.0]) * scale
    slip = np.array([[1e-2, 0.0, 0.0], [5e-3, 5e-3, 0.0]]) * scale  # k_t s >> mu_s f_n
    velocity = np.zeros((2, 3))
    force, stick = _friction(normal, slip, velocity, [7, 7], LAW.friction_static)
    trial = -LAW.tangential_stiffness_N_m * slip
    total = force.sum(axis=0)
    assert stick.tolist() == [False, False]
    assert np.linalg.norm(total) == pytest.approx(LAW.friction_kinetic * normal.sum(), rel=1e-12)
    direction = trial.sum(axis=0) / np.linalg.norm(trial.sum(axis=0))
    np.testing.assert_allclose(total / np.linalg.norm(total), direction, atol=1e-12)
    # each point keeps its trial force's direction, scaled by one factor per patch
    scale = force[:, 0] / trial[:, 0]
    assert scale[0] == pytest.approx(scale[1], rel=1e-12)
    np.testing.assert_allclose(force, scale[0] * trial, rtol=1e-12)


def test_the_cone_bounds_a_patch_not_each_point_and_patches_are_independent():
    """Coulomb's law on a patch: a point whose own trial force is outside its share of the
    cone still sticks when the patch's sum is inside; a second patch (another label) is
    judged on its own load."""
    normal = np.array([1.0, 99.0, 5.0])
    slip = np.array([[1e-3, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-2, 0.0]])
    force, stick = _friction(normal, slip, np.zeros((3, 3)), [3, 3, 9], LAW.friction_static)
    trial = -LAW.tangential_stiffness_N_m * slip
    # point 0 alone: 15 N > 0.7 x 1 N, but the patch holds 15 N < 0.7 x 100 N
    assert np.linalg.norm(trial[0]) > LAW.friction_static * normal[0]
    assert stick.tolist() == [True, True, False]
    np.testing.assert_allclose(force[:2], trial[:2], rtol=1e-14)
    assert np.linalg.norm(force[2]) == pytest.approx(LAW.friction_kinetic * normal[2], rel=1e-12)


def test_static_kinetic_hysteresis_a_patch_sticks_up_to_and_on_the_cone():
    """A trial force exactly on the cone (|f_trial| = mu f_n) still sticks (<=); just
    outside it slips with mu_k f_n < mu_s f_n, so the friction drops as slip begins; the
    same load judged with mu = mu_k (a patch already slipping) slips, and below mu_k f_n
    sticks again."""
    normal = np.array([10.0])
    k_t = LAW.tangential_stiffness_N_m
    on_cone = np.array([[LAW.friction_static * normal[0] / k_t, 0.0, 0.0]])
    force, stick = _friction(normal, on_cone, np.zeros((1, 3)), [0], LAW.friction_static)
    assert stick.tolist() == [True]
    np.testing.assert_allclose(np.linalg.norm(force), LAW.friction_static * normal[0], rtol=1e-14)

    outside = on_cone * (1.0 + 1e-6)
    force, stick = _friction(normal, outside, np.zeros((1, 3)), [0], LAW.friction_static)
    assert stick.tolist() == [False]
    assert np.linalg.norm(force) == pytest.approx(LAW.friction_kinetic * normal[0], rel=1e-12)

    between = on_cone * 0.5 * (1 + LAW.friction_kinetic / LAW.friction_static)
    _, stick = _friction(normal, between, np.zeros((1, 3)), [0], LAW.friction_static)
    assert stick.tolist() == [True]  # below mu_s: a sticking patch holds
    _, stick = _friction(normal, between, np.zeros((1, 3)), [0], LAW.friction_kinetic)
    assert stick.tolist() == [False]  # above mu_k: a slipping patch slips on
    below = on_cone * 0.9 * LAW.friction_kinetic / LAW.friction_static
    force, stick = _friction(normal, below, np.zeros((1, 3)), [0], LAW.friction_kinetic)
    assert stick.tolist() == [True]
    np.testing.assert_allclose(force, -k_t * below, rtol=1e-14)


def test_friction_dissipates_while_slipping():
    """A slipping point's friction opposes its stretch and velocity when both point the same
    way: f_t . v_t < 0 (the power of friction on the sliding body)."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        velocity = rng.normal(size=(1, 3)) * 0.1
        slip = velocity * 0.05  # stretched along the motion
        force, stick = _friction([1.0], slip, velocity, [0], LAW.friction_static)
        assert not stick[0]
        assert float(force[0] @ velocity[0]) < 0.0


@pytest.mark.parametrize(
    ("static", "kinetic", "ok"),
    [(0.6, 0.5, True), (0.5, 0.5, True), (0.0, 0.0, True), (0.4, 0.5, False),
     (0.5, -0.1, False), (float("nan"), 0.1, False), (float("inf"), 0.1, False)],
)  # fmt: skip
def test_friction_coefficients_need_static_at_least_kinetic_at_least_zero(static, kinetic, ok):
    """mu_s >= mu_k >= 0, both finite (the law and each object's own coefficients)."""
    if ok:
        check_friction(static, kinetic, "here")
        ContactLaw(friction_static=static, friction_kinetic=kinetic)
    else:
        with pytest.raises(ParameterError, match="friction_static >= friction_kinetic >= 0"):
            check_friction(static, kinetic, "here")
