"""mim_solvers' CSQP on the OCPs, the input bounds as constraints, beside crocoddyl's
BoxFDDP (the bounds as a box): the same problems solved to the same cost, the bounds held.

crocoddyl and mim-solvers are in the dev extra; without them these tests skip.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy

pytest.importorskip("crocoddyl")
from uvms_pin.ocp import problems
from uvms_pin.ocp.crocoddyl_module import mim_solvers_module

try:
    mim_solvers_module()
except ImportError:  # OptionalDependencyError is an ImportError too
    pytest.skip("mim-solvers is not installed", allow_module_level=True)


def _solve_both(build, bounds, iterations):
    """{solver: (solver, rolled-out states, inputs, cost of the rollout, planned states)}
    of the problem ``build(bounds, as_constraints)`` by BoxFDDP and by CSQP."""
    out = {}
    for name in ("box_fddp", "csqp"):
        problem = build(bounds, name == "csqp")
        solver = problems.solve(problem, iterations=iterations, solver=name)
        planned_xs, us = problems.solution(solver)
        xs = problem.rollout(us)
        cost = problem.calc(list(xs), us)
        out[name] = (solver, np.array(xs), np.array(us), cost, np.array(planned_xs))
    return out


def _active(us, lower, upper):
    return int(np.sum(np.isclose(us, lower, atol=1e-6) | np.isclose(us, upper, atol=1e-6)))


def test_csqp_moves_the_end_effector_within_tight_bounds_like_boxfddp(reference_uvms, ten_cm_move):
    """The 10 cm end-effector move (1 s, 50 nodes, tau as the input) with |tau| bounded to
    70 % of what the unbounded plan uses (0.2 at least): the bounds bind (59 node inputs at
    a bound, measured, for both solvers); CSQP holds them to 1e-6 (8e-9 measured), leaves no
    gap in its trajectory (its controls replayed give its states to 1e-8), reaches the target
    within 5 mm and the cost of BoxFDDP within 0.1 % (1.1e-4 lower, measured)."""
    uvms = reference_uvms
    x0, target = ten_cm_move.x0, ten_cm_move.target
    data = uvms.model.createData()

    def build(bounds, as_constraints):
        actuators = problems.Actuators(None, bounds, as_constraints=as_constraints)
        return problems.point_to_point(
            uvms, x0, target, horizon_s=1.0, dt_s=0.02, actuators=actuators
        )

    free = problems.solve(build(None, False), iterations=60, solver="fddp")
    limit = np.maximum(0.7 * np.abs(np.array(problems.solution(free)[1])).max(axis=0), 0.2)
    lower, upper = -limit, limit
    out = _solve_both(build, (lower, upper), iterations=100)
    box, csqp = out["box_fddp"], out["csqp"]
    assert csqp[0].constraint_norm < 1e-6
    np.testing.assert_allclose(csqp[1], csqp[4], atol=1e-8)
    for _, _, us, _, _ in out.values():
        assert np.all(us >= lower - 1e-6) and np.all(us <= upper + 1e-6)
        assert _active(us, lower, upper) > 20
    assert abs(csqp[3] - box[3]) < 1e-3 * box[3], (csqp[3], box[3])
    pin.framesForwardKinematics(uvms.model, data, csqp[1][-1][: uvms.nq])
    assert np.linalg.norm(data.oMf[uvms.ee_frame_id].translation - target.translation) < 5e-3


def test_csqp_keeps_station_with_saturated_thrusters_like_boxfddp(reference_uvms):
    """Station keeping in a 0.3 m/s current with the BlueROV2 Heavy's eight thrusters capped
    at 1.4 N (holding station wants ~1.6 N of some: they saturate, 192 node inputs at a
    bound for BoxFDDP, 308 for CSQP, measured): CSQP holds the caps to 1e-6 (1e-14
    measured), its trajectory is gap-free, its cost is not above BoxFDDP's (0.03333 against
    0.03398 measured: BoxFDDP stops earlier on the saturated plan) and within 5 % of it, and
    the vehicle's largest drift is the same to 1 mm (7.9 and 8.1 mm, measured)."""
    uvms = reference_uvms
    q0 = uvms.neutral_configuration()
    q0[2] = -3.0
    x0 = np.r_[q0, np.zeros(uvms.nv)]
    b_u = up.input_matrix(bluerov2_heavy.thrusters(), uvms.nv)
    effort = uvms.model.effortLimit[6:]
    lower, upper = np.r_[np.full(8, -1.4), -effort], np.r_[np.full(8, 1.4), effort]
    station = pin.SE3(np.eye(3), q0[:3].copy())

    def build(bounds, as_constraints):
        actuators = problems.Actuators(b_u, bounds, as_constraints=as_constraints)
        return problems.station_hold(
            uvms,
            x0,
            station,
            horizon_s=1.0,
            dt_s=0.02,
            actuators=actuators,
            flow=UniformCurrent([0.3, 0.0, 0.0]),
        )

    out = _solve_both(build, (lower, upper), iterations=100)
    box, csqp = out["box_fddp"], out["csqp"]
    assert csqp[0].constraint_norm < 1e-6
    np.testing.assert_allclose(csqp[1], csqp[4], atol=1e-8)
    drifts = []
    for _, xs, us, _, _ in out.values():
        assert np.all(us >= lower - 1e-6) and np.all(us <= upper + 1e-6)
        assert _active(us, lower, upper) > 100
        drifts.append(max(np.linalg.norm(x[:3] - q0[:3]) for x in xs))
    assert csqp[3] <= box[3] * (1.0 + 1e-6), (csqp[3], box[3])
    assert csqp[3] > 0.95 * box[3], (csqp[3], box[3])
    assert abs(drifts[0] - drifts[1]) < 1e-3, drifts


def test_csqp_needs_the_bounds_as_constraints(reference_uvms):
    """A problem whose bounds are only a box (no constraints) is refused by "csqp", naming
    the fix; an unknown solver's error lists the choices."""
    uvms = reference_uvms
    x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    bounds = (np.full(uvms.nv, -5.0), np.full(uvms.nv, 5.0))
    problem = problems.point_to_point(
        uvms, x0, pin.SE3.Identity(), actuators=problems.Actuators(None, bounds)
    )
    with pytest.raises(ParameterError, match="as_constraints=True"):
        problems.solver_of(problem, "csqp")
    with pytest.raises(ParameterError, match="box_fddp, fddp, csqp"):
        problems.solver_of(problem, "ipopt")


def test_solution_copies_what_the_solver_holds(reference_uvms):
    """`problems.solution` gives copies of xs and us that outlive the solver's containers and
    its next solve (mim_solvers' ``solver.us[0]`` alone would view freed memory)."""
    uvms = reference_uvms
    x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    x0[2] = -3.0
    station = pin.SE3(np.eye(3), x0[:3].copy())
    problem = problems.station_hold(
        uvms, x0, station, horizon_s=0.2, dt_s=0.02, flow=UniformCurrent([0.3, 0.0, 0.0])
    )
    solver = problems.solve(problem, iterations=5, solver="csqp")
    xs, us = problems.solution(solver)
    expected = np.array(solver.us)
    assert len(xs) == problem.T + 1 and len(us) == problem.T
    np.testing.assert_array_equal(np.array(us), expected)
    assert np.abs(expected).max() > 0.1  # the current is fought
    problem.x0 = x0 + np.r_[np.full(3, 0.05), np.zeros(uvms.nq + uvms.nv - 3)]
    problems.solve(problem, iterations=5, solver=solver)
    np.testing.assert_array_equal(np.array(us), expected)
    assert np.abs(np.array(solver.us) - expected).max() > 1e-3
