"""The compiled OCP (`uvms_pin.ocp.compiled`, src/uvms_core/ocp_*.cpp) against the
Python reference (`uvms_pin.ocp.model`): every node's calc and calcDiff, the solves, and an
MPC run; and against central differences of its own dynamics and cost.

crocoddyl (the Python reference's) is in the dev extra; without it these tests skip.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.flow import AiryWave, UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy
from uvms_pin.physics.contact import CompliantPlane, LinearSpring

pytest.importorskip("crocoddyl")

from uvms_pin.control.measurement import Measurement
from uvms_pin.control.mpc import MpcController, MpcForceTask
from uvms_pin.ocp import costs, plans, problems
from uvms_pin.ocp.compiled import place_contact, planner_of
from uvms_pin.ocp.state import UvmsState
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.derivatives.task_contact import TaskContact

OUTPUTS = ("xout", "Fx", "Fu", "Lx", "Lu", "Lxx", "Luu", "Lxu")


def _start(uvms) -> np.ndarray:
    q = uvms.neutral_configuration()
    q[2] = -3.0
    return np.r_[q, np.zeros(uvms.nv)]


def _state(uvms, rng) -> np.ndarray:
    q = uvms.neutral_configuration()
    q[:3] = np.array([0.1, -0.2, -3.0]) + rng.normal(scale=0.05, size=3)
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(scale=0.3, size=3))).coeffs()
    tangent = np.zeros(uvms.nv)
    tangent[6:] = rng.uniform(-0.6, 0.6, size=uvms.nv - 6)
    q = pin.integrate(uvms.model, q, tangent)
    return np.r_[q, rng.normal(scale=0.3, size=uvms.nv)]


def _thrusters(uvms, bounded: bool = True) -> problems.Actuators:
    thrusters = bluerov2_heavy.thrusters()
    effort = uvms.model.effortLimit[6:]
    lower = np.r_[[-t.max_reverse_N for t in thrusters], -effort]
    upper = np.r_[[t.max_forward_N for t in thrusters], effort]
    bounds = (lower, upper) if bounded else None
    return problems.Actuators(up.input_matrix(thrusters, uvms.nv), bounds)


def _every_term(uvms, x_ref, contact: bool):
    """A node cost of every term kind of uvms_pin.ocp.costs (the contact force with one)."""
    target = pin.SE3(pin.exp3(np.array([0.1, -0.2, 0.3])), np.array([0.5, 0.1, -2.5]))

    def build(nu: int):
        terms = [
            (costs.end_effector_pose(uvms, target, np.linspace(0.5, 2.0, 6)), 1.0),
            (costs.FramePosition(uvms.ee_frame_id, [0.3, 0.0, -3.0], np.ones(3)), 0.3),
            (costs.vehicle_attitude(uvms, pin.exp3(np.array([0.0, 0.1, 0.2])), np.ones(3)), 0.5),
            (costs.StateDeviation(uvms.model, x_ref, np.linspace(0.1, 1.0, 2 * uvms.nv)), 1.0),
            (costs.JointLimitMargin(uvms.model, 0.3, 50.0), 1.0),
            (costs.Effort(np.linspace(1.0, 2.0, nu)), 1e-3),
        ]
        if contact:
            terms.append((costs.ContactForce([0.5, -0.2, 1.0], [30.0, 10.0, 20.0]), 1.0))
        return terms

    return build


def _plan(uvms, *, flow=None, contact=None, integrator="euler", nodes=6, bounded=True):
    x0 = _start(uvms)
    terms = _every_term(uvms, x0, contact is not None)
    return plans.plan(
        uvms,
        x0,
        terms,
        terms,
        nodes=nodes,
        dt_s=0.05,
        actuators=_thrusters(uvms, bounded),
        flow=flow,
        time_s=0.4,
        contact=contact,
        integrator=integrator,
    )


def _nodes(problem):
    running = [node.differential for node in problem.runningModels]
    return [*running, problem.terminalModel.differential]


def _assert_nodes_agree(problem, planner, uvms, rng, states: int = 3) -> None:
    """Each node's compiled calc and calcDiff equal the Python node's to 1e-10 (relative to
    each output's size) at random states and inputs."""
    for k, node in enumerate(_nodes(problem)):
        if k not in (0, 3, len(_nodes(problem)) - 1):
            continue
        data = node.createData()
        for _ in range(states):
            x, u = _state(uvms, rng), rng.normal(scale=4.0, size=node.nu)
            node.calc(data, x, u)
            node.calcDiff(data, x, u)
            got = planner.evaluate(k, x, u)
            assert got["cost"] == pytest.approx(data.cost, rel=1e-12)
            np.testing.assert_allclose(got["r"], data.residual, rtol=0, atol=1e-12)
            for name in OUTPUTS:
                expected = np.asarray(getattr(data, name))
                scale = max(1.0, np.abs(expected).max())
                assert np.abs(got[name] - expected).max() <= 1e-10 * scale, (k, name)


@pytest.mark.parametrize(
    "flow",
    [None, UniformCurrent([0.3, -0.1, 0.05]), AiryWave(0.3, 5.0, water_depth_m=20.0)],
    ids=["still", "current", "wave"],
)
def test_every_node_is_the_python_node_in_any_water(reference_uvms, flow):
    """All seven cost kinds, thrusters and joint torques within bounds, in still water, a
    current and a wave (each node at its own time): calc and calcDiff equal the reference's."""
    plan = _plan(reference_uvms, flow=flow)
    planner = planner_of(plan, "box_fddp")
    assert not isinstance(planner, Fallback), planner
    _assert_nodes_agree(
        problems.problem_of(plan), planner, reference_uvms, np.random.default_rng(1)
    )


@pytest.mark.parametrize(
    "environment",
    [
        LinearSpring([40.0, 20.0, 60.0]),
        CompliantPlane([0.0, 0.3, 1.0], stiffness_N_m=300.0, damping_N_s_m=20.0),
    ],
    ids=["spring", "plane"],
)
def test_the_contact_in_the_dynamics_and_its_force_cost_are_the_references(
    reference_uvms, environment
):
    """The end-effector's spring or plane in every node's dynamics (the plane pushing at some
    states, not at others) and the contact-force cost: the compiled nodes equal the Python
    ones, the environment placed after the planner was built (as the MPC places it)."""
    contact = TaskContact(reference_uvms.ee_frame_id, environment)
    plan = _plan(reference_uvms, contact=contact, flow=UniformCurrent([0.2, 0.0, 0.0]))
    planner = planner_of(plan, "box_fddp")
    data = reference_uvms.model.createData()
    pin.framesForwardKinematics(
        reference_uvms.model, data, _start(reference_uvms)[: reference_uvms.nq]
    )
    environment.attach(
        data.oMf[reference_uvms.ee_frame_id].translation + np.array([0.02, 0.0, 0.05])
    )
    place_contact(planner, environment)
    rng = np.random.default_rng(2)
    _assert_nodes_agree(problems.problem_of(plan), planner, reference_uvms, rng, states=6)


def test_a_continuous_joint_model_on_rk4_nodes(tmp_path):
    """A model whose arm joints are continuous (nq != nv: the state's atan2 difference and
    the cost of its configuration) on RK4 nodes: the nodes agree and so do the solves."""
    from conftest import continuous_joint_urdf

    uvms = up.load_uvms(continuous_joint_urdf(tmp_path))
    plan = _plan(uvms, integrator="rk4", flow=UniformCurrent([0.1, 0.1, 0.0]))
    planner = planner_of(plan, "box_fddp")
    _assert_nodes_agree(problems.problem_of(plan), planner, uvms, np.random.default_rng(3))
    _assert_solves_agree(problems.problem_of(plan), planner, "box_fddp")


def _assert_solves_agree(problem, planner, solver: str, iterations: int = 8) -> None:
    """A cold solve of ``iterations`` from the held start: the same iterations, cost,
    regularization and plan as crocoddyl solving the Python problem."""
    reference = problems.solve(problem, iterations=iterations, solver=solver)
    x0 = problem.x0
    nodes = planner.nodes
    result = planner.solve(
        [x0] * (nodes + 1),
        [np.zeros(planner.nu)] * nodes,
        iterations,
        math.nan,
        planner.default_step_lengths,
    )
    assert result.iterations == reference.iter
    assert result.cost == pytest.approx(reference.cost, rel=1e-8)
    assert result.regularization == pytest.approx(reference.preg, rel=1e-8)
    xs, us = problems.solution(reference)
    for got, expected in zip(planner.us, us, strict=True):
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * max(1.0, np.abs(us).max()))
    for got, expected in zip(planner.xs, xs, strict=True):
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize("solver", ["box_fddp", "fddp"])
def test_the_solves_are_crocoddyls_on_the_python_problem(reference_uvms, solver):
    """BoxFDDP (the thrust and effort bounds a box) and FDDP: the compiled solve is the
    Python problem's, iteration for iteration."""
    plan = _plan(reference_uvms, flow=UniformCurrent([0.3, 0.0, 0.0]), nodes=10)
    planner = planner_of(plan, solver)
    _assert_solves_agree(problems.problem_of(plan), planner, solver)


