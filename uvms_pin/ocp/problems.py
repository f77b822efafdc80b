"""Shooting problems of a UVMS in water, and their solution by crocoddyl's FDDP or
mim_solvers' CSQP.

A problem has N nodes of dt_s each: every running node is the `UnderwaterActionModel`
integrated over dt_s by crocoddyl's Euler (``integrator="euler"``: v+ = v + dt a,
q+ = q (+) dt v+, the plant's semi-implicit Euler with a step of dt_s) or by crocoddyl's
fourth-order Runge-Kutta (``"rk4"``: four stages k_i = (v_i, a_i) at x (+) c_i dt k_(i-1),
x+ = x (+) dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4), and the cost integrated alike; the plant's
RK4 steps its chart with the chart rate instead, the same to third order), the flow frozen
at the node's time; the terminal node carries the terminal costs. `point_to_point` moves the
end-effector to a pose, `station_hold` keeps the vehicle at a pose (e.g. in a current),
`force_tracking` presses the end-effector on a compliant environment (the contact in every
node's dynamics) to track a desired force while holding its attitude; `solve` runs
box-constrained FDDP (the thrust and effort limits as bounds), plain FDDP or CSQP (the limits
as inequality constraints: `Actuators.as_constraints`) from a warm start or the initial
state held.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField, UniformCurrent
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import costs
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module, mim_solvers_module
from uvms_pin.ocp.held_errors import HeldError, ctrl_c_deferred
from uvms_pin.ocp.model import UnderwaterActionModel, WeightedTerms
from uvms_pin.physics.derivatives.task_contact import TaskContact

crocoddyl = crocoddyl_module()

CostBuilder = Callable[[int], WeightedTerms]
"""nu -> the (term, scale) pairs of one node's cost."""

#: the nodes' integrators (crocoddyl's IntegratedActionModelEuler, IntegratedActionModelRK)
INTEGRATORS = ("euler", "rk4")
#: the solvers: crocoddyl's SolverBoxFDDP (bounds as a box), SolverFDDP (no bounds),
#: mim_solvers' SolverCSQP (bounds as constraints)
SOLVERS = ("box_fddp", "fddp", "csqp")
#: CSQP's ADMM iterations per QP (mim_solvers' default, 1000, left the station-keeping QP
#: with saturated thrusters unconverged at every SQP iteration; 200 solved it)
CSQP_QP_ITERATIONS = 200


@dataclass(frozen=True)
class Actuators:
    """What u is: tau = input_matrix u, within bounds (lower, upper) (None: the identity,
    unbounded). `uvms_pin.physics.discrete.input_matrix` for thrusters and joint torques.
    ``as_constraints``: the bounds also as each running node's inequality constraints
    (what the "csqp" solver enforces; box FDDP reads them as a box either way)."""

    input_matrix: np.ndarray | None = None
    bounds: tuple[np.ndarray, np.ndarray] | None = None
    as_constraints: bool = False

    def nu(self, nv: int) -> int:
        return nv if self.input_matrix is None else int(np.shape(self.input_matrix)[1])


