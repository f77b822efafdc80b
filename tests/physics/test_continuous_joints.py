"""Continuous arm joints (nq != nv: q holds (cos, sin) of each such joint, no limits).

The test model is the reference UVMS with every arm joint made ``continuous`` in its URDF
text: same bodies and axes, so at the same angles it must have exactly the dynamics of the
revolute original, and the compiled core must agree with the Python reference at 1e-12.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF, assert_rel, continuous_joint_urdf, random_configuration

import uvms_pin as up
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.sim.integrators import RK4, SemiImplicitEuler
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System


@pytest.fixture(scope="module")
def continuous(tmp_path_factory):
    return up.load_uvms(continuous_joint_urdf(tmp_path_factory.mktemp("continuous")))


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """Joints 1 and 3 continuous, 2 and 4 revolute."""
    path = continuous_joint_urdf(tmp_path_factory.mktemp("mixed"), ("arm_joint1", "arm_joint3"))
    return up.load_uvms(path)


def test_a_continuous_joint_is_two_configuration_entries_and_no_limits(continuous, mixed):
    assert (continuous.nq, continuous.nv) == (15, 10)
    assert continuous.arm_joints.kinds == ("continuous",) * 4
    assert np.all(np.isinf(continuous.arm_joints.lower))
    assert np.all(np.isinf(continuous.arm_joints.upper))
    assert (mixed.nq, mixed.nv) == (13, 10)
    arm = mixed.arm_joints
    assert arm.kinds == ("continuous", "revolute", "continuous", "revolute")
    np.testing.assert_array_equal(arm.limited, [False, True, False, True])
    np.testing.assert_array_equal(arm.lower[[1, 3]], [-0.3, -2.6])
    # the neutral configuration: every joint at 0 (cos 1, sin 0), on the circle
    q = mixed.neutral_configuration()
    np.testing.assert_array_equal(q[7:], [1.0, 0.0, 0.0, 1.0, 0.0, 0.0])


def test_positions_and_configuration_are_inverse(mixed):
    arm = mixed.arm_joints
    angles = np.array([3.0, 0.4, -3.1, -1.0])
    q = np.r_[np.zeros(3), 0.0, 0.0, 0.0, 1.0, arm.configuration(angles)]
    np.testing.assert_allclose(arm.positions(q), angles, rtol=0, atol=1e-15)
    # an angle past pi comes back wrapped into (-pi, pi]
    wrapped = arm.positions(np.r_[q[:7], arm.configuration([4.0, 0.4, 0.0, 0.0])])
    assert wrapped[0] == pytest.approx(4.0 - 2 * np.pi, abs=1e-15)


def _revolute_q(q_continuous, uvms):
    """The reference (revolute) model's q at the angles of ``q_continuous``."""
    return np.r_[q_continuous[:7], uvms.arm_joints.positions(q_continuous)]


def test_same_dynamics_as_the_revolute_model_at_the_same_angles(reference_uvms, continuous):
    """Only the configuration's chart differs: M, h and the forward dynamics are equal."""
    rng = np.random.default_rng(21)
    current = np.array([0.2, -0.1, 0.05])
    for _ in range(5):
        q = random_configuration(continuous, rng)
        q_rev = _revolute_q(q, continuous)
        v = rng.normal(scale=0.5, size=10)
        tau = rng.normal(scale=5.0, size=10)
        for backend in ("core", "python"):
            assert_rel(
                up.mass_matrix(continuous, q, backend=backend),
                up.mass_matrix(reference_uvms, q_rev, backend=backend),
            )
            assert_rel(
                up.forward_dynamics(continuous, q, v, tau, current, backend=backend),
                up.forward_dynamics(reference_uvms, q_rev, v, tau, current, backend=backend),
            )


@pytest.mark.parametrize("fixture", ["continuous", "mixed"])
def test_core_matches_the_reference(fixture, request):
    uvms = request.getfixturevalue(fixture)
    rng = np.random.default_rng(22)
    for current in (np.zeros(3), np.array([0.3, -0.2, 0.1])):
        for _ in range(5):
            q = random_configuration(uvms, rng)
            v = rng.normal(scale=0.5, size=uvms.nv)
            tau = rng.normal(scale=5.0, size=uvms.nv)
            assert_rel(up.mass_matrix(uvms, q), up.mass_matrix(uvms, q, backend="python"))
            assert_rel(
                up.bias_forces(uvms, q, v, current),
                up.bias_forces(uvms, q, v, current, backend="python"),
            )
            assert_rel(
                up.forward_dynamics(uvms, q, v, tau, current),
                up.forward_dynamics(uvms, q, v, tau, current, backend="python"),
            )


