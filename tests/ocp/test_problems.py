"""The shooting problems' structure in time and their costs (`uvms_pin.ocp.problems`):
each node's dynamics at its own time in a moving flow, the desired force of each node at
its own offset, and the station-keeping cost as its docstring writes it.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import random_state

import uvms_pin as up
from uvms_pin.flow import AiryWave
from uvms_pin.physics.contact import LinearSpring

pytest.importorskip("crocoddyl")

from uvms_pin.ocp import costs, problems
from uvms_pin.physics.derivatives.task_contact import TaskContact

WAVE = AiryWave(0.5, 4.0, water_depth_m=20.0)
T0_S, DT_S, NODES = 0.3, 0.1, 4


def _xout(node, x, u):
    """The differential model's acceleration at (x, u)."""
    model = node.differential
    data = model.createData()
    model.calc(data, x, u)
    return np.array(data.xout)


def test_each_node_of_a_wave_problem_is_the_dynamics_at_its_own_time(reference_uvms):
    """In a wave the running node k is the forward dynamics at t0 + k dt and the terminal
    node at t0 + N dt (each node its own model: the flow moves along the horizon)."""
    uvms = reference_uvms
    q, v, tau = random_state(uvms, np.random.default_rng(21), depth_m=-1.5)
    x = np.r_[q, v]
    problem = problems.shooting_problem(
        uvms, x,
        lambda nu: [(costs.Effort(np.ones(nu)), 1.0)],
        lambda nu: [(costs.Effort(np.ones(nu)), 1.0)],
        nodes=NODES, dt_s=DT_S, flow=WAVE, time_s=T0_S,
    )  # fmt: skip
    nodes = [*problem.runningModels, problem.terminalModel]
    for k, node in enumerate(nodes):
        expected = up.forward_dynamics(uvms, q, v, tau, flow=WAVE, time_s=T0_S + k * DT_S)
        np.testing.assert_allclose(_xout(node, x, tau), expected, rtol=0, atol=1e-10)
    first, last = _xout(nodes[0], x, tau), _xout(nodes[-1], x, tau)
    assert np.abs(first - last).max() > 1e-3  # the wave does move the dynamics


def test_each_force_node_tracks_the_desired_force_at_its_own_offset(reference_uvms):
    """force_tracking's node k (terminal: N) asks for f_d(t0 + k dt), after `retarget` too."""
    uvms = reference_uvms
    x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    x0[2] = -3.0
    contact = TaskContact(uvms.ee_frame_id, LinearSpring(np.full(3, 2.0), np.zeros(3)))

    def desired(t):
        return np.array([t, 2.0 * t, -t])

    plan = problems.force_tracking(
        uvms, x0, contact, desired, np.eye(3), horizon_s=NODES * DT_S, dt_s=DT_S, time_s=T0_S
    )
    nodes = [*plan.problem.runningModels, plan.problem.terminalModel]
    for time_s in (T0_S, 1.7):
        plan.retarget(desired, time_s)
        for k, node in enumerate(nodes):
            force = node.differential.terms[0][0]
            np.testing.assert_allclose(force.target_N, desired(time_s + k * DT_S), atol=1e-12)


def test_station_keeping_cost_is_its_docstrings(reference_uvms):
    """station_hold's node cost: the vehicle's pose error (not its state deviation from x0),
    (1/2)||arm (-) arm_0||^2 + 0.1 (1/2)||v||^2, x10 at the end; a vehicle at the station,
    the arm off by d on one joint, at rest and without input costs (1/2) d^2 (x10)."""
    uvms = reference_uvms
    x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    x0[2] = -3.0
    station = pin.SE3(pin.exp3(np.array([0.0, 0.0, 0.4])), np.array([1.0, -0.5, -2.0]))
    problem = problems.station_hold(uvms, x0, station, horizon_s=NODES * DT_S, dt_s=DT_S)
    x = x0.copy()
    x[:3] = station.translation
    x[3:7] = pin.Quaternion(station.rotation).coeffs()
    d = 0.2
    x[7] += d
    velocity = np.zeros(uvms.nv)
    velocity[0] = 0.3
    for node, scale in ((problem.runningModels[0], 1.0), (problem.terminalModel, 10.0)):
        model = node.differential
        data = model.createData()
        model.calc(data, x, np.zeros(model.nu))
        assert data.cost == pytest.approx(scale * 0.5 * d**2, rel=1e-9, abs=1e-12)
        moving = np.r_[x[: uvms.nq], velocity]
        moving[7] -= d
        model.calc(data, moving, np.zeros(model.nu))
        assert data.cost == pytest.approx(scale * 0.1 * 0.5 * 0.3**2, rel=1e-9)


@pytest.mark.parametrize("iterations", [0, -3, True, 1.5, "10"])
def test_solve_refuses_a_count_of_iterations_that_is_no_whole_number_from_one(
    reference_uvms, iterations
):
    problem = _small_problem(reference_uvms)
    with pytest.raises(up.ParameterError, match="ocp iterations must be"):
        problems.solve(problem, iterations=iterations)


def test_solve_refuses_a_warm_start_that_is_not_finite(reference_uvms):
    """A NaN in the warm start's states or inputs is refused before the solver sees it; a
    finite one is taken (and one iteration is enough to run)."""
    problem = _small_problem(reference_uvms)
    xs = [np.array(problem.x0) for _ in range(problem.T + 1)]
    us = [np.zeros(m.nu) for m in problem.runningModels]
    problems.solve(problem, iterations=1, warm_start=(xs, us))
    for bad in ("xs", "us"):
        held = ([x.copy() for x in xs], [u.copy() for u in us])
        held[0 if bad == "xs" else 1][-1][0] = np.nan
        with pytest.raises(up.ParameterError, match="warm_start: its xs and us must be finite"):
            problems.solve(problem, iterations=1, warm_start=held)


def _small_problem(uvms):
    x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    x0[2] = -3.0
    effort = lambda nu: [(costs.Effort(np.ones(nu)), 1.0)]  # noqa: E731
    return problems.shooting_problem(uvms, x0, effort, effort, nodes=NODES, dt_s=DT_S)