def test_the_compiled_dynamics_and_cost_match_central_differences(reference_uvms):
    """Fx, Fu and Lx, Lu of a node with the plane's contact against central differences of
    its own xout and cost along the state's tangent (step 1e-6): the compiled derivatives
    are those of what it computes, not only equal to the reference's."""
    environment = CompliantPlane([0.0, 0.0, 1.0], stiffness_N_m=200.0, damping_N_s_m=15.0)
    contact = TaskContact(reference_uvms.ee_frame_id, environment)
    plan = _plan(reference_uvms, contact=contact, flow=UniformCurrent([0.2, 0.0, 0.1]))
    planner = planner_of(plan, "box_fddp")
    rng = np.random.default_rng(4)
    state = UvmsState(reference_uvms.model)
    x, u = _state(reference_uvms, rng), rng.normal(scale=3.0, size=planner.nu)
    data = reference_uvms.model.createData()
    pin.framesForwardKinematics(reference_uvms.model, data, x[: reference_uvms.nq])
    environment.attach(
        data.oMf[reference_uvms.ee_frame_id].translation + np.array([0.0, 0.0, 0.03])
    )
    place_contact(planner, environment)
    at = planner.evaluate(2, x, u)
    assert np.abs(at["xout"]).max() > 0 and at["Fx"].any()
    step, ndx = 1e-6, 2 * reference_uvms.nv
    fx, lx = np.empty((reference_uvms.nv, ndx)), np.empty(ndx)
    for i in range(ndx):
        e = np.zeros(ndx)
        e[i] = step
        plus = planner.evaluate(2, state.integrate(x, e), u)
        minus = planner.evaluate(2, state.integrate(x, -e), u)
        fx[:, i] = (plus["xout"] - minus["xout"]) / (2 * step)
        lx[i] = (plus["cost"] - minus["cost"]) / (2 * step)
    fu, lu = np.empty((reference_uvms.nv, planner.nu)), np.empty(planner.nu)
    for i in range(planner.nu):
        e = np.zeros(planner.nu)
        e[i] = step
        plus, minus = planner.evaluate(2, x, u + e), planner.evaluate(2, x, u - e)
        fu[:, i] = (plus["xout"] - minus["xout"]) / (2 * step)
        lu[i] = (plus["cost"] - minus["cost"]) / (2 * step)
    for got, expected in ((at["Fx"], fx), (at["Fu"], fu), (at["Lx"], lx), (at["Lu"], lu)):
        assert np.abs(got - expected).max() <= 1e-6 * max(1.0, np.abs(expected).max())


