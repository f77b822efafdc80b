"""Shooting problems of a UVMS in water as crocoddyl's, and their solution by crocoddyl's
FDDP or mim_solvers' CSQP: the Python reference of the compiled planner.

A problem is a plan of `uvms_pin.ocp.plans` (its nodes, costs, inputs, water and contact)
made into crocoddyl's ShootingProblem (`problem_of`): every running node is the
`UnderwaterActionModel` integrated over dt_s by crocoddyl's Euler (``integrator="euler"``:
v+ = v + dt a, q+ = q (+) dt v+, the plant's semi-implicit Euler with a step of dt_s) or by
crocoddyl's fourth-order Runge-Kutta (``"rk4"``: four stages k_i = (v_i, a_i) at
x (+) c_i dt k_(i-1), x+ = x (+) dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4), and the cost integrated
alike; the plant's RK4 steps its chart with the chart rate instead, the same to third order),
the flow frozen at the node's time; the terminal node carries the terminal costs.
`point_to_point`, `station_hold` and `force_tracking` are the plans' tasks as problems;
`solve` runs box-constrained FDDP (the thrust and effort limits as bounds), plain FDDP or
CSQP (the limits as inequality constraints: `Actuators.as_constraints`) from a warm start or
the initial state held.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import plans
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module, mim_solvers_module
from uvms_pin.ocp.held_errors import HeldError, ctrl_c_deferred
from uvms_pin.ocp.model import UnderwaterActionModel
from uvms_pin.ocp.plans import (  # (the names the problems' users know them by)
    INTEGRATORS,
    SOLVERS,
    Actuators,
    ForceTracking,
    Horizon,
    Node,
    ShootingPlan,
    check_integrator,
    check_solver,
    check_start,
)

__all__ = [
    "CSQP_QP_ITERATIONS", "INTEGRATORS", "SOLVERS", "Actuators", "ForceTracking", "Horizon",
    "force_tracking", "integrated_node", "point_to_point", "problem_of", "shooting_problem",
    "solution", "solve", "solver_of", "station_hold",
]  # fmt: skip

crocoddyl = crocoddyl_module()

#: CSQP's ADMM iterations per QP (mim_solvers' default, 1000, left the station-keeping QP
#: with saturated thrusters unconverged at every SQP iteration; 200 solved it)
CSQP_QP_ITERATIONS = 200


def problem_of(plan: ShootingPlan):
    """crocoddyl's ShootingProblem of ``plan``: its nodes as `UnderwaterActionModel`s (a node
    shared by the running nodes one model, each node its own data), integrated by its
    integrator, the terminal one by Euler over 0 s; the same cost term objects as the plan's
    (a retarget reaches both)."""
    models: dict[int, UnderwaterActionModel] = {}

    def model_of(node: Node, constrained: bool) -> UnderwaterActionModel:
        if id(node) not in models:
            models[id(node)] = UnderwaterActionModel(
                plan.uvms,
                node.terms,
                input_matrix_=plan.input_matrix,
                flow=plan.flow,
                time_s=node.time_s,
                u_bounds=plan.bounds,
                backend=plan.backend,
                contact=plan.contact,
                bounds_as_constraints=constrained,
            )
        return models[id(node)]

    running = [
        integrated_node(model_of(node, plan.as_constraints), plan.dt_s, plan.integrator)
        for node in plan.running
    ]
    last = model_of(plan.terminal, False)
    return crocoddyl.ShootingProblem(
        np.asarray(plan.x0, float), running, crocoddyl.IntegratedActionModelEuler(last, 0.0)
    )


def shooting_problem(uvms: UVMS, x0: np.ndarray, running, terminal, **options):
    """crocoddyl's ShootingProblem of `uvms_pin.ocp.plans.plan` (the same arguments: x0 over
    ``nodes`` steps of ``dt_s`` [s], each node's dynamics with ``contact`` integrated by
    ``integrator``; ``per_node``: each running node its own terms)."""
    return problem_of(plans.plan(uvms, x0, running, terminal, **options))


def _as_problem(task: Callable[..., ShootingPlan]) -> Callable[..., object]:
    """The task of `uvms_pin.ocp.plans` ``task`` returning crocoddyl's problem of its plan."""

    @functools.wraps(task)
    def problem(*args, **kwargs):
        return problem_of(task(*args, **kwargs))

    problem.__doc__ = f"{task.__doc__}\n\n    Returns crocoddyl's ShootingProblem (`problem_of`)."
    return problem


point_to_point = _as_problem(plans.point_to_point)
station_hold = _as_problem(plans.station_hold)


def force_tracking(*args, **kwargs) -> ForceTracking:
    """`uvms_pin.ocp.plans.force_tracking`, its ``problem`` crocoddyl's ShootingProblem of
    its plan (the same contact-force terms: `ForceTracking.retarget` moves both)."""
    tracking = plans.force_tracking(*args, **kwargs)
    tracking.problem = problem_of(tracking.plan)
    return tracking


