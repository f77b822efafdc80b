"""The OCP's nodes integrated by crocoddyl's RK4 (``integrator="rk4"``): their derivatives
against crocoddyl's NumDiff and their step against the plant's own RK4.

crocoddyl is in the dev extra; without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy
from uvms_pin.physics.contact import LinearSpring

crocoddyl = pytest.importorskip("crocoddyl")

from uvms_pin.ocp import costs, problems  # noqa: E402
from uvms_pin.ocp.model import UnderwaterActionModel  # noqa: E402
from uvms_pin.physics.derivatives.task_contact import TaskContact  # noqa: E402

CURRENT = UniformCurrent([0.3, -0.1, 0.0])


def _state(uvms, rng):
    q = uvms.neutral_configuration()
    q[2] = -3.0
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(scale=0.3, size=3))).coeffs()
    q[7:] += rng.uniform(-0.5, 0.5, size=uvms.nv - 6)
    return np.r_[q, rng.normal(scale=0.3, size=uvms.nv)]


def _node_model(uvms, x, contact: bool):
    """A thruster-driven node in a current, bounded inputs as constraints, optionally with
    the end-effector on a spring (anchored 10 cm off the tip at x)."""
    b_u = up.input_matrix(bluerov2_heavy.thrusters(), uvms.nv)
    nu = b_u.shape[1]
    x_ref = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    target = pin.SE3(pin.exp3(np.array([0.1, -0.2, 0.3])), np.array([0.5, 0.1, -2.5]))
    terms = [
        (costs.end_effector_pose(uvms, target, np.ones(6)), 1.0),
        (costs.vehicle_attitude(uvms, np.eye(3), np.ones(3)), 0.5),
        (costs.StateDeviation(uvms.model, x_ref, np.full(2 * uvms.nv, 0.1)), 1.0),
        (costs.Effort(np.ones(nu)), 1e-3),
    ]
    task_contact = None
    if contact:
        data = uvms.model.createData()
        pin.framesForwardKinematics(uvms.model, data, x[: uvms.nq])
        tip = data.oMf[uvms.ee_frame_id].translation
        spring = LinearSpring(np.array([20.0, 30.0, 50.0]), tip - [0.1, 0.05, -0.05])
        task_contact = TaskContact(uvms.ee_frame_id, spring)
        terms.append((costs.ContactForce([0.4, 0.1, -0.2], [1.0, 0.5, 0.1]), 1.0))
    bounds = (np.full(nu, -20.0), np.full(nu, 20.0))
    return UnderwaterActionModel(
        uvms,
        terms,
        input_matrix_=b_u,
        flow=CURRENT,
        u_bounds=bounds,
        contact=task_contact,
        bounds_as_constraints=True,
    )


@pytest.mark.parametrize("contact", [False, True], ids=["free", "spring"])
def test_rk4_node_derivatives_match_crocoddyl_numdiff(reference_uvms, contact):
    """Fx, Fu (the RK4 step's, chained by crocoddyl through the four stages), Lx, Lu (the
    cost integrated over the step) and the input constraints' Gx, Gu against crocoddyl's
    ActionModelNumDiff (forward differences of the same node): held to 1e-5 relative
    (measured: 4e-7 at most, on Fx); the RK4 step is not the Euler one."""
    uvms = reference_uvms
    rng = np.random.default_rng(11)
    x = _state(uvms, rng)
    differential = _node_model(uvms, x, contact)
    node = problems.integrated_node(differential, 0.02, "rk4")
    numdiff = crocoddyl.ActionModelNumDiff(node, False)
    data, nd_data = node.createData(), numdiff.createData()
    u = rng.normal(scale=5.0, size=node.nu)
    node.calc(data, x, u)
    node.calcDiff(data, x, u)
    numdiff.calc(nd_data, x, u)
    numdiff.calcDiff(nd_data, x, u)
    np.testing.assert_array_equal(data.g, u)
    for name in ("Fx", "Fu", "Lx", "Lu", "Gx", "Gu"):
        got, expected = getattr(data, name), getattr(nd_data, name)
        scale = max(np.abs(expected).max(), 1e-9)
        assert np.abs(got - expected).max() < 1e-5 * scale, name
    euler = problems.integrated_node(differential, 0.02, "euler")
    euler_data = euler.createData()
    euler.calc(euler_data, x, u)
    assert np.abs(differential.state.diff(euler_data.xnext, data.xnext)).max() > 1e-3


def test_rk4_node_steps_like_the_plants_rk4(reference_uvms):
    """From the same state and input, in a uniform current, one RK4 node of 20 ms and one
    20 ms step of the plant's RK4 (`up.step_derivatives(..., integrator="rk4")`, the
    integrator of `Plant.advance`) end within 1e-4 of each other on the tangent (1.5e-5 at
    most measured: crocoddyl's stages move along v where the plant's move along the chart rate,
    a difference of order three) where an Euler node is 0.3 to 1 away on these brisk states
    (the arm's joints at 0.3 rad/s and up to 5 N m on them); at 10 ms the difference falls
    by more than 6x (8x measured: order three)."""
    uvms = reference_uvms
    rng = np.random.default_rng(3)
    x_ref = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    terms = [(costs.StateDeviation(uvms.model, x_ref, np.full(2 * uvms.nv, 0.1)), 1.0)]
    differential = UnderwaterActionModel(uvms, terms, flow=CURRENT)
    state = differential.state

    def gap(x, u, dt_s, integrator):
        node = problems.integrated_node(differential, dt_s, integrator)
        data = node.createData()
        node.calc(data, x, u)
        q, v = x[: uvms.nq], x[uvms.nq :]
        plant = up.step_derivatives(
            uvms, q, v, u, dt_s, step_s=dt_s, integrator="rk4", flow=CURRENT
        )
        return np.abs(state.diff(np.r_[plant.q, plant.v], data.xnext)).max()

    for _ in range(3):
        x, u = _state(uvms, rng), rng.normal(scale=5.0, size=uvms.nv)
        rk4 = gap(x, u, 0.02, "rk4")
        assert rk4 < 1e-4, rk4
        assert gap(x, u, 0.02, "euler") > 1e3 * rk4
        half = gap(x, u, 0.01, "rk4")
        assert half < rk4 / 6.0


def test_point_to_point_on_rk4_nodes_reaches_the_target(reference_uvms, ten_cm_move):
    """The 10 cm end-effector move of tests/ocp/test_ocp.py on RK4 nodes: solved to within
    5 mm (0.05 mm measured), and its controls replayed through the plant's RK4 (one 20 ms
    step per node) end within 1e-6 of the plan's last state (6e-8 measured: the plan's
    moves are slow, the two RK4s' difference of order three is small)."""
    uvms = reference_uvms
    q0, x0, target = ten_cm_move.q0, ten_cm_move.x0, ten_cm_move.target
    data = uvms.model.createData()
    problem = problems.point_to_point(uvms, x0, target, horizon_s=1.0, dt_s=0.02, integrator="rk4")
    solver = problems.solve(problem, iterations=60, solver="fddp")
    pin.framesForwardKinematics(uvms.model, data, solver.xs[-1][: uvms.nq])
    miss_m = np.linalg.norm(data.oMf[uvms.ee_frame_id].translation - target.translation)
    assert miss_m < 5e-3, miss_m
    q, v = q0, np.zeros(uvms.nv)
    for u in solver.us:
        step = up.step_derivatives(uvms, q, v, u, 0.02, step_s=0.02, integrator="rk4")
        q, v = step.q, step.v
    end = problem.terminalModel.state.diff(np.r_[q, v], solver.xs[-1])
    assert np.abs(end).max() < 1e-6, np.abs(end).max()


def test_an_unknown_integrator_is_refused(reference_uvms):
    x0 = np.r_[reference_uvms.neutral_configuration(), np.zeros(reference_uvms.nv)]
    with pytest.raises(ParameterError, match="euler, rk4"):
        problems.point_to_point(reference_uvms, x0, pin.SE3.Identity(), integrator="rk2")