def shooting_problem(
    uvms: UVMS,
    x0: np.ndarray,
    running: CostBuilder,
    terminal: CostBuilder,
    *,
    nodes: int,
    dt_s: float,
    actuators: Actuators = Actuators(),
    flow: FlowField | None = None,
    time_s: float = 0.0,
    backend: str = "core",
    contact: TaskContact | None = None,
    per_node: bool = False,
    integrator: str = "euler",
):
    """A crocoddyl.ShootingProblem from x0 over ``nodes`` steps of ``dt_s`` [s], each node's
    dynamics with ``contact`` (None: none) integrated by ``integrator`` (`INTEGRATORS`).
    The running nodes share one model in a steady flow unless ``per_node`` (each its own
    terms: ``running`` is called once per node, in order, e.g. for a cost whose target moves
    along the horizon). The terminal node has no constraints (its u is not an input)."""
    if nodes < 1 or not (dt_s > 0.0 and np.isfinite(dt_s)):
        raise ParameterError(f"need nodes >= 1 and dt_s > 0, got {nodes}, {dt_s}")
    check_integrator(integrator)
    _check_start(x0, uvms.nq + uvms.nv, "x0")
    nu = actuators.nu(uvms.nv)

    def node(costs_of: CostBuilder, t: float, constrained: bool):
        return UnderwaterActionModel(
            uvms,
            costs_of(nu),
            input_matrix_=actuators.input_matrix,
            flow=flow,
            time_s=t,
            u_bounds=actuators.bounds,
            backend=backend,
            contact=contact,
            bounds_as_constraints=constrained,
        )

    # a steady flow: one model shared by the running nodes (each has its own data)
    steady = flow is None or isinstance(flow, UniformCurrent)
    constrained = actuators.as_constraints
    shared = node(running, time_s, constrained) if steady and not per_node else None
    models = [
        integrated_node(
            shared if shared is not None else node(running, time_s + k * dt_s, constrained),
            dt_s,
            integrator,
        )
        for k in range(nodes)
    ]
    last = node(terminal, time_s + nodes * dt_s, False)
    return crocoddyl.ShootingProblem(
        np.asarray(x0, float), models, crocoddyl.IntegratedActionModelEuler(last, 0.0)
    )


def integrated_node(model: UnderwaterActionModel, dt_s: float, integrator: str = "euler"):
    """``model`` integrated over ``dt_s`` [s]: crocoddyl's IntegratedActionModelEuler
    ("euler") or IntegratedActionModelRK with RKType.four ("rk4")."""
    if check_integrator(integrator) == "rk4":
        return crocoddyl.IntegratedActionModelRK(model, crocoddyl.RKType.four, dt_s)
    return crocoddyl.IntegratedActionModelEuler(model, dt_s)


def check_integrator(integrator: str) -> str:
    """``integrator`` if it is one of `INTEGRATORS`, else ParameterError naming them."""
    if integrator not in INTEGRATORS:
        raise ParameterError(
            f"ocp integrator must be one of {', '.join(INTEGRATORS)}, got '{integrator}'"
        )
    return integrator


def check_solver(solver: str) -> str:
    """``solver`` if it is one of `SOLVERS`, else ParameterError naming them."""
    if solver not in SOLVERS:
        raise ParameterError(f"ocp solver must be one of {', '.join(SOLVERS)}, got '{solver}'")
    return solver


def _nodes(horizon_s: float, dt_s: float) -> int:
    """round(horizon_s / dt_s), the nodes of a horizon; ParameterError unless both are
    positive finite times [s] and the horizon holds at least one node."""
    for name, value in (("dt_s", dt_s), ("horizon_s", horizon_s)):
        if not (value > 0.0 and math.isfinite(value)):
            raise ParameterError(f"ocp {name} must be a positive finite time [s], got {value}")
    nodes = round(horizon_s / dt_s)
    if nodes < 1:
        raise ParameterError(
            f"ocp horizon_s {horizon_s} s holds no node of dt_s {dt_s} s (at least one needed)"
        )
    return nodes


def _six_weights(name: str, weights) -> np.ndarray:
    """``weights``: one number or six, as a (6,) array; ParameterError naming ``name``."""
    values = np.asarray(weights, float).reshape(-1)
    if values.size not in (1, 6):
        raise ParameterError(f"ocp {name}: one number or six needed, got {values.size}")
    return np.broadcast_to(values, (6,)).copy()


def _scale(name: str, value: float) -> float:
    """A cost term's scale: finite and >= 0, else ParameterError naming it."""
    if not (value >= 0.0 and math.isfinite(value)):
        raise ParameterError(f"ocp {name} must be finite and >= 0, got {value}")
    return float(value)


