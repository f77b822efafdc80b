"""The paper's prescribed-performance controller: signs, values, determinism, model-freeness.

Models are built in code (free-flyer + n revolute joints with axes Z, Y, Y, X, ... and an
``ee`` frame), so these tests do not depend on the reference URDF.
"""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from uvms_pin.control.measurement import Measurement
from uvms_pin.control.performance import transformation_gain, transformed_error
from uvms_pin.control.ppc import (
    FIRST_LEVEL_NAMES,
    PPCParams,
    PrescribedPerformanceController,
)
from uvms_pin.errors import FunnelViolation, ParameterError
from uvms_pin.physics.kinematics import analytical_jacobian, end_effector_pose, frame_id_from_name

K_F_N_PER_M = 2.0  # the paper's environment stiffness (unknown to the controller)


def build_test_uvms(n_joints: int = 4, mass_scale: float = 1.0) -> pin.Model:
    """LBV150-sized free-flyer with an n-joint arm (axes Z, Y, Y, X, ...) and an `ee` frame.

    ``mass_scale`` scales every inertia and leaves the kinematics unchanged.
    """
    model = pin.Model()
    model.name = "test_uvms"
    root = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    model.appendBodyToJoint(
        root, pin.Inertia.FromBox(11.0 * mass_scale, 0.53, 0.25, 0.25), pin.SE3.Identity()
    )
    joint_types = [pin.JointModelRZ, pin.JointModelRY, pin.JointModelRY, pin.JointModelRX]
    parent = root
    placement = pin.SE3(np.eye(3), np.array([0.25, 0.05, -0.1]))
    for i in range(n_joints):
        joint_id = model.addJoint(
            parent,
            joint_types[i % 4](),
            placement,
            f"arm_joint_{i + 1}",
            np.array([5.0]),
            np.array([2.0]),
            np.array([-2.5]),
            np.array([2.5]),
        )
        model.appendBodyToJoint(
            joint_id,
            pin.Inertia.FromCylinder(0.3 * mass_scale, 0.02, 0.15),
            pin.SE3(np.eye(3), np.array([0.075, 0.0, 0.0])),
        )
        parent = joint_id
        placement = pin.SE3(np.eye(3), np.array([0.15, 0.0, 0.02]))
    model.addFrame(
        pin.Frame("ee", parent, pin.SE3(np.eye(3), np.array([0.1, 0.0, 0.0])), pin.OP_FRAME)
    )
    return model


def arm_configuration(model: pin.Model, joint_angles) -> np.ndarray:
    q = pin.neutral(model)
    q[7:] = joint_angles
    return q


def ee_rpy(model, q) -> np.ndarray:
    return end_effector_pose(model, model.createData(), q, frame_id_from_name(model, "ee"))[1]


def ee_position(model, q) -> np.ndarray:
    return end_effector_pose(model, model.createData(), q, frame_id_from_name(model, "ee"))[0]


def make_measurement(model, q, v=None, force=(0.0, 0.0, 0.0), time_s=0.0) -> Measurement:
    v = np.zeros(model.nv) if v is None else np.asarray(v, dtype=float)
    return Measurement(time_s=time_s, q=q, v=v, wrench_world=np.r_[force, np.zeros(3)])


@pytest.fixture
def model() -> pin.Model:
    return build_test_uvms()


@pytest.fixture
def q_bent(model) -> np.ndarray:
    """A bent arm, end-effector away from singularities."""
    return arm_configuration(model, [0.2, -0.4, 0.6, 0.1])


def controller_holding_orientation(model, q, **kwargs) -> PrescribedPerformanceController:
    """Controller whose desired orientation is the current one (zero orientation error)."""
    return PrescribedPerformanceController(model, "ee", desired_rpy=ee_rpy(model, q), **kwargs)


# ---------------------------------------------------------------- parameters


