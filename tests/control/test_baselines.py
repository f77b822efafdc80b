"""The baseline controllers (issue 14.1): computed torque tracks exactly with the exact model,
the model-free ones ignore the plant's parameters, and scenario files select them."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from uvms_pin.control.baselines.computed_torque import ComputedTorqueController
from uvms_pin.control.baselines.impedance import ImpedanceController
from uvms_pin.control.baselines.pi_force import PIForceController
from uvms_pin.control.baselines.task import ForceOrientationLoop
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.closed_loop import simulate_closed_loop
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorConfig, SensorSuite
from uvms_pin.sim.settings import SimulationSettings

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def _ee_name(uvms) -> str:
    return uvms.model.frames[uvms.require_ee_frame("test")].name


def _motion_reference(uvms, q0):
    """Constant body twist of the vehicle and sinusoidal joints: exact q_r, zeta_r, a_r."""
    n_arm = uvms.nv - 6
    twist = np.array([0.2, -0.1, 0.05, 0.1, -0.05, 0.2])
    amplitude, omega = np.full(n_arm, 0.3), 2.0 * np.pi * 0.5

    def reference(time_s):
        s, c = np.sin(omega * time_s), np.cos(omega * time_s)
        q_r = pin.integrate(uvms.model, q0, np.r_[twist * time_s, amplitude * s])
        return (
            q_r,
            np.r_[twist, amplitude * omega * c],
            np.r_[np.zeros(6), -amplitude * omega**2 * s],
        )

    return reference


def _track(reference_uvms, model_uvms) -> float:
    q0 = pin.neutral(reference_uvms.model)
    q0[2] = -2.0
    reference = _motion_reference(reference_uvms, q0)
    controller = ComputedTorqueController(
        model_uvms, _ee_name(reference_uvms), reference=reference,
        velocity_gain_per_s=10.0, position_gain_per_s2=25.0,
    )  # fmt: skip
    settings = SimulationSettings(1.0, RK4(step_s=1e-3), log_period_s=0.01)  # continuous control
    sensors = SensorSuite(reference_uvms.model, SensorConfig(), 1.0, 0)
    rollout = simulate_closed_loop(
        Plant(reference_uvms), controller, sensors, q0, reference(0.0)[1], settings
    )
    errors = [
        np.linalg.norm(pin.difference(reference_uvms.model, q, reference(t)[0]))
        for t, q in zip(rollout.time_s, rollout.q, strict=True)
    ]
    return float(max(errors))


def test_computed_torque_with_the_exact_model_tracks_to_numerical_precision(reference_uvms):
    exact = _track(reference_uvms, reference_uvms)
    assert exact < 1e-9
    # what model error costs: 30 % more mass and added mass in the controller's model
    wrong = _track(
        reference_uvms, scaled_uvms(reference_uvms, mass_scale=1.3, added_mass_scale=1.3)
    )
    assert wrong > 1e3 * max(exact, 1e-12)


def _measurement(uvms, rng) -> Measurement:
    q = pin.neutral(uvms.model)
    q[7:] = [-0.2, 1.0, -0.8, 0.2][: uvms.nv - 6]
    return Measurement(0.3, q, rng.normal(0.0, 0.1, uvms.nv), np.r_[rng.normal(0, 0.5, 3), 0, 0, 0])


@pytest.mark.parametrize("cls", [PIForceController, ImpedanceController])
def test_model_free_controllers_ignore_the_plant_parameters(reference_uvms, cls):
    """Built on a plant with every inertial and hydrodynamic parameter x1.3 or x0.7, the
    same measurement gives the same tau, bit for bit."""
    measurement = _measurement(reference_uvms, np.random.default_rng(14))
    taus = []
    for scale in (1.0, 0.7, 1.3):
        uvms = scaled_uvms(
            reference_uvms, mass_scale=scale, added_mass_scale=scale, damping_scale=scale,
            buoyancy_scale=scale,
        )  # fmt: skip
        controller = cls(uvms.model, _ee_name(uvms), desired_force_world_N=(0.4, 0.0, 0.0))
        controller.compute(0.29, measurement)  # (the PI's integral advances on the second call)
        taus.append(controller.compute(0.3, measurement))
    assert np.any(taus[0] != 0.0)
    for tau in taus[1:]:
        np.testing.assert_array_equal(tau, taus[0])


def test_computed_torque_uses_its_model(reference_uvms):
    measurement = _measurement(reference_uvms, np.random.default_rng(3))
    ee = _ee_name(reference_uvms)
    exact = ComputedTorqueController(reference_uvms, ee).compute(0.3, measurement)
    heavier = ComputedTorqueController(scaled_uvms(reference_uvms, mass_scale=1.3), ee)
    assert not np.allclose(heavier.compute(0.3, measurement), exact)


def test_pi_force_and_computed_torque_share_the_force_task(reference_uvms):
    """The same `ForceTaskOptions` keywords give both the same reference velocity; an
    unknown keyword or a bad gain is refused by name."""
    ee = _ee_name(reference_uvms)
    options = {
        "kp_force_m_s_per_N": 0.3,
        "null_space_gain_per_s": 0.5,
        "desired_force_world_N": (0.4, 0.0, 0.0),
    }
    measurement = _measurement(reference_uvms, np.random.default_rng(7))
    pi = PIForceController(reference_uvms.model, ee, **options)
    computed = ComputedTorqueController(reference_uvms, ee, **options)
    for controller in (pi, computed):
        controller.compute(0.29, measurement)
        controller.compute(0.3, measurement)
    np.testing.assert_array_equal(pi.signals()["zeta_r"], computed.signals()["zeta_r"])
    with pytest.raises(TypeError, match="stiffness_N_m"):
        PIForceController(reference_uvms.model, ee, stiffness_N_m=1.0)
    with pytest.raises(ParameterError, match="ki_force_m_s2_per_N"):
        ComputedTorqueController(reference_uvms, ee, ki_force_m_s2_per_N=-1.0)


def _with_controller(table: dict):
    """The realistic scenario (0.1 s) with its [controller] table replaced."""
    raw = read_toml(REALISTIC, ScenarioError)
    raw.pop("baselines")  # the tunings compare-controllers uses; not this table's
    raw["controller"] = {"desired_force": raw["controller"]["desired_force"], **table}
    raw["scenario"]["duration_s"] = 0.1
    return scenario_from_dict(raw, REALISTIC)


@pytest.mark.parametrize(
    "kind, cls",
    [
        ("pi_force", PIForceController),
        ("impedance", ImpedanceController),
        ("computed_torque", ComputedTorqueController),
    ],
)
def test_scenario_selects_the_baseline(kind, cls):
    scenario = _with_controller({"type": kind})
    assert isinstance(scenario.controller_factory(scenario.uvms), cls)
    assert scenario.controller_factory.type == kind
    assert scenario.controller_factory.params["desired_force"]["offset"] == [0.4, 0.0, 0.0]


def test_baseline_rejects_a_ppc_key_and_a_bad_gain():
    with pytest.raises(ScenarioError, match="k_zeta"):
        load_scenario(REALISTIC, {"controller.type": "pi_force"})
    with pytest.raises(ScenarioError, match="damping"):
        _with_controller({"type": "pi_force", "damping": -1.0})


def test_a_gain_that_is_not_numbers_is_refused_by_name(reference_uvms):
    """A string or None as a gain (Python API: the scenario reader refuses them first):
    ParameterError naming it (was: numpy's ValueError or TypeError from float())."""
    model = reference_uvms.model
    ee = model.frames[reference_uvms.ee_frame_id].name
    for given in ("20", None, ["a", "b"]):
        with pytest.raises(ParameterError, match="damping must be a number or"):
            PIForceController(model, ee, damping=given)
        with pytest.raises(ParameterError, match="stiffness_N_m must be a number or"):
            ImpedanceController(model, ee, stiffness_N_m=given)
        with pytest.raises(ParameterError, match="velocity_gain_per_s must be a number or"):
            ComputedTorqueController(reference_uvms, ee, velocity_gain_per_s=given)


def test_model_error_table():
    table = {"type": "computed_torque", "model_error": {"mass_scale": 1.3}}
    scenario = _with_controller(table)
    controller = scenario.controller_factory(scenario.uvms)
    assert controller.uvms.model.inertias[1].mass == pytest.approx(
        1.3 * scenario.uvms.model.inertias[1].mass
    )
    with pytest.raises(ScenarioError, match="mass_scale"):
        _with_controller({"type": "computed_torque", "model_error": {"mass_scale": -1.0}})


def test_each_baseline_on_the_nominal_realistic_task():
    """The shipped tunings over the full 10 s: pi_force and computed_torque hold the task
    (peak force error after t = 5 s <= 0.5 N, joints within limits); the impedance
    controller, which has no force feedback, does not, and says why."""
    from uvms_pin.apps.compare.metrics import Criteria
    from uvms_pin.apps.compare.runs import compare_controllers, controller_scenarios

    names = ["pi_force", "impedance", "computed_torque"]
    rows, _ = compare_controllers(controller_scenarios(REALISTIC, names), Criteria(5.0))
    verdict = {row["controller"]: row for row in rows}
    assert verdict["pi_force"]["success"] and verdict["computed_torque"]["success"]
    assert verdict["computed_torque"]["orientation_error_peak_rad"] < 0.1
    assert not verdict["impedance"]["success"]
    assert "force error after t = 5 s" in verdict["impedance"]["reason"]


@pytest.mark.parametrize("motion", [False, True])
def test_computed_torque_gives_the_commanded_acceleration_to_its_own_model(reference_uvms, motion):
    """Inverse dynamics: on the model it believes in, M zeta_dot + h = tau - J^T w_meas, its
    tau yields exactly the commanded acceleration, a = K_v (zeta_r - zeta) for the force
    task and a = zeta_dot_r + K_v (zeta_r - zeta) + K_q (q_r (-) q) for a motion task (a
    reference off the measured state, so that each term counts)."""
    from uvms_pin.physics.dynamics import bias_forces, mass_matrix

    uvms, ee = reference_uvms, _ee_name(reference_uvms)
    rng = np.random.default_rng(21)
    measurement = _measurement(uvms, rng)
    q, v = measurement.q, measurement.v
    k_v, k_q = rng.uniform(2.0, 8.0, uvms.nv), rng.uniform(10.0, 30.0, uvms.nv)
    q_r = pin.integrate(uvms.model, q, rng.normal(0.0, 0.1, uvms.nv))
    zeta_r, zeta_dot_r = rng.normal(0.0, 0.2, uvms.nv), rng.normal(0.0, 0.5, uvms.nv)
    controller = ComputedTorqueController(
        uvms, ee, reference=(lambda t: (q_r, zeta_r, zeta_dot_r)) if motion else None,
        velocity_gain_per_s=k_v, position_gain_per_s2=k_q, desired_force_world_N=(0.4, 0, 0),
    )  # fmt: skip
    tau = controller.compute(0.3, measurement)
    jacobian = controller.task.evaluate(0.3, measurement).jacobian_lwa
    wrench = np.asarray(measurement.wrench_world, dtype=float)
    achieved = np.linalg.solve(
        mass_matrix(uvms, q), tau - jacobian.T @ wrench - bias_forces(uvms, q, v)
    )
    if motion:
        commanded = zeta_dot_r + k_v * (zeta_r - v) + k_q * pin.difference(uvms.model, q, q_r)
    else:
        commanded = k_v * (controller.signals()["zeta_r"] - v)
    assert np.abs(commanded).max() > 0.1
    np.testing.assert_allclose(achieved, commanded, rtol=1e-9, atol=1e-9)


def test_pi_force_damps_the_velocity_about_its_reference(reference_uvms):
    """tau = -K_d (zeta - zeta_r): a damping about the reference velocity, each component
    with its own k_d, so tau . (zeta - zeta_r) = -sum k_d (zeta - zeta_r)^2 < 0 (it only
    takes energy out of the deviation from the reference)."""
    uvms, ee = reference_uvms, _ee_name(reference_uvms)
    rng = np.random.default_rng(22)
    measurement = _measurement(uvms, rng)
    damping = rng.uniform(5.0, 40.0, uvms.nv)
    controller = PIForceController(
        uvms.model, ee, damping=damping, desired_force_world_N=(0.4, 0.0, 0.0)
    )
    controller.compute(0.29, measurement)
    tau = controller.compute(0.3, measurement)
    deviation = measurement.v - controller.signals()["zeta_r"]
    np.testing.assert_allclose(tau, -damping * deviation, rtol=1e-14, atol=1e-14)
    assert tau @ deviation < 0.0


def test_the_force_loop_integrates_its_error_by_rectangles_within_its_limit():
    """xdot_r = -[kp e_f + ki I_f; k_o e_o], I_f advanced by the rectangle (t - t_last)
    e_f(t_last) at each later call and clipped to +-integral_limit per component (the
    anti-windup, both signs)."""
    kp, ki, k_o = np.array([0.1, 0.2, 0.3]), np.array([0.05, 0.5, 1.0]), np.array([1.0, 2.0, 3.0])
    loop = ForceOrientationLoop(kp, ki, k_o, np.array([5.0, 5.0, 0.4]))
    e0 = np.array([2.0, -1.0, 0.5, 0.1, -0.2, 0.3])
    np.testing.assert_allclose(loop.velocity(1.0, e0), -np.r_[kp * e0[:3], k_o * e0[3:]])
    e1 = np.array([-1.0, 3.0, 0.2, 0.0, 0.4, -0.1])
    integral = 0.5 * e0[:3]  # the first sample's error over [1.0, 1.5]
    expected = -np.r_[kp * e1[:3] + ki * integral, k_o * e1[3:]]
    np.testing.assert_allclose(loop.velocity(1.5, e1), expected, rtol=1e-14)
    np.testing.assert_allclose(loop.integral_Ns, integral, rtol=1e-14)
    # 100 s more of e1 would integrate to (-100, 300, 20) N s: clipped to (-5, 5, 0.4)
    loop.velocity(101.5, e1)
    np.testing.assert_allclose(loop.integral_Ns, [-5.0, 5.0, 0.4], rtol=1e-14)


def test_the_impedance_law_is_its_formula_at_a_generic_state(reference_uvms):
    """tau = J^T [f_d + K_p (p_a - p) - D_p p_dot; K_o log(R_d R^T) - D_o omega] - D_zeta
    zeta - [0; K_q (q (-) q_a)], J the end effector's world-aligned Jacobian, p_a and q_a
    the position and posture of the first call: recomputed from Pinocchio at a second,
    moved state, each gain its own."""
    uvms, ee = reference_uvms, _ee_name(reference_uvms)
    model, data = uvms.model, uvms.model.createData()
    frame = model.getFrameId(ee)
    rng = np.random.default_rng(5)
    gains = {
        "stiffness_N_m": rng.uniform(2.0, 8.0, 3),
        "damping_N_s_m": rng.uniform(5.0, 15.0, 3),
        "stiffness_Nm_rad": rng.uniform(1.0, 3.0, 3),
        "damping_Nm_s_rad": rng.uniform(0.2, 0.8, 3),
        "velocity_damping": rng.uniform(2.0, 8.0, uvms.nv),
        "posture_stiffness_Nm_rad": rng.uniform(0.2, 0.8, uvms.nv - 6),
    }
    f_d, rpy_d = np.array([0.3, -0.1, 0.5]), np.array([0.2, -0.3, 1.0])
    controller = ImpedanceController(
        model, ee, desired_force_world_N=f_d, desired_rpy=rpy_d, **gains
    )
    first = _measurement(uvms, rng)
    controller.compute(0.2, first)
    q = pin.integrate(model, first.q, rng.normal(0.0, 0.2, uvms.nv))
    v = rng.normal(0.0, 0.3, uvms.nv)
    tau = controller.compute(0.3, Measurement(0.3, q, v, np.zeros(6)))
    pin.framesForwardKinematics(model, data, first.q)  # the anchor: the first position
    anchor = data.oMf[frame].translation.copy()
    pin.framesForwardKinematics(model, data, q)
    placement = data.oMf[frame]
    jacobian = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    twist = jacobian @ v
    rotation_error = pin.log3(pin.rpy.rpyToMatrix(*rpy_d) @ placement.rotation.T)
    wrench = np.r_[
        f_d + gains["stiffness_N_m"] * (anchor - placement.translation)
        - gains["damping_N_s_m"] * twist[:3],
        gains["stiffness_Nm_rad"] * rotation_error - gains["damping_Nm_s_rad"] * twist[3:],
    ]  # fmt: skip
    expected = jacobian.T @ wrench - gains["velocity_damping"] * v
    expected[6:] -= gains["posture_stiffness_Nm_rad"] * pin.difference(model, first.q, q)[6:]
    np.testing.assert_allclose(tau, expected, rtol=1e-12, atol=1e-12)
    assert np.linalg.norm(anchor - placement.translation) > 0.05  # the spring is stretched
