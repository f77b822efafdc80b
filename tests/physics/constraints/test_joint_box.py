"""The exact step of one body's joints with Coulomb friction and limits
(`uvms_pin.physics.constraints.joint_box`): the same velocity as Pinocchio's ADMM solve of
the `JointCoulombFriction` and `JointLimits` rows (to the solver's tolerance), its own
optimality conditions to rounding, and a stuck joint exactly still."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from fixture_helpers import double_lever_urdf

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.joint_box import joint_box_step
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import constrained_velocity

H = 0.002


@pytest.fixture(scope="module")
def double(tmp_path_factory):
    path = double_lever_urdf(tmp_path_factory.mktemp("lever"), friction_Nm=1.0)
    return pin.buildModelFromUrdf(str(path))


def _both(model, q, v_free, coulomb):
    mass = pin.crba(model, model.createData(), q)
    mass = np.triu(mass) + np.triu(mass, 1).T
    gaps = (q - model.lowerPositionLimit, model.upperPositionLimit - q)
    exact = joint_box_step(v_free, mass, coulomb, gaps, H)
    sets = (JointCoulombFriction((1, 2), coulomb), JointLimits((1, 2)))
    admm = constrained_velocity(model, mass, v_free, q, sets, H)
    return exact, admm, mass


@pytest.mark.parametrize("seed", range(12))
def test_the_exact_step_is_the_solvers_to_its_tolerance(double, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.0, 1.0, 2) * np.array([1.0, 1.0])
    q[rng.integers(2)] = rng.choice([-1.0, 1.0]) * (1.0 - rng.uniform(0.0, 2e-3))  # near a limit
    v_free = rng.normal(0.0, 1.0, 2)
    coulomb = rng.uniform(0.0, 0.5, 2)
    exact, admm, mass = _both(double, q, v_free, coulomb)
    assert admm.converged
    # the ADMM's tolerance is 1e-8 on impulses: a rate error of about G = M^-1 times it
    tolerance = 1e-8 * np.max(np.abs(np.linalg.inv(mass))) * 10
    np.testing.assert_allclose(exact.velocity, admm.velocity, atol=tolerance)
    # the exact step's own conditions: the impulses are M (v+ - v_free), the friction's in
    # its box and opposing motion, the limits' only where a limit is reached
    total = mass @ (exact.velocity - v_free)
    np.testing.assert_allclose(exact.friction_impulse + exact.limit_impulse, total, atol=1e-13)
    assert np.all(np.abs(exact.friction_impulse) <= coulomb * H + 1e-15)
    moving = exact.velocity != 0.0
    np.testing.assert_allclose(
        exact.friction_impulse[moving], -coulomb[moving] * H * np.sign(exact.velocity[moving])
    )
    assert np.all(q + H * exact.velocity >= double.lowerPositionLimit - 1e-15)
    assert np.all(q + H * exact.velocity <= double.upperPositionLimit + 1e-15)


def test_a_stuck_joint_is_exactly_still_and_one_joint_is_one_update():
    step = joint_box_step(np.array([0.3]), np.array([[0.01]]), np.array([2.0]),
                          (np.array([np.inf]), np.array([np.inf])), H)  # fmt: skip
    assert step.velocity[0] == 0.0 and step.friction_impulse[0] == pytest.approx(-0.003)
    slid = joint_box_step(np.array([0.5]), np.array([[0.01]]), np.array([2.0]),
                          (np.array([np.inf]), np.array([np.inf])), H)  # fmt: skip
    assert slid.velocity[0] == pytest.approx(0.5 - 2.0 * H / 0.01, abs=1e-15)
    stopped = joint_box_step(np.array([5.0]), np.array([[0.01]]), np.array([0.1]),
                             (np.array([1.0]), np.array([1e-3])), H)  # fmt: skip
    assert stopped.velocity[0] == pytest.approx(1e-3 / H) and stopped.limit_impulse[0] < 0.0


def test_bad_input_is_refused():
    with pytest.raises(ParameterError, match="h > 0"):
        joint_box_step(np.zeros(1), np.eye(1), np.array([-1.0]), (np.ones(1), np.ones(1)), H)


def test_a_badly_conditioned_body_moving_freely_gets_its_exact_step():
    """Two joints coupled as a near-rigid pair (M_12 / sqrt(M_11 M_22) = 0.9999): coordinate
    descent contracts its error by only 0.9998 a sweep and is still 10-14 % off after its
    10,000 sweeps; the joints it leaves moving are then solved exactly, M (v+ - v_free) +
    c h sign(v+) = 0 to rounding, as is the friction's impulse -c h sign(v+)."""
    mass = np.array([[1.0, 0.9999], [0.9999, 1.0]])
    v_free, coulomb = np.array([2.0, 1.5]), np.array([0.5, 0.5])
    free = (np.full(2, np.inf), np.full(2, np.inf))
    step = joint_box_step(v_free, mass, coulomb, free, H)
    assert np.all(step.velocity > 0.0)  # both keep moving
    stationary = mass @ (step.velocity - v_free) + coulomb * H * np.sign(step.velocity)
    np.testing.assert_allclose(stationary, 0.0, atol=1e-12)
    expected = v_free - np.linalg.solve(mass, coulomb * H)
    np.testing.assert_allclose(step.velocity, expected, rtol=1e-10)
    np.testing.assert_allclose(step.friction_impulse, -coulomb * H, rtol=1e-12)
