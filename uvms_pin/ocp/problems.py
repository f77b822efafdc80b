"""Shooting problems of a UVMS in water, and their solution by crocoddyl's FDDP.

A problem has N nodes of dt_s each: every running node is the `UnderwaterActionModel`
integrated by crocoddyl's Euler (v+ = v + dt a, q+ = q (+) dt v+: the plant's semi-implicit
Euler with a step of dt_s), the flow frozen at the node's time; the terminal node carries the
terminal costs. `point_to_point` moves the end-effector to a pose, `station_hold` keeps the
vehicle at a pose (e.g. in a current); `solve` runs box-constrained FDDP (the thrust and
effort limits as bounds) from a warm start or the initial state held.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField, UniformCurrent
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import costs
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module
from uvms_pin.ocp.model import UnderwaterActionModel, WeightedTerms

crocoddyl = crocoddyl_module()

CostBuilder = Callable[[int], WeightedTerms]
"""nu -> the (term, scale) pairs of one node's cost."""


@dataclass(frozen=True)
class Actuators:
    """What u is: tau = input_matrix u, within bounds (lower, upper) (None: the identity,
    unbounded). `uvms_pin.physics.discrete.input_matrix` for thrusters and joint torques."""

    input_matrix: np.ndarray | None = None
    bounds: tuple[np.ndarray, np.ndarray] | None = None

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
):
    """A crocoddyl.ShootingProblem from x0 over ``nodes`` steps of ``dt_s`` [s]."""
    if nodes < 1 or not (dt_s > 0.0 and np.isfinite(dt_s)):
        raise ParameterError(f"need nodes >= 1 and dt_s > 0, got {nodes}, {dt_s}")
    nu = actuators.nu(uvms.nv)

    def node(costs_of: CostBuilder, t: float):
        return UnderwaterActionModel(
            uvms,
            costs_of(nu),
            input_matrix_=actuators.input_matrix,
            flow=flow,
            time_s=t,
            u_bounds=actuators.bounds,
            backend=backend,
        )

    # a steady flow: one model shared by the running nodes (each has its own data)
    shared = node(running, time_s) if flow is None or isinstance(flow, UniformCurrent) else None
    models = [
        crocoddyl.IntegratedActionModelEuler(
            shared if shared is not None else node(running, time_s + k * dt_s), dt_s
        )
        for k in range(nodes)
    ]
    last = crocoddyl.IntegratedActionModelEuler(node(terminal, time_s + nodes * dt_s), 0.0)
    return crocoddyl.ShootingProblem(np.asarray(x0, float), models, last)


def _nodes(horizon_s: float, dt_s: float) -> int:
    return max(1, round(horizon_s / dt_s))


def point_to_point(
    uvms: UVMS,
    x0: np.ndarray,
    target: pin.SE3,
    *,
    horizon_s: float = 1.0,
    dt_s: float = 0.02,
    actuators: Actuators = Actuators(),
    flow: FlowField | None = None,
    effort_weight: float = 1e-4,
    pose_weights=(1.0, 1.0, 1.0, 0.1, 0.1, 0.1),
    backend: str = "core",
):
    """Move the end-effector to ``target`` (its pose at the horizon's end, at rest); the
    running cost keeps velocities and effort small. ``pose_weights``: of the pose error
    (position [m], rotation [rad]), x1e3 at the end."""
    x0 = np.asarray(x0, float)
    pose_w = np.broadcast_to(np.asarray(pose_weights, float), (6,)).copy()
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

    return shooting_problem(
        uvms,
        x0,
        running,
        terminal,
        nodes=_nodes(horizon_s, dt_s),
        dt_s=dt_s,
        actuators=actuators,
        flow=flow,
        backend=backend,
    )


def station_hold(
    uvms: UVMS,
    x0: np.ndarray,
    station: pin.SE3,
    *,
    horizon_s: float = 1.0,
    dt_s: float = 0.02,
    actuators: Actuators = Actuators(),
    flow: FlowField | None = None,
    effort_weight: float = 1e-4,
    pose_weights=100.0,
    backend: str = "core",
):
    """Keep the vehicle's body frame at ``station`` and the arm as in x0, at rest.

    Per node: (1/2)||log6(T_station^-1 T_vehicle)||^2_W (W = diag(pose_weights) over x, y,
    z [m] and the rotation [rad], body axes) + (1/2)||arm (-) arm_0||^2 + 0.1 (1/2)||v||^2 +
    effort_weight (1/2)||u||^2 (N, N m); x10 at the end. The default trades 1 cm of error
    against 1 N of input; give a DoF the input cannot reach (e.g. the passively stable roll
    and pitch of a vehicle without thrust there) a small weight, or the plan fights it."""
    x0 = np.asarray(x0, float)
    pose_w = np.broadcast_to(np.asarray(pose_weights, float), (6,)).copy()
    hold_arm = np.r_[np.zeros(6), np.ones(uvms.nv - 6), np.full(uvms.nv, 0.1)]

    def terms(scale: float):
        def build(nu: int):
            return [
                (costs.vehicle_pose(uvms, station, pose_w), scale),
                (costs.StateDeviation(uvms.model, x0, hold_arm), scale),
                (costs.Effort(np.ones(nu)), effort_weight),
            ]

        return build

    return shooting_problem(
        uvms,
        x0,
        terms(1.0),
        terms(10.0),
        nodes=_nodes(horizon_s, dt_s),
        dt_s=dt_s,
        actuators=actuators,
        flow=flow,
        backend=backend,
    )


def solve(problem, *, iterations: int = 100, warm_start=None, bounded: bool = True):
    """Solve ``problem`` by crocoddyl's SolverBoxFDDP (bounded) or SolverFDDP; warm start:
    (xs, us), else the initial state held with zero input. Returns the solver (``xs``,
    ``us``, ``cost``, ``iter``, ``isFeasible``)."""
    solver = crocoddyl.SolverBoxFDDP(problem) if bounded else crocoddyl.SolverFDDP(problem)
    if warm_start is None:
        xs = [problem.x0] * (problem.T + 1)
        us = [np.zeros(m.nu) for m in problem.runningModels]
    else:
        xs, us = warm_start
    solver.solve(list(xs), list(us), iterations, False)
    return solver