@dataclass(frozen=True)
class Horizon:
    """The keywords every problem builder (`point_to_point`, `station_hold`,
    `force_tracking`) takes besides its task: a plan of ``horizon_s`` [s] in nodes of
    ``dt_s`` [s] (round(horizon_s / dt_s) of them), u as ``actuators`` says, in ``flow``
    (None: still water), the dynamics on ``backend`` ("core" or "python"), each node
    integrated by ``integrator`` (`INTEGRATORS`)."""

    horizon_s: float = 1.0
    dt_s: float = 0.02
    actuators: Actuators = Actuators()
    flow: FlowField | None = None
    backend: str = "core"
    integrator: str = "euler"

    @property
    def nodes(self) -> int:
        """round(horizon_s / dt_s); ParameterError unless both are positive finite times and
        the horizon holds a node."""
        return _nodes(self.horizon_s, self.dt_s)

    def problem(self, uvms: UVMS, x0: np.ndarray, running, terminal, **node_options):
        """`shooting_problem` from ``x0`` over this horizon (``node_options``: its
        ``time_s``, ``contact``, ``per_node``)."""
        return shooting_problem(
            uvms,
            x0,
            running,
            terminal,
            nodes=self.nodes,
            dt_s=self.dt_s,
            actuators=self.actuators,
            flow=self.flow,
            backend=self.backend,
            integrator=self.integrator,
            **node_options,
        )


def point_to_point(
    uvms: UVMS,
    x0: np.ndarray,
    target: pin.SE3,
    *,
    effort_weight: float = 1e-4,
    pose_weights=(1.0, 1.0, 1.0, 0.1, 0.1, 0.1),
    **horizon: Any,
):
    """Move the end-effector to ``target`` (its pose at the horizon's end, at rest); the
    running cost keeps velocities and effort small. ``pose_weights``: of the pose error
    (position [m], rotation [rad]), x1e3 at the end. ``horizon``: the `Horizon` keywords."""
    horizon = Horizon(**horizon)
    x0 = np.asarray(x0, float)
    pose_w = _six_weights("pose_weights", pose_weights)
    slow = np.r_[np.zeros(uvms.nv), np.ones(uvms.nv)]

    def running(nu: int):
        return [
            (costs.end_effector_pose(uvms, target, pose_w), 1.0),
            (costs.Effort(np.ones(nu)), effort_weight),
            (costs.StateDeviation(uvms.model, x0, slow), 1e-2),
        ]

    def terminal(nu: int):
        return [
            (costs.end_effector_pose(uvms, target, pose_w), 1e3),
            (costs.StateDeviation(uvms.model, x0, slow), 10.0),
        ]

    return horizon.problem(uvms, x0, running, terminal)


def station_hold(
    uvms: UVMS,
    x0: np.ndarray,
    station: pin.SE3,
    *,
    effort_weight: float = 1e-4,
    pose_weights=100.0,
    **horizon: Any,
):
    """Keep the vehicle's body frame at ``station`` and the arm as in x0, at rest.

    Per node: (1/2)||log6(T_station^-1 T_vehicle)||^2_W (W = diag(pose_weights) over x, y,
    z [m] and the rotation [rad], body axes) + (1/2)||arm (-) arm_0||^2 + 0.1 (1/2)||v||^2 +
    effort_weight (1/2)||u||^2 (N, N m); x10 at the end. The default trades 1 mm of error
    against 1 N of input; give a DoF the input cannot reach (e.g. the passively stable roll
    and pitch of a vehicle without thrust there) a small weight, or the plan fights it.
    ``horizon``: the `Horizon` keywords."""
    horizon = Horizon(**horizon)
    x0 = np.asarray(x0, float)
    pose_w = _six_weights("pose_weights", pose_weights)
    hold_arm = np.r_[np.zeros(6), np.ones(uvms.nv - 6), np.full(uvms.nv, 0.1)]

    def terms(scale: float):
        def build(nu: int):
            return [
                (costs.vehicle_pose(uvms, station, pose_w), scale),
                (costs.StateDeviation(uvms.model, x0, hold_arm), scale),
                (costs.Effort(np.ones(nu)), effort_weight),
            ]

        return build

    return horizon.problem(uvms, x0, terms(1.0), terms(10.0))