def test_default_params_are_the_papers_with_errata_fixed():
    params = PPCParams.for_uvms(4)
    np.testing.assert_array_equal(params.k_x, np.full(6, 0.2))  # paper prints -0.2
    np.testing.assert_array_equal(params.k_zeta, np.full(10, 5.0))  # paper prints -5
    np.testing.assert_array_equal(params.rho0_x, [1, 1, 1, 0.9, 0.9, 0.9])
    np.testing.assert_array_equal(params.rho_inf_x, np.full(6, 0.2))
    np.testing.assert_array_equal(params.l_x_per_s, np.full(6, 3.0))
    np.testing.assert_array_equal(params.rho0_zeta, np.ones(10))
    np.testing.assert_array_equal(params.rho_inf_zeta, [0.2] * 6 + [0.4] * 4)
    np.testing.assert_array_equal(params.l_zeta_per_s, np.full(10, 2.2))
    np.testing.assert_array_equal(params.desired_rpy, np.zeros(3))
    assert params.null_space_gain_per_s == 0.0


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"k_x": -0.2}, "k_x must be > 0"),
        ({"k_zeta": [5.0] * 9 + [-5.0]}, "k_zeta must be > 0"),
        ({"k_zeta": [5.0] * 7}, "k_zeta must be a scalar or have 10 entries"),
        ({"rho0_x": [1.0] * 5}, "rho0_x"),
        ({"null_space_gain_per_s": -1.0}, "null_space_gain_per_s"),
        ({"l_zeta_per_s": np.nan}, "non-finite"),
    ],
)
def test_bad_params_raise(overrides, match):
    with pytest.raises(ParameterError, match=match):
        PPCParams.for_uvms(4, **overrides)


def test_bad_funnel_params_raise_naming_component(model):
    with pytest.raises(ParameterError, match="'arm_joint_2'"):
        PrescribedPerformanceController(
            model, "ee", PPCParams(rho_inf_zeta=[0.2] * 6 + [0.4, 1.5, 0.4, 0.4])
        )


# ---------------------------------------------------------------- construction


def test_unknown_frame_raises_listing_frames(model):
    with pytest.raises(ParameterError, match=r"'gripper'.*'ee'"):
        PrescribedPerformanceController(model, "gripper")


def test_model_without_free_flyer_raises():
    fixed = pin.Model()
    fixed.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    with pytest.raises(ParameterError, match="free-flyer"):
        PrescribedPerformanceController(fixed, "universe")


@pytest.mark.parametrize("n_joints", [0, 2, 4, 6])
def test_any_number_of_joints(n_joints):
    model = build_test_uvms(n_joints)
    q = pin.neutral(model)
    q[7:] = 0.3 * np.arange(1, n_joints + 1) / max(n_joints, 1)
    controller = controller_holding_orientation(model, q)
    tau = controller.compute(0.0, make_measurement(model, q, force=(0.3, 0.0, 0.0)))
    assert tau.shape == (model.nv,) == (6 + n_joints,)
    assert np.all(np.isfinite(tau))
    expected = ["u", "v", "w", "p", "q", "r"] + [f"arm_joint_{i + 1}" for i in range(n_joints)]
    assert list(controller.second_level_names) == expected
    assert controller.first_level_names == FIRST_LEVEL_NAMES


# ---------------------------------------------------------------- signs


def test_force_above_desired_backs_the_end_effector_off(model, q_bent):
    """e_f,x > 0 -> xdot_r,x < 0; zeta_r realizes xdot_r (J zeta_r = xdot_r, J full row rank),
    and following zeta_r for a short time lowers f_x = K_f (p_x - p0_x) with K_f > 0."""
    controller = controller_holding_orientation(model, q_bent)
    force = np.array([0.5, 0.0, 0.0])  # desired is zero: e_f = +0.5 N, inside rho0 = 1 N
    controller.compute(0.0, make_measurement(model, q_bent, force=force))
    signals = controller.last_signals
    assert signals.e_x[0] == pytest.approx(0.5)
    assert signals.xdot_r[0] < 0.0
    # k_x eps(0.5) = 0.2 ln 3
    assert signals.xdot_r[0] == pytest.approx(-0.2 * np.log(3.0), rel=1e-12)
    np.testing.assert_allclose(signals.xdot_r[1:], 0.0, atol=1e-15)

    jacobian = analytical_jacobian(
        model, model.createData(), q_bent, frame_id_from_name(model, "ee")
    )
    np.testing.assert_allclose(jacobian @ signals.zeta_r, signals.xdot_r, atol=1e-12)

    dt = 1e-3
    p0 = ee_position(model, q_bent) - force / K_F_N_PER_M  # anchor so that f = K_f (p - p0)
    q_next = pin.integrate(model, q_bent, dt * signals.zeta_r)
    force_next = K_F_N_PER_M * (ee_position(model, q_next) - p0)
    assert force_next[0] < force[0]
    # first order: delta f_x = K_f xdot_r,x dt, to O(dt^2)
    assert force_next[0] - force[0] == pytest.approx(K_F_N_PER_M * signals.xdot_r[0] * dt, rel=1e-3)
    np.testing.assert_allclose(force_next[1:], 0.0, atol=1e-6)