def test_a_node_that_fails_is_raised_after_the_solve(reference_uvms):
    """A warm start whose velocities overflow the quadratic damping (finite in, infinite
    acceleration out): the node's failure cannot cross crocoddyl's loop, it is held and
    raised as SimulationError once the solve returns, naming the node's calc; bad warm
    starts and settings are ParameterError before anything runs."""
    plan = _plan(reference_uvms, nodes=4)
    planner = planner_of(plan, "box_fddp")
    x0 = plan.x0.copy()
    wild = x0.copy()
    wild[reference_uvms.nq :] = 1e160
    us = [np.zeros(planner.nu)] * 4
    with pytest.raises(SimulationError, match="ocp node calc"):
        planner.solve([x0, wild, wild, wild, wild], us, 2, math.nan, [1.0])
    # the planner solves again afterwards (nothing held over)
    planner.solve([x0] * 5, us, 2, math.nan, [1.0])
    bad = x0.copy()
    bad[0] = np.nan
    with pytest.raises(ParameterError, match="warm start state"):
        planner.solve([bad] * 5, us, 2, math.nan, [1.0])
    with pytest.raises(ParameterError, match="N \\+ 1 states"):
        planner.solve([x0] * 4, us, 2, math.nan, [1.0])
    with pytest.raises(ParameterError, match="node 9 outside"):
        planner.set_force_target(9, np.zeros(3))
    with pytest.raises(ParameterError, match="no contact"):
        planner.set_contact(core_module().NoContact())


