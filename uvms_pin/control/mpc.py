"""Model-predictive control on the analytical derivatives: an OCP re-solved at a fixed rate.

At each re-plan (every 1 / rate_hz seconds) the controller sets the OCP's initial state to
the measured (q, v), warm-starts its solver (crocoddyl's BoxFDDP or FDDP, or mim_solvers'
CSQP with the input bounds as constraints) from the previous solution shifted by the nodes
the time since it spans (one at the usual rate_hz = 1 / dt_s),
runs at most ``iterations`` iterations (at most `COLD_START_ITERATIONS` for a plan without
a warm start, e.g. the first) and applies the first control,
tau = B_u u_0, held until the next re-plan. The OCP (a plan of `uvms_pin.ocp.plans`) is built
once on the model the controller believes in (it can be wrong on purpose, as for computed
torque: `uvms_pin.model.scaled.scaled_uvms`) and the water it is told about (a known
current; None: it plans in still water). Its re-plans run on the compiled planner
(`uvms_pin.ocp.compiled`, crocoddyl's C++ solvers, no Python per node and no crocoddyl
Python package) where the core has a counterpart of every part of the plan, else on
crocoddyl's problem of the plan (`uvms_pin.ocp.problems`, the ``ocp`` extra).

Tasks: "station" keeps the vehicle's body frame at a pose and the arm at its posture
(`plans.station_hold`); "end_effector" brings the end-effector to a pose and holds it
(`plans.point_to_point`, re-planned over a receding horizon); "force" presses the
end-effector on a compliant environment to track a desired force f_d(t) while holding its
attitude (`plans.force_tracking`, the paper's task): the controller's model of the
environment (`MpcForceTask.contact`, a `uvms_pin.physics.contact` model; placed where the
tip is at the first re-plan unless its point is given) is in every node's dynamics, and
each re-plan moves the desired force along the horizon (the controller previews f_d).
Unlike the PPC (model-free) the MPC is model-based: it needs the vehicle's, the water's and
the environment's models, and what they get wrong it corrects only through re-planning.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.task_space import first_level_error
from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import plans
from uvms_pin.ocp.compiled import place_contact, planner_of
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.contact import ContactModel
from uvms_pin.physics.derivatives.task_contact import TaskContact

__all__ = ["MpcController", "MpcForceTask"]

TASKS = ("station", "end_effector", "force")
#: where the re-plans are solved (`MpcController`'s ``planner``)
PLANNERS = ("core", "python")
#: the iterations of a plan without a warm start (the first, or every one without warm_start)
COLD_START_ITERATIONS = 20
#: the line search of a warm-started re-plan: each trial step costs one rollout of the
#: horizon; when 1, 1/2 and 1/4 fail, crocoddyl takes the last step whatever it gives, here
#: 1/512 (the warm start kept, nearly), as crocoddyl's own ten (1 down to 1/512) would end,
#: six rollouts sooner. A cold plan tries all ten.
REPLAN_STEP_LENGTHS = (1.0, 0.5, 0.25, 2.0**-9)


@dataclass(frozen=True)
class MpcForceTask:
    """The force task of the MPC (task "force"): what to press on and how hard.

    Attributes:
        contact: the environment the controller believes in (its own copy is used): a spring
            or a plane (`uvms_pin.physics.contact`); its anchor / surface point given, or
            None: where the tip is at the first re-plan (the plant's own convention).
        desired_force: f_d(t) (3,) [N, world axes], the force on the environment.
        desired_rpy: the end-effector's attitude to hold (roll, pitch, yaw) [rad].
        force_weights: of the force error (3,) [1/N^2]; attitude_weights (3,) [1/rad^2];
            posture_weight: of the arm's deviation from the posture [1/rad^2].
    """

    contact: ContactModel
    desired_force: Callable[[float], np.ndarray]
    desired_rpy: ArrayLike = (0.0, 0.0, 0.0)
    force_weights: ArrayLike = field(default_factory=lambda: np.full(3, 100.0))
    attitude_weights: ArrayLike = field(default_factory=lambda: np.full(3, 100.0))
    posture_weight: float = 1.0


class MpcController(Controller):
    """Receding-horizon optimal control of a UVMS in water.

    Args:
        uvms: the model the controller believes in (a private copy of its Pinocchio model is
            used).
        task: "station", "end_effector" or "force" (with ``force_task``). target: the pose
            to hold (vehicle body frame, or end-effector), world frame; None for "force".
        posture: the arm's and vehicle's reference configuration (nq,) for the state terms
            (x_ref = (posture, 0)).
        horizon_s, dt_s: the OCP's horizon and node length [s]. rate_hz: re-plans per second.
        iterations: solver iterations per re-plan. solver: "box_fddp" (bounds enforced as a
            box), "fddp" (not enforced) or "csqp" (mim_solvers' CSQP: enforced as the
            nodes' inequality constraints). integrator: of the OCP's nodes, "euler" or
            "rk4" (`uvms_pin.ocp.plans.INTEGRATORS`).
        actuators: what u is and its bounds (`uvms_pin.ocp.plans.Actuators`).
        flow: the water the controller plans in. warm_start: shift the previous solution.
        pose_weights: of the target pose's error (x, y, z [m], rotation [rad]); None: the
            plan's default (`plans.station_hold`, `plans.point_to_point`).
        force_task: the force task's `MpcForceTask` (task "force" only; ``target`` unused).
        planner: "core": each re-plan solved in the compiled core, crocoddyl's C++ FDDP on
            the compiled nodes (`uvms_pin.ocp.compiled`; where the core has no
            counterpart, e.g. the "csqp" solver or a cost of the user's own class, the
            Python problem is solved instead and `planner_path` says why); "python": the
            Python problem always (crocoddyl calling `uvms_pin.ocp.model` per node, the
            reference the compiled planner is tested against). The Python problem needs
            crocoddyl's Python package (the ``ocp`` extra); the compiled planner does not.
    """

    def __init__(
        self,
        uvms: UVMS,
        *,
        task: str,
        target: pin.SE3 | None,
        posture: np.ndarray,
        horizon_s: float = 1.0,
        dt_s: float = 0.02,
        rate_hz: float = 50.0,
        iterations: int = 3,
        solver: str = "box_fddp",
        integrator: str = "euler",
        actuators: plans.Actuators | None = None,
        flow: FlowField | None = None,
        warm_start: bool = True,
        pose_weights: np.ndarray | None = None,
        backend: str = "core",
        force_task: MpcForceTask | None = None,
        planner: str = "core",
    ):
        if task not in TASKS:
            raise ParameterError(f"mpc task must be one of {TASKS}, got '{task}'")
        if (task == "force") != (force_task is not None):
            raise ParameterError("mpc: a force_task is given with task 'force' and only then")
        if not (horizon_s >= dt_s > 0.0 and math.isfinite(horizon_s)):
            raise ParameterError(
                f"mpc needs 0 < dt_s <= horizon_s (at least one node), got {dt_s}, {horizon_s}"
            )
        plans.check_solver(solver)
        plans.check_integrator(integrator)
        if planner not in PLANNERS:
            raise ParameterError(f"mpc planner must be one of {PLANNERS}, got '{planner}'")
        if not (rate_hz > 0.0 and math.isfinite(rate_hz)) or iterations < 1:
            raise ParameterError(
                f"mpc needs rate_hz > 0 and iterations >= 1, got {rate_hz}, {iterations}"
            )
        self.uvms = uvms.with_model(pin.Model(uvms.model))
        actuators = plans.Actuators() if actuators is None else actuators
        # csqp: the bounds as constraints (box FDDP reads them as a box either way)
        actuators = dataclasses.replace(actuators, as_constraints=solver == "csqp")
        x_ref = np.r_[np.asarray(posture, float), np.zeros(uvms.nv)]
        self.force_task, self.force_tracking = force_task, None
        common = {
            "horizon_s": horizon_s,
            "dt_s": dt_s,
            "actuators": actuators,
            "flow": flow,
            "backend": backend,
            "integrator": integrator,
        }
        if force_task is not None:
            self.plan = self._force_plan(force_task, x_ref, common)
        else:
            build = plans.station_hold if task == "station" else plans.point_to_point
            weights = {} if pose_weights is None else {"pose_weights": pose_weights}
            self.plan = build(self.uvms, x_ref, target, **common, **weights)
        self.period_s, self.dt_s = 1.0 / rate_hz, dt_s
        self.iterations, self.solver, self.warm_start = iterations, solver, warm_start
        self.input_matrix = (
            np.eye(uvms.nv) if actuators.input_matrix is None else actuators.input_matrix
        )
        # the re-plans in the core (no Python per node), decided once: the planner, or the
        # reason the Python problem is solved instead (`planner_path`)
        compiled = planner_of(self.plan, solver) if backend == planner == "core" else None
        self._planner = None if isinstance(compiled, Fallback | None) else compiled
        if self._planner is not None:
            self.planner_path = "compiled"
        elif compiled is None:
            self.planner_path = f"asked for: backend '{backend}', planner '{planner}'"
        else:
            self.planner_path = compiled.reason
        self._replan = self._plan_compiled if self._planner is not None else self._plan_python
        self.reset()

    @functools.cached_property
    def problem(self):
        """crocoddyl's ShootingProblem of the plan (`uvms_pin.ocp.problems.problem_of`: its
        nodes share the plan's cost terms), made on first use: the Python re-plans solve it
        (the ``ocp`` extra's crocoddyl; a compiled planner needs neither)."""
        from uvms_pin.ocp.problems import problem_of  # crocoddyl's Python package: on use

        return problem_of(self.plan)

    def _force_plan(self, task: MpcForceTask, x_ref: np.ndarray, common: dict):
        """The force task's OCP on the controller's own copy of the environment."""
        ee = self.uvms.require_ee_frame("the MPC's force task")
        self._contact = TaskContact(ee, copy.deepcopy(task.contact))
        self._rpy_desired = np.asarray(task.desired_rpy, float).reshape(-1)
        if self._rpy_desired.shape != (3,) or not np.all(np.isfinite(self._rpy_desired)):
            raise ParameterError(f"mpc desired_rpy: 3 finite angles, got {task.desired_rpy}")
        self._ee_data = self.uvms.model.createData()
        self.force_tracking = plans.force_tracking(
            self.uvms,
            x_ref,
            self._contact,
            task.desired_force,
            pin.rpy.rpyToMatrix(*self._rpy_desired),
            force_weights=task.force_weights,
            attitude_weights=task.attitude_weights,
            posture_weight=task.posture_weight,
            **common,
        )
        return self.force_tracking.plan

    def reset(self) -> None:
        self._last_plan_s = -math.inf
        self._guess: tuple[list, list] | None = None
        self._tau = np.zeros(self.uvms.nv)
        self._signals: dict[str, np.ndarray] = {}
        # one solver for the run: each re-plan starts from the last one's regularization
        # (the Python problem's only when it is the one solved: its nodes' data are many)
        if self._planner is None:
            from uvms_pin.ocp.problems import solver_of  # crocoddyl's Python package: on use

            self._solver = solver_of(self.problem, self.solver)
            self._cold_steps = list(self._solver.alphas)
        self._regularization: float | None = None

    def _initial_guess(self, x: np.ndarray, elapsed_s: float) -> tuple[list, list]:
        """The solver's start: the last plan moved on by the ``elapsed_s`` [s] since it, in
        whole nodes (its last node repeated at the end), from the measured state x."""
        nodes = self.plan.nodes
        if self._guess is None or not self.warm_start:
            return [x] * (nodes + 1), [np.zeros(self.plan.nu)] * nodes
        xs, us = self._guess
        shift = min(max(round(elapsed_s / self.dt_s), 0), nodes)
        return [x, *xs[shift + 1 :], *[xs[-1]] * shift], [*us[shift:], *[us[-1]] * shift]

    def _force_signals(self, time_s: float, measurement: Measurement) -> dict[str, np.ndarray]:
        """f_d(t) and the task error e_x = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) (3) rad]
        (the PPC's), for the logs and the comparison of controllers."""
        model, data, ee = self.uvms.model, self._ee_data, self._contact.frame_id
        pin.framesForwardKinematics(model, data, measurement.q)
        rpy_ee = pin.rpy.matrixToRpy(data.oMf[ee].rotation)
        force_desired = np.asarray(self.force_task.desired_force(time_s), float)
        error = first_level_error(
            np.asarray(measurement.wrench_world), force_desired, rpy_ee, self._rpy_desired
        )
        return {"force_desired_world_N": force_desired, "e_x": np.array(error)}

    def _start_force_plan(self, time_s: float, measurement: Measurement) -> None:
        """Place the environment (first plan: at the tip unless its point is given) and move
        the desired force along the horizon."""
        if self._guess is None:
            data = self._ee_data
            pin.framesForwardKinematics(self.uvms.model, data, measurement.q)
            self._contact.model.attach(data.oMf[self._contact.frame_id].translation)
        self.force_tracking.retarget(self.force_task.desired_force, time_s)

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        if self.force_task is not None:
            self._signals.update(self._force_signals(time_s, measurement))
        if time_s < self._last_plan_s + self.period_s - 1e-12:
            return self._tau
        cold = self._guess is None or not self.warm_start
        if self.force_task is not None:
            self._start_force_plan(time_s, measurement)
        x = np.r_[measurement.q, measurement.v]
        iterations = max(self.iterations, COLD_START_ITERATIONS) if cold else self.iterations
        warm = self._initial_guess(x, time_s - self._last_plan_s)
        regularization = self._regularization if self.warm_start else None
        self._guess, cost, self._regularization = self._replan(
            x, cold, iterations, warm, regularization
        )
        u0 = self._guess[1][0].copy()
        self._tau = self.input_matrix @ u0
        self._last_plan_s = time_s
        self._signals.update({"mpc_cost": np.array([cost]), "mpc_u": u0})
        return self._tau

    def _plan_python(self, x, cold, iterations, warm, regularization):
        """One re-plan by crocoddyl from Python (the reference): ((xs, us), cost, preg)."""
        from uvms_pin.ocp import problems  # crocoddyl's Python package: on use

        self.problem.x0 = x
        if self.solver != "csqp":  # (CSQP's filter line search keeps its own steps)
            self._solver.alphas = self._cold_steps if cold else list(REPLAN_STEP_LENGTHS)
        solver = problems.solve(
            self.problem,
            iterations=iterations,
            warm_start=warm,
            solver=self._solver,
            regularization=regularization,
        )
        return problems.solution(solver), solver.cost, solver.preg

    def _plan_compiled(self, x, cold, iterations, warm, regularization):
        """The same re-plan in the core (`uvms_pin.ocp.compiled`): the plan's initial
        state, environment and desired forces given to the planner first."""
        planner = self._planner
        planner.set_x0(x)
        if self.force_task is not None:
            place_contact(planner, self._contact.model)
            for node, term in enumerate(self.force_tracking.forces):
                planner.set_force_target(node, term.target_N)
        steps = planner.default_step_lengths if cold else list(REPLAN_STEP_LENGTHS)
        result = planner.solve(
            *warm, iterations, math.nan if regularization is None else regularization, steps
        )
        guess = ([np.array(v) for v in planner.xs], [np.array(v) for v in planner.us])
        return guess, result.cost, result.regularization

    def signals(self) -> dict[str, np.ndarray]:
        return self._signals
