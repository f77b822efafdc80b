"""The crocoddyl action model of the UVMS in water, its derivatives and two OCPs.

crocoddyl is in the dev extra (``pip install -e '.[dev]'``); without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.flow import AiryWave, UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy

crocoddyl = pytest.importorskip("crocoddyl")

from uvms_pin.ocp import costs, problems  # noqa: E402
from uvms_pin.ocp.model import UnderwaterActionModel  # noqa: E402
from uvms_pin.ocp.state import UvmsState  # noqa: E402


def _state(uvms, rng):
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(scale=0.3, size=3))).coeffs()
    q[7:] += rng.uniform(-0.5, 0.5, size=uvms.nv - 6)
    return np.r_[q, rng.normal(scale=0.3, size=uvms.nv)]


def _model(uvms, flow, actuators: problems.Actuators):
    nu = actuators.nu(uvms.nv)
    target = pin.SE3(pin.exp3(np.array([0.1, -0.2, 0.3])), np.array([0.5, 0.1, -2.5]))
    x_ref = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    terms = [
        (costs.end_effector_pose(uvms, target, np.ones(6)), 1.0),
        (costs.FramePosition(uvms.ee_frame_id, [0.3, 0.0, -3.0], np.ones(3)), 0.3),
        (costs.vehicle_attitude(uvms, np.eye(3), np.ones(3)), 0.5),
        (costs.StateDeviation(uvms.model, x_ref, np.full(2 * uvms.nv, 0.1)), 1.0),
        (costs.Effort(np.ones(nu)), 1e-3),
    ]
    return UnderwaterActionModel(
        uvms, terms, input_matrix_=actuators.input_matrix, flow=flow, time_s=0.3
    )


def _thrusters(uvms) -> problems.Actuators:
    thrusters = bluerov2_heavy.thrusters()
    b_u = up.input_matrix(thrusters, uvms.nv)
    return problems.Actuators(b_u, None)


def test_the_state_manifold_is_pinocchios_and_its_jacobians_match_numdiff(reference_uvms):
    """diff / integrate are Pinocchio's; Jdiff and Jintegrate against crocoddyl's StateNumDiff
    (forward differences of the same diff / integrate). (crocoddyl 3.2.1's own
    StateMultibody returns NaN beside pin 4.1: the reason UvmsState exists.)"""
    model = reference_uvms.model
    state, numdiff = UvmsState(model), None
    numdiff = crocoddyl.StateNumDiff(state)
    rng = np.random.default_rng(6)
    for _ in range(3):
        x0, x1 = _state(reference_uvms, rng), _state(reference_uvms, rng)
        dx = state.diff(x0, x1)
        np.testing.assert_allclose(
            dx[: model.nv], pin.difference(model, x0[: model.nq], x1[: model.nq]), atol=1e-15
        )
        back = state.integrate(x0, dx)
        np.testing.assert_allclose(state.diff(x1, back), 0.0, atol=1e-12)
        for name, args in (("Jdiff", (x0, x1)), ("Jintegrate", (x0, dx))):
            got = getattr(state, name)(*args, crocoddyl.Jcomponent.both)
            expected = getattr(numdiff, name)(*args, crocoddyl.Jcomponent.both)
            for g, e in zip(got, expected, strict=True):
                np.testing.assert_allclose(g, e, atol=1e-6)


def test_the_state_difference_of_a_continuous_joint_is_exact_at_tiny_angles(tmp_path):
    """x1 (-) x0 of a continuous joint (q its cos and sin) is the angle between them to
    1e-15 rad (the rounding of cos and sin) for steps of 1e-12 to 1e-6 rad, at any base
    angle: what crocoddyl's NumDiff (steps ~1.5e-8) differences. Pinocchio 4.1's
    difference returns 0 for about 1 % of such steps (its SO(2) log rounds a trace just
    above 2 to the identity)."""
    from conftest import continuous_joint_urdf

    uvms = up.load_uvms(continuous_joint_urdf(tmp_path))
    model, state = uvms.model, UvmsState(uvms.model)
    joint = model.getJointId("arm_joint2")
    iq, iv = model.idx_qs[joint], model.idx_vs[joint]
    rng = np.random.default_rng(11)
    x0 = np.r_[pin.neutral(model), np.zeros(model.nv)]
    for _ in range(500):
        angle, step = rng.uniform(-np.pi, np.pi), 10 ** rng.uniform(-12, -6)
        x0[iq : iq + 2] = np.cos(angle), np.sin(angle)
        tangent = np.zeros(2 * model.nv)
        tangent[iv] = step
        x1 = state.integrate(x0, tangent)
        np.testing.assert_allclose(state.diff(x0, x1)[iv], step, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize("actuated", ["tau", "thrusters"])
@pytest.mark.parametrize(
    "flow",
    [None, UniformCurrent([0.3, -0.1, 0.0]), AiryWave(0.3, 5.0, water_depth_m=20.0)],
    ids=["still", "current", "wave"],
)
def test_calc_diff_matches_crocoddyl_numdiff(reference_uvms, flow, actuated):
    """Fx, Fu (the dynamics) and Lx, Lu (the costs) against crocoddyl's own forward
    differences (DifferentialActionModelNumDiff, step ~ sqrt(machine eps): ~1e-7 relative
    error expected, held to 1e-5). Lxx is Gauss-Newton (not compared)."""
    actuators = problems.Actuators() if actuated == "tau" else _thrusters(reference_uvms)
    model = _model(reference_uvms, flow, actuators)
    numdiff = crocoddyl.DifferentialActionModelNumDiff(model, False)
    data, nd_data = model.createData(), numdiff.createData()
    rng = np.random.default_rng(7)
    for _ in range(2):
        x = _state(reference_uvms, rng)
        u = rng.normal(scale=5.0, size=model.nu)
        model.calc(data, x, u)
        model.calcDiff(data, x, u)
        numdiff.calc(nd_data, x, u)
        numdiff.calcDiff(nd_data, x, u)
        np.testing.assert_allclose(data.xout, nd_data.xout, rtol=0, atol=1e-12)
        for name in ("Fx", "Fu", "Lx", "Lu"):
            got, expected = getattr(data, name), getattr(nd_data, name)
            scale = max(np.abs(expected).max(), 1e-9)
            assert np.abs(got - expected).max() < 1e-5 * scale, name


def test_the_model_dynamics_are_uvms_pin_forward_dynamics(reference_uvms):
    actuators = _thrusters(reference_uvms)
    current = UniformCurrent([0.2, 0.0, 0.1])
    model = _model(reference_uvms, current, actuators)
    data = model.createData()
    x = _state(reference_uvms, np.random.default_rng(8))
    u = np.linspace(-10, 10, model.nu)
    model.calc(data, x, u)
    q, v = x[: reference_uvms.nq], x[reference_uvms.nq :]
    expected = up.forward_dynamics(
        reference_uvms, q, v, actuators.input_matrix @ u, flow=current, time_s=0.3
    )
    np.testing.assert_array_equal(data.xout, expected)


def test_point_to_point_moves_the_end_effector(reference_uvms, ten_cm_move):
    """A 10 cm end-effector move in 1 s (50 nodes), tau as the input: the solved rollout
    reaches the target and ends nearly at rest; replaying its controls through uvms-pin's own
    semi-implicit Euler gives the same trajectory (the OCP's model is the simulator's)."""
    uvms = reference_uvms
    q0, x0, target = ten_cm_move.q0, ten_cm_move.x0, ten_cm_move.target
    data = uvms.model.createData()
    problem = problems.point_to_point(uvms, x0, target, horizon_s=1.0, dt_s=0.02)
    solver = problems.solve(problem, iterations=60, solver="fddp")
    q_end = solver.xs[-1][: uvms.nq]
    pin.framesForwardKinematics(uvms.model, data, q_end)
    miss_m = np.linalg.norm(data.oMf[uvms.ee_frame_id].translation - target.translation)
    assert miss_m < 5e-3, miss_m
    assert np.linalg.norm(solver.xs[-1][uvms.nq :]) < 0.05
    q, v = q0, np.zeros(uvms.nv)
    for k, u in enumerate(solver.us):
        step = up.step_derivatives(uvms, q, v, u, 0.02, step_s=0.02, time_s=0.02 * k)
        q, v = step.q, step.v
    np.testing.assert_allclose(np.r_[q, v], solver.xs[-1], atol=1e-8)


def test_station_hold_in_a_current_with_bounded_thrusters(reference_uvms):
    """In a 0.3 m/s current the vehicle left alone (from rest) drifts 9 cm in 1 s; the OCP
    with the BlueROV2 Heavy's eight bounded thrusters keeps it within 5 mm of its station (0.7 mm measured),
    its thrusts within their limits."""
    uvms = reference_uvms
    q0 = uvms.neutral_configuration()
    q0[2] = -3.0
    x0 = np.r_[q0, np.zeros(uvms.nv)]
    thrusters = bluerov2_heavy.thrusters()
    b_u = up.input_matrix(thrusters, uvms.nv)
    effort = uvms.model.effortLimit[6:]
    lower = np.r_[[-t.max_reverse_N for t in thrusters], -effort]
    upper = np.r_[[t.max_forward_N for t in thrusters], effort]
    current = UniformCurrent([0.3, 0.0, 0.0])
    station = pin.SE3(np.eye(3), q0[:3].copy())
    problem = problems.station_hold(
        uvms,
        x0,
        station,
        horizon_s=1.0,
        dt_s=0.02,
        actuators=problems.Actuators(b_u, (lower, upper)),
        flow=current,
    )
    solver = problems.solve(problem, iterations=80)
    # the controls replayed through the dynamics (no gaps left by the solver)
    xs = problem.rollout(list(solver.us))
    np.testing.assert_allclose(np.array(xs), np.array(solver.xs), atol=1e-6)
    drift = max(np.linalg.norm(x[:3] - q0[:3]) for x in xs)
    us = np.array(solver.us)
    assert drift < 5e-3, drift
    assert np.all(us >= lower - 1e-9) and np.all(us <= upper + 1e-9)
    # left alone, the same current carries it away
    passive = problems.station_hold(uvms, x0, station, horizon_s=1.0, dt_s=0.02, flow=current)
    xs = passive.rollout([np.zeros(uvms.nv)] * passive.T)
    assert np.linalg.norm(xs[-1][:3] - q0[:3]) > 0.08


def _force_model(uvms, contact_model, actuators: problems.Actuators):
    """A node of the force task: the contact in the dynamics, its force in the cost."""
    from uvms_pin.physics.derivatives.task_contact import TaskContact

    nu = actuators.nu(uvms.nv)
    x_ref = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    terms = [
        (costs.ContactForce([0.4, 0.1, -0.2], [1.0, 0.5, 0.1]), 1.0),
        (costs.end_effector_attitude(uvms, np.eye(3), np.ones(3)), 1.0),
        (costs.StateDeviation(uvms.model, x_ref, np.full(2 * uvms.nv, 0.1)), 1.0),
        (costs.Effort(np.ones(nu)), 1e-3),
        # a wide margin: some joints of the random states are past it (a non-zero term)
        (costs.JointLimitMargin(uvms.model, 1.0, 10.0), 1.0),
    ]
    contact = TaskContact(uvms.ee_frame_id, contact_model)
    return UnderwaterActionModel(uvms, terms, input_matrix_=actuators.input_matrix, contact=contact)


@pytest.mark.parametrize("environment", ["spring", "plane"])
def test_calc_diff_with_the_contact_matches_crocoddyl_numdiff(reference_uvms, environment):
    """With the end-effector on a spring or a spring-damper plane: Fx (the contact's
    generalized force and its derivatives inside) and Lx (the contact-force cost) against
    crocoddyl's NumDiff, held to 1e-5 as above; the contact does change the dynamics."""
    from uvms_pin.physics.contact import CompliantPlane, LinearSpring

    uvms = reference_uvms
    rng = np.random.default_rng(9)
    x = _state(uvms, rng)
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, x[: uvms.nq])
    tip = data.oMf[uvms.ee_frame_id].translation
    normal = np.array([-1.0, 0.2, 0.1]) / np.linalg.norm([-1.0, 0.2, 0.1])
    contact_model = (
        LinearSpring(np.array([20.0, 30.0, 50.0]), tip - [0.1, 0.05, -0.05])
        if environment == "spring"
        else CompliantPlane(normal, 1000.0, 2.0, tip + 0.005 * normal)
    )
    model = _force_model(uvms, contact_model, _thrusters(uvms))
    numdiff = crocoddyl.DifferentialActionModelNumDiff(model, False)
    data, nd_data = model.createData(), numdiff.createData()
    u = rng.normal(scale=5.0, size=model.nu)
    model.calc(data, x, u)
    model.calcDiff(data, x, u)
    numdiff.calc(nd_data, x, u)
    numdiff.calcDiff(nd_data, x, u)
    assert np.linalg.norm(data.contact.wrench_world[:3]) > 1.0
    assert np.any(data.residuals[-1])  # the joint-limit term is active
    q, v = x[: uvms.nq], x[uvms.nq :]
    free = up.forward_dynamics(uvms, q, v, model.input_matrix @ u)
    assert np.abs(data.xout - free).max() > 0.1
    for name in ("Fx", "Fu", "Lx", "Lu"):
        got, expected = getattr(data, name), getattr(nd_data, name)
        scale = max(np.abs(expected).max(), 1e-9)
        assert np.abs(got - expected).max() < 1e-5 * scale, name