def test_what_the_core_has_no_counterpart_of_is_named(reference_uvms):
    """CSQP, a cost term of the user's own class, the python backend: a Fallback naming it
    (the MPC then solves the Python problem and says why in `planner_path`)."""
    assert "csqp" in planner_of(_plan(reference_uvms), "csqp").reason

    class Mine(costs.Effort):
        pass

    x0 = _start(reference_uvms)
    mine = plans.plan(
        reference_uvms,
        x0,
        lambda nu: [(Mine(np.ones(nu)), 1.0)],
        lambda nu: [],
        nodes=3,
        dt_s=0.05,
        actuators=_thrusters(reference_uvms),
    )
    assert "Mine" in planner_of(mine, "box_fddp").reason
    python = plans.plan(
        reference_uvms,
        x0,
        lambda nu: [(costs.Effort(np.ones(nu)), 1.0)],
        lambda nu: [],
        nodes=3,
        dt_s=0.05,
        actuators=_thrusters(reference_uvms),
        backend="python",
    )
    assert "python backend" in planner_of(python, "box_fddp").reason


@pytest.mark.parametrize("task", ["station", "force"])
def test_the_mpc_plans_the_same_compiled_or_in_python(reference_uvms, task):
    """Twelve re-plans of a closed loop from the same measurements (a moving vehicle):
    the compiled planner's inputs are the Python planner's to 1e-6 N (the force task with
    its spring placed at the first plan and the desired force previewed)."""
    q0 = _start(reference_uvms)[: reference_uvms.nq]
    kw = {}
    if task == "force":
        kw["force_task"] = MpcForceTask(
            LinearSpring([30.0, 30.0, 30.0]),
            lambda t: np.array([0.5 + 0.2 * np.sin(t), 0.0, 0.3]),
        )
    controllers = [
        MpcController(
            reference_uvms,
            task=task,
            target=None if task == "force" else pin.SE3(np.eye(3), q0[:3].copy()),
            posture=q0,
            horizon_s=0.5,
            dt_s=0.05,
            rate_hz=20.0,
            iterations=2,
            actuators=_thrusters(reference_uvms),
            flow=UniformCurrent([0.2, 0.0, 0.0]),
            planner=planner,
            **kw,
        )
        for planner in ("core", "python")
    ]
    assert [c.planner_path == "compiled" for c in controllers] == [True, False]
    rng = np.random.default_rng(5)
    q, v = q0.copy(), np.zeros(reference_uvms.nv)
    for k in range(12):
        t = 0.05 * k
        wrench = np.r_[rng.normal(scale=0.2, size=3), np.zeros(3)]
        taus = [c.compute(t, Measurement(t, q, v, wrench)) for c in controllers]
        np.testing.assert_allclose(taus[0], taus[1], rtol=0, atol=1e-6)
        v = v + rng.normal(scale=0.02, size=v.size)
        q = pin.integrate(reference_uvms.model, q, 0.05 * v)


_WITHOUT_CROCODDYL = """
import json, sys
import uvms_pin as up
from uvms_pin.scenario.load import load_scenario

finals = []
for _ in range(2):  # a fresh controller, planner and run each time
    scenario = load_scenario({path!r}, {{"scenario.duration_s": 0.3}})
    rollout = up.simulate(scenario, progress=False)
    finals.append([*rollout.q[-1], *rollout.v[-1]])
print(json.dumps({{"crocoddyl": "crocoddyl" in sys.modules, "finals": finals,
                  "loop": rollout.metadata["closed_loop"]["path"]}}))
"""


def test_the_mpc_plans_without_crocoddyls_package_on_one_thread(tmp_path):
    """An MPC scenario in a process that never imports crocoddyl's Python package (what a
    base install without the ``ocp`` extra has): its compiled re-plans are the Python
    planner's, and a second run gives the same numbers bit for bit. (The wheel's
    libcrocoddyl runs a problem's nodes on several OpenMP threads unless crocoddyl's Python
    bindings turned that off; the compiled nodes share one workspace: the planner sets one
    thread. Without it, runs here differed, or stopped on a mass matrix not positive
    definite.)"""
    path = str(Path(__file__).resolve().parents[2] / "scenarios" / "mpc_station_keeping.toml")
    script = tmp_path / "mpc.py"
    script.write_text(_WITHOUT_CROCODDYL.format(path=path))
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["crocoddyl"] is False and out["loop"] == "compiled"
    first, second = (np.array(final) for final in out["finals"])
    np.testing.assert_array_equal(first, second)
    reference = up.simulate(
        up.load_scenario(path, {"scenario.duration_s": 0.3, "controller.planner": "python"}),
        progress=False,
    )
    np.testing.assert_allclose(first, np.r_[reference.q[-1], reference.v[-1]], rtol=0, atol=1e-9)