@pytest.mark.parametrize("integrator", [RK4(5e-4), SemiImplicitEuler(5e-4)])
def test_plant_advance_matches_the_reference_and_stays_on_the_circle(mixed, integrator):
    rng = np.random.default_rng(23)
    disturbance = SinusoidalDisturbance(rng.normal(size=6), period_s=3.0)
    current = np.array([0.2, -0.1, 0.05])
    core, python = (
        Plant(mixed, current, LinearSpring(np.full(3, 2.0)), disturbance, backend=b)
        for b in ("core", "python")
    )
    q0 = random_configuration(mixed, rng)
    for plant in (core, python):
        plant.attach(q0)
    v0 = rng.normal(scale=0.5, size=mixed.nv)
    tau = rng.normal(scale=5.0, size=mixed.nv)
    assert_rel(core.acceleration(0.3, q0, v0, tau), python.acceleration(0.3, q0, v0, tau))
    q_c, v_c = System(core).advance(integrator, 0.1, q0, v0, tau, 0.15)
    q_p, v_p = System(python).advance(integrator, 0.1, q0, v0, tau, 0.15)
    assert_rel(q_c, q_p)
    assert_rel(v_c, v_p)
    for k in (7, 10):  # (cos, sin) of joints 1 and 3 stay unit vectors
        assert np.hypot(q_c[k], q_c[k + 1]) == pytest.approx(1.0, abs=1e-14)


def test_a_passive_run_moves_as_the_revolute_model(tmp_path, reference_uvms, continuous):
    """Released from the same state, both models follow the same trajectory (angles read
    from (cos, sin)): the continuous chart changes nothing physical."""
    rng = np.random.default_rng(24)
    q_rev = random_configuration(reference_uvms, rng)
    q_cont = np.r_[q_rev[:7], continuous.arm_joints.configuration(q_rev[7:])]
    v0 = rng.normal(scale=0.3, size=10)
    tau = np.zeros(10)
    ends = []
    for uvms, q0 in ((reference_uvms, q_rev), (continuous, q_cont)):
        plant = Plant(uvms, np.array([0.2, 0.0, 0.0]))
        plant.attach(q0)
        q, v = q0, v0
        for k in range(50):
            q, v = System(plant).advance(RK4(2e-3), 0.01 * k, q, v, tau, 0.01 * (k + 1))
        ends.append((np.r_[q[:7], uvms.arm_joints.positions(q)], v))
    assert np.max(np.abs(ends[0][0] - ends[1][0])) < 1e-10
    assert np.max(np.abs(ends[0][1] - ends[1][1])) < 1e-10
    # and the arm really moved (the comparison is not between two resting states)
    assert np.max(np.abs(ends[0][0][7:] - q_rev[7:])) > 1e-3


def test_pinocchio_difference_gives_one_angle_per_continuous_joint(continuous):
    """What the posture terms of the baselines rely on (the impedance's hold)."""
    q0 = continuous.neutral_configuration()
    q1 = np.r_[q0[:7], continuous.arm_joints.configuration([0.3, -2.0, 3.0, -3.0])]
    np.testing.assert_allclose(
        pin.difference(continuous.model, q0, q1)[6:], [0.3, -2.0, 3.0, -3.0], atol=1e-14
    )


@pytest.mark.parametrize(
    ("kind", "model"), [("planar", "JointModelPlanar"), ("floating", "JointModelFreeFlyer")]
)
def test_an_arm_joint_of_several_degrees_of_freedom_is_refused(tmp_path, kind, model):
    """One position per arm joint is what scenarios, tables and limits speak: a planar or
    floating arm joint is refused when the file is loaded, naming the joint."""
    text = REFERENCE_URDF.read_text().replace(
        '<joint name="arm_joint2" type="revolute">', f'<joint name="arm_joint2" type="{kind}">'
    )
    path = tmp_path / "several.urdf"
    path.write_text(text)
    with pytest.raises(up.ModelError, match=rf"several.urdf: joint 'arm_joint2' \({model}\)"):
        up.load_uvms(path)