def test_force_below_desired_pushes_into_the_environment(model, q_bent):
    controller = controller_holding_orientation(
        model,
        q_bent,
        desired_force_world_N=lambda t: np.array([0.4 * np.sin(np.pi * t) + 0.4, 0, 0]),
    )
    controller.compute(0.0, make_measurement(model, q_bent))
    signals = controller.last_signals
    assert signals.force_desired_world_N[0] == pytest.approx(0.4)
    assert signals.e_x[0] == pytest.approx(-0.4)
    assert signals.xdot_r[0] > 0.0


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_orientation_error_is_reduced(model, q_bent, axis):
    """A positive roll/pitch/yaw error asks a negative Euler rate, and following zeta_r
    for a short time reduces that angle's error."""
    rpy_now = ee_rpy(model, q_bent)
    desired = rpy_now.copy()
    desired[axis] -= 0.3
    controller = PrescribedPerformanceController(model, "ee", desired_rpy=desired)
    controller.compute(0.0, make_measurement(model, q_bent))
    signals = controller.last_signals
    assert signals.e_x[3 + axis] == pytest.approx(0.3)
    assert signals.xdot_r[3 + axis] < 0.0
    q_next = pin.integrate(model, q_bent, 1e-3 * signals.zeta_r)
    error_next = ee_rpy(model, q_next) - desired
    assert abs(error_next[axis]) < 0.3
    assert error_next[axis] - 0.3 == pytest.approx(1e-3 * signals.xdot_r[3 + axis], rel=1e-3)


def test_second_level_value_and_sign(model, q_bent):
    """Zero first-level error -> zeta_r = 0; a surge speed of 0.1 m/s at t = 0 (rho = 1)
    gives tau_u = -k r(0.1) eps(0.1) / rho = -5 * (2 / 0.99) * ln(1.1 / 0.9) = -2.0269767."""
    controller = controller_holding_orientation(model, q_bent)
    v = np.zeros(model.nv)
    v[0] = 0.1
    v[7] = -0.05  # second arm joint turning backwards -> positive torque
    tau = controller.compute(0.0, make_measurement(model, q_bent, v=v))
    np.testing.assert_allclose(controller.last_signals.zeta_r, 0.0, atol=1e-15)
    assert tau[0] == pytest.approx(-5.0 * (2.0 / 0.99) * np.log(1.1 / 0.9), rel=1e-12)
    assert tau[0] == pytest.approx(-2.0269767, abs=1e-7)
    assert tau[7] > 0.0
    np.testing.assert_allclose(np.delete(tau, [0, 7]), 0.0, atol=1e-15)


def test_law_matches_the_formula_at_a_generic_state(model, q_bent):
    """tau = -K_zeta P^-1 R(xi_zeta) eps_zeta recomputed from the logged signals."""
    rng = np.random.default_rng(7)
    controller = PrescribedPerformanceController(
        model,
        "ee",
        desired_force_world_N=[0.1, -0.05, 0.0],
        desired_rpy=ee_rpy(model, q_bent) + 0.05,
    )
    time_s = 0.3
    v = 0.02 * rng.normal(size=model.nv)
    tau = controller.compute(time_s, make_measurement(model, q_bent, v=v, force=(0.2, 0.1, -0.1)))
    s = controller.last_signals
    rho_x = (np.array([1, 1, 1, 0.9, 0.9, 0.9]) - 0.2) * np.exp(-3.0 * time_s) + 0.2
    np.testing.assert_allclose(s.rho_x, rho_x, rtol=1e-14)
    np.testing.assert_allclose(s.e_x[:3], [0.1, 0.15, -0.1], atol=1e-15)
    np.testing.assert_allclose(s.e_x[3:], -0.05, atol=1e-12)
    np.testing.assert_allclose(s.xdot_r, -0.2 * transformed_error(s.e_x / rho_x), rtol=1e-14)
    np.testing.assert_allclose(s.e_zeta, v - s.zeta_r, atol=1e-15)
    rho_zeta = (1.0 - np.r_[[0.2] * 6, [0.4] * 4]) * np.exp(-2.2 * time_s) + np.r_[
        [0.2] * 6, [0.4] * 4
    ]
    np.testing.assert_allclose(s.rho_zeta, rho_zeta, rtol=1e-14)
    xi = s.e_zeta / rho_zeta
    expected = -5.0 * transformation_gain(xi) * transformed_error(xi) / rho_zeta
    np.testing.assert_allclose(tau, expected, rtol=1e-12, atol=1e-14)


