"""Shooting problems of a UVMS in water as data: their nodes, costs, inputs, water and contact.

A plan has N running nodes of dt_s each and a terminal node. A node is its cost, a list of
(term, scale) pairs of `uvms_pin.ocp.costs` (l = sum_i scale_i (1/2) r_i^T W_i r_i), and the
time its flow is frozen at; every node's dynamics are the UVMS's in the plan's flow, with its
contact, its input u as its `Actuators` say (tau = B_u u within bounds). Running nodes are
integrated over dt_s by Euler or RK4 (``integrator``, `uvms_pin.ocp.problems`), the terminal
node over 0 s.

Nothing here needs crocoddyl: a plan is what the core's compiled planner is built from
(`uvms_pin.ocp.compiled.planner_of`) and what `uvms_pin.ocp.problems` turns into crocoddyl's
ShootingProblem (the Python reference, `uvms_pin.ocp.model`). `point_to_point` moves the
end-effector to a pose, `station_hold` keeps the vehicle at a pose (e.g. in a current),
`force_tracking` presses the end-effector on a compliant environment (the contact in every
node's dynamics) to track a desired force while holding its attitude; each is checked here,
before any solver runs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import nonnegative, number
from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField, UniformCurrent
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import costs
from uvms_pin.physics.derivatives.task_contact import TaskContact

WeightedTerms = Sequence[tuple[costs.CostTerm, float]]
"""The cost of a node: (term, scale) pairs, l = sum_i scale_i (1/2) r_i^T W_i r_i."""

CostBuilder = Callable[[int], WeightedTerms]
"""nu -> the (term, scale) pairs of one node's cost."""

#: the nodes' integrators (crocoddyl's IntegratedActionModelEuler, IntegratedActionModelRK)
INTEGRATORS = ("euler", "rk4")
#: the solvers: crocoddyl's SolverBoxFDDP (bounds as a box), SolverFDDP (no bounds),
#: mim_solvers' SolverCSQP (bounds as constraints)
SOLVERS = ("box_fddp", "fddp", "csqp")


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


@dataclass
class Node:
    """One node: its cost's (term, scale) pairs and the time its flow is frozen at [s]."""

    terms: list[tuple[costs.CostTerm, float]]
    time_s: float


@dataclass
class ShootingPlan:
    """A shooting problem as data (`plan`): ``running`` nodes of ``dt_s`` [s] integrated by
    ``integrator``, then ``terminal``, from ``x0`` = (q, v). In a steady flow the running
    nodes are one `Node` object repeated (one model shared, as crocoddyl's problem shares
    it). ``input_matrix`` (nv, nu) and ``bounds`` ((nu,), (nu,)) or None are the actuators'
    once checked; ``as_constraints``: the bounds also as the running nodes' inequalities."""

    uvms: UVMS
    x0: np.ndarray
    running: list[Node]
    terminal: Node
    dt_s: float
    integrator: str
    input_matrix: np.ndarray
    bounds: tuple[np.ndarray, np.ndarray] | None
    as_constraints: bool
    flow: FlowField | None
    backend: str
    contact: TaskContact | None

    @property
    def nodes(self) -> int:
        """N, the running nodes."""
        return len(self.running)

    @property
    def nu(self) -> int:
        """The inputs of a node."""
        return int(self.input_matrix.shape[1])


def plan(
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
) -> ShootingPlan:
    """The plan from x0 over ``nodes`` steps of ``dt_s`` [s], each node's dynamics with
    ``contact`` (None: none) integrated by ``integrator`` (`INTEGRATORS`), node k's flow at
    time_s + k dt_s. The running nodes share one node in a steady flow unless ``per_node``
    (each its own terms: ``running`` is called once per node, in order, e.g. for a cost
    whose target moves along the horizon). The terminal node has no constraints (its u is
    not an input).

    Raises:
        ParameterError: no node, a bad dt_s, integrator, x0, input matrix or bounds, a cost
            scale not finite and >= 0, an effort term not over the nu inputs, or a term
            that needs a contact without one.
    """
    if nodes < 1 or not (dt_s > 0.0 and np.isfinite(dt_s)):
        raise ParameterError(f"need nodes >= 1 and dt_s > 0, got {nodes}, {dt_s}")
    check_integrator(integrator)
    check_start(x0, uvms.nq + uvms.nv, "x0")
    b_u = checked_input_matrix(uvms, actuators.input_matrix)
    nu = b_u.shape[1]
    bounds = None if actuators.bounds is None else checked_bounds(actuators.bounds, nu)

    def node(costs_of: CostBuilder, t: float) -> Node:
        terms = list(costs_of(nu))
        check_terms(terms, nu, contact is not None)
        return Node(terms, float(t))

    # a steady flow: one node shared by the running nodes (crocoddyl: one model, each node
    # its own data)
    steady = flow is None or isinstance(flow, UniformCurrent)
    if steady and not per_node:
        running_nodes = [node(running, time_s)] * nodes
    else:
        running_nodes = [node(running, time_s + k * dt_s) for k in range(nodes)]
    return ShootingPlan(
        uvms, np.asarray(x0, float), running_nodes, node(terminal, time_s + nodes * dt_s),
        float(dt_s), integrator, b_u, bounds, actuators.as_constraints and bounds is not None,
        flow, backend, contact,
    )  # fmt: skip