@dataclass
class ForceTracking:
    """A force-tracking shooting problem and its contact-force terms, one per node (running
    nodes, then the terminal one) at ``offsets_s`` from the plan's start: `retarget` moves
    the desired force along the horizon (a receding horizon re-plans from a later time)."""

    problem: object  # crocoddyl.ShootingProblem
    forces: list[costs.ContactForce]
    offsets_s: list[float]

    def retarget(self, desired_force: Callable[[float], np.ndarray], time_s: float) -> None:
        """Each node's f_d = desired_force(time_s + its offset) [N, world axes]."""
        for term, offset in zip(self.forces, self.offsets_s, strict=True):
            term.target_N = np.asarray(desired_force(time_s + offset), dtype=float)


def force_tracking(
    uvms: UVMS,
    x0: np.ndarray,
    contact: TaskContact,
    desired_force: Callable[[float], np.ndarray],
    rotation: np.ndarray,
    *,
    time_s: float = 0.0,
    force_weights=(100.0, 100.0, 100.0),
    attitude_weights=(100.0, 100.0, 100.0),
    posture_weight: float = 1.0,
    velocity_weight: float = 0.1,
    effort_weight: float = 1e-4,
    limit_margin_rad: float = 0.1,
    limit_weight: float = 1e3,
    **horizon: Any,
) -> ForceTracking:
    """Press on ``contact`` with the desired force f_d(t) [N] while holding the end-effector's
    attitude at ``rotation`` (world <- end-effector), the arm near its posture in x0.

    Per node at time t_k: (1/2)||f - f_d(t_k)||^2_Wf + (1/2)||log3(R_d^T R_ee)||^2_Wo +
    posture_weight (1/2)||arm (-) arm_0||^2 + velocity_weight (1/2)||v||^2 +
    effort_weight (1/2)||u||^2 + limit_weight (1/2)||arm past its limits less
    limit_margin_rad||^2; the terminal node the same without the effort. The vehicle's
    position is free (it moves to make the force); f the contact's force on the environment
    in every node's dynamics (`uvms_pin.physics.derivatives.task_contact`); ``time_s`` [s]:
    the plan's start. ``horizon``: the `Horizon` keywords."""
    horizon = Horizon(**horizon)
    x0 = np.asarray(x0, float)
    nodes = horizon.nodes
    effort_weight = _scale("effort_weight", effort_weight)
    hold = np.r_[
        np.zeros(6), np.full(uvms.nv - 6, posture_weight), np.full(uvms.nv, velocity_weight)
    ]
    offsets = [k * horizon.dt_s for k in range(nodes + 1)]
    forces = [
        costs.ContactForce(desired_force(time_s + offset), force_weights) for offset in offsets
    ]
    pending = iter(forces)

    def terms(effort: float):
        def build(nu: int):
            out = [
                (next(pending), 1.0),
                (costs.end_effector_attitude(uvms, rotation, attitude_weights), 1.0),
                (costs.StateDeviation(uvms.model, x0, hold), 1.0),
                (costs.JointLimitMargin(uvms.model, limit_margin_rad, limit_weight), 1.0),
            ]
            return out + ([(costs.Effort(np.ones(nu)), effort)] if effort > 0.0 else [])

        return build

    problem = horizon.problem(
        uvms, x0, terms(effort_weight), terms(0.0), time_s=time_s, contact=contact, per_node=True
    )
    return ForceTracking(problem, forces, offsets)


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


def _check_start(x0, nx: int, name: str) -> None:
    """x0 of nx finite values, else ParameterError (before crocoddyl runs: its nodes would
    compute with NaN)."""
    x0 = np.asarray(x0, float)
    if x0.shape != (nx,) or not np.all(np.isfinite(x0)):
        raise ParameterError(f"ocp {name} must be {nx} finite values (q, v), got {x0}")


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
    _check_start(problem.x0, problem.nx, "the problem's x0")
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