# ---------------------------------------------------------------- funnels


def test_first_level_violation_names_force_component(model, q_bent):
    controller = controller_holding_orientation(model, q_bent)
    with pytest.raises(FunnelViolation) as info:
        controller.compute(0.0, make_measurement(model, q_bent, force=(0.0, 1.2, 0.0)))
    assert info.value.level == "first"
    assert info.value.component == "f_y"
    assert info.value.bound == pytest.approx(1.0)
    assert info.value.error == pytest.approx(1.2)


def test_second_level_violation_names_joint(model, q_bent):
    controller = controller_holding_orientation(model, q_bent)
    v = np.zeros(model.nv)
    v[9] = 1.5  # last arm joint, rho0 = 1 rad/s
    with pytest.raises(FunnelViolation) as info:
        controller.compute(0.0, make_measurement(model, q_bent, v=v))
    assert info.value.level == "second"
    assert info.value.component == "arm_joint_4"
    assert "arm_joint_4" in str(info.value)


def test_funnel_shrinks_with_time(model, q_bent):
    """e_f = 0.5 N is inside at t = 0 (rho = 1 N) but outside at t = 1 s (rho = 0.24 N)."""
    controller = controller_holding_orientation(model, q_bent)
    measurement = make_measurement(model, q_bent, force=(0.5, 0.0, 0.0))
    controller.compute(0.0, measurement)
    with pytest.raises(FunnelViolation) as info:
        controller.compute(1.0, measurement)
    assert info.value.time_s == 1.0
    assert info.value.bound == pytest.approx(0.8 * np.exp(-3.0) + 0.2)


def test_bad_measurement_raises(model, q_bent):
    controller = controller_holding_orientation(model, q_bent)
    with pytest.raises(ParameterError):
        controller.compute(0.0, make_measurement(model, q_bent, v=np.zeros(model.nv + 1)))
    with pytest.raises(ParameterError):
        controller.compute(0.0, make_measurement(model, q_bent, force=(np.nan, 0.0, 0.0)))


# ---------------------------------------------------------------- determinism, model-free


def test_output_is_a_deterministic_function_of_the_measurement(model, q_bent):
    rng = np.random.default_rng(3)
    v = 0.05 * rng.normal(size=model.nv)
    measurement = make_measurement(model, q_bent, v=v, force=(0.3, 0.05, -0.02))
    controller = controller_holding_orientation(model, q_bent)
    tau_first = controller.compute(0.2, measurement)
    # An unrelated call in between must not change the next answer (no hidden state).
    controller.compute(
        0.4, make_measurement(model, arm_configuration(model, [0.1, -0.3, 0.5, 0.0]))
    )
    tau_again = controller.compute(0.2, measurement)
    tau_fresh = controller_holding_orientation(model, q_bent).compute(0.2, measurement)
    np.testing.assert_array_equal(tau_first, tau_again)
    np.testing.assert_array_equal(tau_first, tau_fresh)
    assert tau_first.shape == (model.nv,)
    controller.reset()
    assert controller.last_signals is None


@pytest.mark.parametrize("backend", ["core", "python"])
def test_model_free_inertias_do_not_matter(q_bent, backend):
    """Same kinematics, inertias scaled by 7: identical tau for the same measurement."""
    light, heavy = build_test_uvms(mass_scale=1.0), build_test_uvms(mass_scale=7.0)
    measurement = make_measurement(light, q_bent, v=0.01 * np.ones(light.nv), force=(0.2, 0, 0))
    rpy = ee_rpy(light, q_bent)
    tau_light = PrescribedPerformanceController(
        light, "ee", desired_rpy=rpy, backend=backend
    ).compute(0.1, measurement)
    tau_heavy = PrescribedPerformanceController(
        heavy, "ee", desired_rpy=rpy, backend=backend
    ).compute(0.1, measurement)
    np.testing.assert_array_equal(tau_light, tau_heavy)