def test_a_contact_force_cost_needs_a_contact(reference_uvms):
    from uvms_pin.errors import ParameterError

    with pytest.raises(ParameterError, match="contact force"):
        UnderwaterActionModel(reference_uvms, [(costs.ContactForce(np.zeros(3), np.ones(3)), 1.0)])


def test_calc_diff_reuses_the_contact_of_calc_only_at_the_same_state(reference_uvms):
    """calcDiff reuses the contact wrench its calc computed at the same state (crocoddyl's
    solvers calc first); after a calc elsewhere it recomputes it: the derivatives are those
    of a calc at the calcDiff's own state, bit for bit."""
    from uvms_pin.physics.contact import LinearSpring

    uvms = reference_uvms
    rng = np.random.default_rng(12)
    x, elsewhere = _state(uvms, rng), _state(uvms, rng)
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, x[: uvms.nq])
    tip = data.oMf[uvms.ee_frame_id].translation
    spring = LinearSpring(np.array([20.0, 30.0, 50.0]), tip - [0.1, 0.05, -0.05])
    model = _force_model(uvms, spring, _thrusters(uvms))
    u = rng.normal(scale=5.0, size=model.nu)
    same, stale = model.createData(), model.createData()
    model.calc(same, x, u)
    model.calcDiff(same, x, u)
    model.calc(stale, elsewhere, u)
    stale.residual = same.residual  # the costs' part reads calc's residual (a crocoddyl rule)
    model.calcDiff(stale, x, u)
    for name in ("Fx", "Fu", "Lx", "Lu", "Lxx"):
        np.testing.assert_array_equal(getattr(stale, name), getattr(same, name), err_msg=name)


def test_a_horizon_of_one_node_is_planned_and_one_of_none_refused(reference_uvms, ten_cm_move):
    """round(horizon_s / dt_s) nodes: a horizon of one node is a problem of one running node
    that solves (its one control moves the state as the simulator's step does); a horizon
    below half a node holds none and is refused, naming both times."""
    uvms, x0, target = reference_uvms, ten_cm_move.x0, ten_cm_move.target
    problem = problems.point_to_point(uvms, x0, target, horizon_s=0.02, dt_s=0.02)
    assert problem.T == 1
    solver = problems.solve(problem, iterations=5, solver="fddp")
    q0, v0 = x0[: uvms.nq], x0[uvms.nq :]
    step = up.step_derivatives(uvms, q0, v0, solver.us[0], 0.02, step_s=0.02)
    np.testing.assert_allclose(np.r_[step.q, step.v], solver.xs[1], atol=1e-8)
    with pytest.raises(up.ParameterError, match=r"horizon_s 0.009 s holds no node of dt_s 0.02"):
        problems.point_to_point(uvms, x0, target, horizon_s=0.009, dt_s=0.02)