def checked_input_matrix(uvms: UVMS, input_matrix: np.ndarray | None) -> np.ndarray:
    """B_u (nv, nu) as a float array (None: the identity), else ParameterError."""
    b_u = np.eye(uvms.nv) if input_matrix is None else np.asarray(input_matrix, float)
    if b_u.ndim != 2 or b_u.shape[0] != uvms.nv:
        raise ParameterError(f"input_matrix_ must be (nv={uvms.nv}, nu), got {b_u.shape}")
    return b_u


def checked_bounds(bounds, nu: int) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) as two (nu,) float arrays with lower <= upper (not NaN), else
    ParameterError."""
    lower, upper = (np.asarray(b, float).reshape(-1) for b in bounds)
    if lower.shape != (nu,) or upper.shape != (nu,) or not np.all(lower <= upper):
        raise ParameterError(
            f"u_bounds: two (nu={nu},) arrays, lower <= upper (not NaN), got {lower}, {upper}"
        )
    return lower, upper


def check_terms(terms: WeightedTerms, nu: int, has_contact: bool) -> None:
    """Each term's scale finite and >= 0 (a negative one makes the cost unbounded below, a
    NaN one every cost NaN), an effort term over the nu inputs, a term of the contact
    (``needs_contact``) only in a node with one; else ParameterError."""
    for term, scale in terms:
        nonnegative(f"cost '{term.name}': its scale", scale)
        if isinstance(term, costs.Effort) and term.nr != nu:
            raise ParameterError(
                f"cost '{term.name}': {term.nr} weights for the node's {nu} inputs (nu)"
            )
    needing = [term.name for term, _ in terms if term.needs_contact]
    if needing and not has_contact:
        raise ParameterError(f"cost(s) {needing} need a contact in the node's dynamics")


def check_start(x0, nx: int, name: str) -> None:
    """x0 of nx finite values, else ParameterError (before a solver runs: its nodes would
    compute with NaN)."""
    x0 = np.asarray(x0, float)
    if x0.shape != (nx,) or not np.all(np.isfinite(x0)):
        raise ParameterError(f"ocp {name} must be {nx} finite values (q, v), got {x0}")


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
        if not (number(f"ocp {name}", value) > 0.0 and math.isfinite(value)):
            raise ParameterError(f"ocp {name} must be a positive finite time [s], got {value}")
    nodes = round(horizon_s / dt_s)
    if nodes < 1:
        raise ParameterError(
            f"ocp horizon_s {horizon_s} s holds no node of dt_s {dt_s} s (at least one needed)"
        )
    return nodes


def _six_weights(name: str, weights) -> np.ndarray:
    """``weights``: one number or six, as a (6,) array; ParameterError naming ``name``."""
    try:
        values = np.asarray(weights, float).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(f"ocp {name}: one number or six needed, got {weights!r}") from None
    if values.size not in (1, 6):
        raise ParameterError(f"ocp {name}: one number or six needed, got {values.size}")
    return np.broadcast_to(values, (6,)).copy()


def _scale(name: str, value: float) -> float:
    """A cost term's scale: finite and >= 0, else ParameterError naming it."""
    return nonnegative(f"ocp {name}", value)


@dataclass(frozen=True)
class Horizon:
    """The keywords every task (`point_to_point`, `station_hold`, `force_tracking`) takes
    besides its own: a plan of ``horizon_s`` [s] in nodes of ``dt_s`` [s]
    (round(horizon_s / dt_s) of them), u as ``actuators`` says, in ``flow`` (None: still
    water), the dynamics on ``backend`` ("core" or "python"), each node integrated by
    ``integrator`` (`INTEGRATORS`)."""

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

    def plan(self, uvms: UVMS, x0: np.ndarray, running, terminal, **node_options):
        """`plan` from ``x0`` over this horizon (``node_options``: its ``time_s``,
        ``contact``, ``per_node``)."""
        return plan(
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
    **horizon,
) -> ShootingPlan:
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

    return horizon.plan(uvms, x0, running, terminal)


def station_hold(
    uvms: UVMS,
    x0: np.ndarray,
    station: pin.SE3,
    *,
    effort_weight: float = 1e-4,
    pose_weights=100.0,
    **horizon,
) -> ShootingPlan:
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

    return horizon.plan(uvms, x0, terms(1.0), terms(10.0))


@dataclass
class ForceTracking:
    """A force-tracking plan and its contact-force terms, one per node (running nodes, then
    the terminal one) at ``offsets_s`` from the plan's start: `retarget` moves the desired
    force along the horizon (a receding horizon re-plans from a later time). ``problem``:
    crocoddyl's ShootingProblem of the plan when `uvms_pin.ocp.problems.force_tracking`
    built it (it shares the terms), else None."""

    plan: ShootingPlan
    forces: list[costs.ContactForce]
    offsets_s: list[float]
    problem: object = None

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
    **horizon,
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

    made = horizon.plan(
        uvms, x0, terms(effort_weight), terms(0.0), time_s=time_s, contact=contact, per_node=True
    )
    return ForceTracking(made, forces, offsets)