def test_model_free_the_compiled_law_uses_only_frame_kinematics():
    """The compiled law (src/uvms_core/ppc.cpp on the force task, law_force_task.cpp, and
    the frame Jacobian's unit, pinocchio_frame_jacobian.cpp) calls one Pinocchio algorithm,
    the frame Jacobian, and no other (the Python test below cannot patch C++ calls); it
    includes no Pinocchio algorithm header (the Jacobian's template is declared, not
    included) and none of the core's dynamics."""
    core = ROOT / "src" / "uvms_core"
    names = ("ppc", "law_force_task", "pinocchio_frame_jacobian")
    source = "".join((core / f"{name}.cpp").read_text() for name in names)
    header = "".join((core / f"{name}.hpp").read_text() for name in names)
    header += (core / "law.hpp").read_text()
    algorithms = re.findall(r"#include <pinocchio/algorithm/([\w-]+)\.hpp>", source + header)
    assert algorithms == []
    calls = set(re.findall(r"pinocchio::(\w+)\(", source))
    assert calls == {"computeFrameJacobian"}, calls
    local = set(re.findall(r'#include "([\w.]+)"', source + header))
    expected = {"ppc.hpp", "law.hpp", "law_force_task.hpp", "types.hpp"}
    assert local == expected | {"pinocchio_frame_jacobian.hpp"}, local


def test_model_free_no_dynamics_algorithm_is_called(model, q_bent, monkeypatch):
    """Every Pinocchio dynamics entry point raises: the controller still computes tau."""

    def forbidden(*args, **kwargs):
        raise AssertionError("the model-free controller called a dynamics algorithm")

    for name in (
        "crba",
        "rnea",
        "aba",
        "nonLinearEffects",
        "computeGeneralizedGravity",
        "computeAllTerms",
        "computeCoriolisMatrix",
        "computeMinverse",
        "forwardDynamics",
        "centerOfMass",
    ):
        monkeypatch.setattr(pin, name, forbidden)
    controller = controller_holding_orientation(model, q_bent, backend="python")
    tau = controller.compute(0.1, make_measurement(model, q_bent, force=(0.2, 0.0, 0.0)))
    assert np.all(np.isfinite(tau))


# ---------------------------------------------------------------- null-space task


def test_null_space_task_keeps_the_end_effector_task(model):
    """With k_0 > 0 the secondary velocity lies in ker J: J zeta_r is still xdot_r, and the
    arm joints far from mid-range get a component toward mid-range."""
    q = arm_configuration(model, [2.0, -0.4, 0.6, -2.0])  # joints 1 and 4 near their limits
    force = (0.3, 0.0, 0.0)
    plain = controller_holding_orientation(model, q)
    with_task = controller_holding_orientation(
        model, q, params=PPCParams(null_space_gain_per_s=0.5)
    )
    plain.compute(0.0, make_measurement(model, q, force=force))
    with_task.compute(0.0, make_measurement(model, q, force=force))
    jacobian = analytical_jacobian(model, model.createData(), q, frame_id_from_name(model, "ee"))
    s_plain, s_task = plain.last_signals, with_task.last_signals
    np.testing.assert_allclose(jacobian @ s_task.zeta_r, s_task.xdot_r, atol=1e-12)
    difference = s_task.zeta_r - s_plain.zeta_r
    assert np.linalg.norm(difference) > 1e-3
    # The difference is the projection of zeta_0 onto ker J: it does not oppose zeta_0.
    zeta_0 = with_task.null_space_velocity(q)
    np.testing.assert_allclose(zeta_0[:6], 0.0)
    assert zeta_0[6] == pytest.approx(-0.5 * 2.0 / 2.5) and zeta_0[9] == pytest.approx(0.4)
    assert difference @ zeta_0 > 0.0


@pytest.mark.parametrize("backend", ["core", "python"])
@pytest.mark.parametrize("turns", [1, -1, 2])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_an_orientation_error_is_read_wrapped_to_within_pi(model, q_bent, axis, turns, backend):
    """A desired angle a whole number of turns away from another is the same orientation:
    the error, the reference velocity and the torque are those of the angle itself (a roll
    or yaw crossing +-pi, where matrixToRpy jumps by 2 pi, is not a huge error), on the
    compiled law as on the reference."""
    rpy_now = ee_rpy(model, q_bent)
    near = rpy_now.copy()
    near[axis] -= 0.3
    far = near.copy()
    far[axis] += turns * 2.0 * np.pi
    out = []
    for desired in (near, far):
        controller = PrescribedPerformanceController(
            model, "ee", desired_rpy=desired, backend=backend
        )
        tau = controller.compute(0.0, make_measurement(model, q_bent))
        out.append((tau, controller.last_signals))
    (tau_near, near_signals), (tau_far, far_signals) = out
    assert far_signals.e_x[3 + axis] == pytest.approx(0.3, abs=1e-12)
    np.testing.assert_allclose(far_signals.e_x, near_signals.e_x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tau_far, tau_near, rtol=1e-9, atol=1e-9)