def integrated_node(model: UnderwaterActionModel, dt_s: float, integrator: str = "euler"):
    """``model`` integrated over ``dt_s`` [s]: crocoddyl's IntegratedActionModelEuler
    ("euler") or IntegratedActionModelRK with RKType.four ("rk4")."""
    if check_integrator(integrator) == "rk4":
        return crocoddyl.IntegratedActionModelRK(model, crocoddyl.RKType.four, dt_s)
    return crocoddyl.IntegratedActionModelEuler(model, dt_s)


def solver_of(problem, solver: str = "box_fddp"):
    """A solver of ``problem`` (`SOLVERS`): crocoddyl's SolverBoxFDDP (the input bounds
    enforced as a box), SolverFDDP (ignored) or mim_solvers' SolverCSQP (enforced as the
    nodes' inequality constraints: the problem built with ``Actuators(...,
    as_constraints=True)``; the mim-solvers package, the ``ocp`` extra)."""
    check_solver(solver)
    if solver == "box_fddp":
        return crocoddyl.SolverBoxFDDP(problem)
    if solver == "fddp":
        return crocoddyl.SolverFDDP(problem)
    unconstrained = [
        k for k, m in enumerate(problem.runningModels) if m.has_control_limits and m.ng == 0
    ]
    if unconstrained:
        raise ParameterError(
            f"csqp enforces the input bounds as constraints, but node(s) {unconstrained[:3]}"
            " have bounds and no constraints: build the problem with "
            "Actuators(..., as_constraints=True)"
        )
    csqp = mim_solvers_module().SolverCSQP(problem)
    csqp.max_qp_iters = CSQP_QP_ITERATIONS
    return csqp


def solution(solver) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """(xs, us) of ``solver``, copied. (mim_solvers' ``xs`` / ``us`` are containers returned
    by value whose items view the container's memory: ``solver.us[0]`` reads freed memory
    once the container is gone; crocoddyl's are the solver's own. Copy them here.)"""
    xs, us = solver.xs, solver.us  # held while their items are copied
    return [np.array(x, dtype=float) for x in xs], [np.array(u, dtype=float) for u in us]


def solve(
    problem,
    *,
    iterations: int = 100,
    warm_start=None,
    solver: str | object = "box_fddp",
    regularization: float | None = None,
):
    """Solve ``problem`` by ``solver``: a name of `SOLVERS` (a new solver, `solver_of`) or a
    solver kept between solves (e.g. a receding horizon's); warm start: (xs, us), else the
    initial state held with zero input; ``regularization``: the initial one (e.g. the last
    solve's ``preg``: a receding horizon keeps what the previous plans learnt of the
    problem's curvature), None: the solver's smallest. An exception a node raised during the
    solve is raised here once the solver has returned, and a Ctrl-C then too
    (`uvms_pin.ocp.held_errors`). Returns the solver (``xs``, ``us``,
    ``cost``, ``iter``, ``preg``; CSQP's ``xs`` may keep gaps to the dynamics, its
    ``gap_norm`` and ``constraint_norm`` the last iterate's; read xs and us by `solution`)."""
    if isinstance(iterations, bool) or not isinstance(iterations, int | np.integer):
        raise ParameterError(f"ocp iterations must be an integer >= 1, got {iterations!r}")
    if iterations < 1:
        raise ParameterError(f"ocp iterations must be >= 1, got {iterations}")
    solver = solver_of(problem, solver) if isinstance(solver, str) else solver
    check_start(problem.x0, problem.nx, "the problem's x0")
    if warm_start is None:
        xs = [problem.x0] * (problem.T + 1)
        us = [np.zeros(m.nu) for m in problem.runningModels]
    else:
        xs, us = warm_start
        if not np.all(np.isfinite(np.concatenate([*map(np.ravel, xs), *map(np.ravel, us)]))):
            raise ParameterError("ocp warm_start: its xs and us must be finite")
    initial = math.nan if regularization is None else float(regularization)
    holds = _held_errors(problem)
    for held in holds:
        held.take()  # (one left by a direct problem.calc: already warned about)
        held.in_solve = True
    try:
        with ctrl_c_deferred():
            solver.solve(list(xs), list(us), iterations, False, initial)
    finally:
        for held in holds:
            held.in_solve = False
    errors = [error for error in (held.take() for held in holds) if error is not None]
    if errors:  # a node's own exception (a user's cost term...), raised here as itself
        raise errors[0]
    return solver


def _held_errors(problem) -> list[HeldError]:
    """The `HeldError` of each of ``problem``'s differential models (once each; a model
    shared by the running nodes once), in the nodes' order."""
    holds: dict[int, HeldError] = {}
    for node in [*problem.runningModels, problem.terminalModel]:
        held = getattr(getattr(node, "differential", None), "held", None)
        if held is not None:
            holds.setdefault(id(held), held)
    return list(holds.values())
